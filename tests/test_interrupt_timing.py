"""Ctrl-C at any moment of ``camfab run`` (docs/decisions.md, "Ctrl-C from start to exit"): while the command
line and numpy are imported, while it computes, while it writes, and after it has returned, the process exits with
130 (``camfab ...: interrupted``, no traceback) or, once the command is over, with the command's own 0; never by
the signal itself, and never leaving a temporary or a file that differs from an uninterrupted run's."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ARGS = ["run", "ejemplo9rt", "--outputs", "dxf,gcode,xlsx"]
linux_only = pytest.mark.skipif(not Path("/proc/self/maps").is_file(), reason="reads /proc/PID/maps (Linux)")


def _env() -> dict[str, str]:
    return dict(os.environ, PYTHONPATH=str(ROOT))


def _importing_numpy(pid: int) -> bool:
    """numpy's core extension is mapped: ``camfab.__main__.main`` is importing the command line (or past it)."""
    try:
        return "_multiarray_umath" in Path(f"/proc/{pid}/maps").read_text()
    except OSError:
        return False


def _files(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()} \
        if folder.exists() else {}


@linux_only
@pytest.mark.slow
def test_ctrl_c_at_any_moment_of_run_exits_130_and_leaves_no_partial_file(tmp_path):
    ref = tmp_path / "ref"
    subprocess.run([sys.executable, "-m", "camfab", *ARGS, "-o", str(ref)], env=_env(), check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    complete = _files(ref)
    assert "Ejemplo9RT.nc" in complete
    codes = []
    for k, delay in enumerate((0.0, 0.05, 0.3, 0.8, 1.5, 3.0, 6.0)):
        out = tmp_path / f"out{k}"
        p = subprocess.Popen([sys.executable, "-m", "camfab", *ARGS, "-o", str(out)], env=_env(), text=True,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
        try:
            deadline = time.monotonic() + 60
            while not _importing_numpy(p.pid) and p.poll() is None:
                assert time.monotonic() < deadline, "the process did not start importing within 60 s"
                time.sleep(0.005)
            time.sleep(delay)
            if p.poll() is None:
                os.kill(p.pid, signal.SIGINT)
            err = p.communicate(timeout=120)[1]
        finally:
            if p.poll() is None:
                p.kill()
        codes.append(p.returncode)
        assert p.returncode in (130, 0), (delay, p.returncode, err)
        assert "Traceback" not in err, (delay, err)
        if p.returncode == 130:
            assert err.splitlines()[-1] in ("camfab: interrupted", "camfab run: interrupted"), (delay, err)
        files = _files(out)
        assert not [n for n in files if ".camfab-" in n], (delay, sorted(files))  # no temporary left
        assert all(files[n] == complete.get(n) for n in files), (delay, sorted(files))  # whole files only
        if p.returncode == 0:
            assert files == complete, delay
    assert 130 in codes, codes  # at least one interrupt landed before the command was over
