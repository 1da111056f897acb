"""The code-quality gates of ``.ci/run``: ``ruff check .`` and ``mypy`` (configured in pyproject.toml)
report nothing when run from the repository root.  Skipped where the tools are not installed."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", *args], cwd=ROOT, capture_output=True, text=True, timeout=900)


def test_ruff_reports_nothing():
    pytest.importorskip("ruff")
    r = _run("ruff", "check", ".")
    assert r.returncode == 0, f"ruff check . failed:\n{r.stdout}\n{r.stderr}"


@pytest.mark.slow  # a cold mypy run (no .mypy_cache) takes 20-30 s
def test_mypy_reports_nothing():
    pytest.importorskip("mypy")
    r = _run("mypy")
    assert r.returncode == 0, f"mypy failed:\n{r.stdout}\n{r.stderr}"
