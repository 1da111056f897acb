"""The command line's exit codes (the contract of the README's "Commands": scripts test them); no imports, so the
console entry (:mod:`camfab.__main__`) has them before numpy is loaded."""
from __future__ import annotations

__all__ = ["EXIT_OK", "EXIT_CHECKS", "EXIT_INPUT", "EXIT_IO", "EXIT_BROKEN_PIPE", "EXIT_INTERRUPTED"]

EXIT_OK, EXIT_CHECKS, EXIT_INPUT, EXIT_IO = 0, 1, 2, 3
EXIT_BROKEN_PIPE = 128 + 13  # 128 + SIGPIPE: what a shell reports for a command whose reader went away
EXIT_INTERRUPTED = 128 + 2  # 128 + SIGINT: what a shell reports for a command ended by Ctrl-C
