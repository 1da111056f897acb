"""An installed package's version, read from its ``version.py`` without importing the package.

Importing ezdxf costs ~0.3 s and numpy's import is what :mod:`camfab.kernels` must come before; ``importlib.metadata``
costs ~30 ms. Reading the file costs well under a millisecond. This module imports nothing of camfab.
"""
from __future__ import annotations

import importlib.util
import re
from pathlib import Path

__all__ = ["installed_version"]


def installed_version(package: str, variable: str = "__version__") -> str | None:
    """The string assigned to ``variable`` in ``package``'s ``version.py`` (a literal, optionally annotated
    ``: str``); None when the package is not installed, has no such file, or the file does not say."""
    try:
        spec = importlib.util.find_spec(package)
    except (ImportError, ValueError):
        return None
    if spec is None or spec.origin is None:
        return None
    try:
        text = (Path(spec.origin).parent / "version.py").read_text(encoding="utf-8")
    except OSError:
        return None
    found = re.search(rf'^{re.escape(variable)}\s*(?::\s*str\s*)?=\s*["\']([^"\']+)["\']', text, re.M)
    return found.group(1) if found else None
