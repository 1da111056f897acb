"""Faults with real processes and signals: Ctrl-C, kill -9, stale and withheld files, the output-folder lock,
I/O errors (disk full injected at the one place camfab writes bytes), leftovers of killed writers, fsync.

docs/decisions.md, "Faults: staging, locks, durability"."""
from __future__ import annotations

import errno
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import camfab.io as cio
from camfab import pipeline
from camfab.cli import main
from camfab.io import LOCK, clean_stale, output_folder, write_all
from tests.conftest import EXAMPLES

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
FAST = "dxf,xlsx"
#: four quick designs (a second or two each with FAST outputs)
QUICK = ("ejemplo9rt", "ejemplo1rt", "ejemplo10ex", "ejemplo11ro")
linux_only = pytest.mark.skipif(not Path("/proc/self/stat").exists() or not hasattr(os, "killpg"),
                                reason="needs /proc and process groups")


# ---------------------------------------------------------------------------
# helpers
class Proc:
    """``python -m camfab ARGS`` in its own process group, its stderr collected line by line as it comes."""

    def __init__(self, cwd: Path, *args: str):
        self.p = subprocess.Popen([sys.executable, "-m", "camfab", *args], cwd=cwd, env=ENV, start_new_session=True,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.err: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.p.stderr is not None
        for line in self.p.stderr:
            self.err.append(line.rstrip("\n"))

    @property
    def pid(self) -> int:
        return self.p.pid

    def wait(self, timeout: float) -> int:
        rc = self.p.wait(timeout)
        self._reader.join(10)
        return rc

    def group(self) -> list[int]:
        return _group(self.p.pid)


def _group(pgid: int) -> list[int]:
    """Live (not zombie) processes of process group ``pgid``, from /proc."""
    out = []
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            stat = Path(f"/proc/{d}/stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if int(fields[2]) == pgid and fields[0] not in ("Z", "X"):
            out.append(int(d))
    return out


def _until(cond, timeout: float, what: str, step: float = 0.02):
    t = time.monotonic()
    while time.monotonic() - t < timeout:
        value = cond()
        if value:
            return value
        time.sleep(step)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def _leftovers(root: Path) -> list[Path]:
    """camfab's temporary files, staging folders and lock files under ``root``."""
    if not root.exists():
        return []
    return sorted(p for p in root.rglob("*") if ".camfab-" in p.name or p.name == LOCK)


def _sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _assert_manifest_matches(out: Path) -> dict:
    manifest = json.loads((out / "manifest.json").read_text())
    for cam in manifest["cams"]:
        for f in cam["files"]:
            p = out / f["path"]
            assert p.is_file() and _sha(p) == f["sha256"] and p.stat().st_size == f["bytes"], p
    return manifest


def _snapshot(root: Path) -> dict[str, str]:
    return {p.relative_to(root).as_posix(): _sha(p) for p in root.rglob("*") if p.is_file()}


@pytest.fixture
def designs(tmp_path):
    src = tmp_path / "designs"
    src.mkdir()
    for name in QUICK:
        shutil.copy(EXAMPLES / f"{name}.toml", src)
    return src


def _unacceptable(tmp_path: Path) -> Path:
    d = tmp_path / "bad.toml"
    d.write_text((EXAMPLES / "ejemplo9rt.toml").read_text().replace("base_radius_mm = 35.0", "base_radius_mm = 12.0"))
    return d


# ---------------------------------------------------------------------------
# 1. Ctrl-C: exit 130, one line, nothing half-written, no survivor; a second Ctrl-C ends at once
def _interrupted_cleanly(proc: Proc, command: str, out: Path) -> None:
    rc = proc.wait(60)
    # 130, never killed by the signal after the cleanup (camfab.__main__.main: CPython had marked the caught
    # KeyboardInterrupt unhandled when it crossed an import)
    assert rc == 130, (rc, proc.err)
    assert not any("Traceback" in line for line in proc.err), proc.err
    own = [line for line in proc.err if not line.startswith(("  ... ", "["))]  # besides the progress lines
    assert own == [f"camfab {command}: interrupted"], proc.err
    _until(lambda: not proc.group(), 10, "the process group to end")
    assert _leftovers(out) == []


@linux_only
@pytest.mark.slow
@pytest.mark.parametrize("jobs", ["1", "2"])
def test_ctrl_c_during_package(designs, tmp_path, jobs):
    """SIGINT to the whole process group (as a terminal sends it) once the first design is done."""
    out = tmp_path / "out"
    proc = Proc(tmp_path, "package", str(designs), "-o", str(out), "--jobs", jobs, "--outputs", FAST)
    _until(lambda: any("1/4" in line for line in proc.err), 120, "the first design")
    os.killpg(proc.pid, signal.SIGINT)
    _interrupted_cleanly(proc, "package", out)
    for folder in (p for p in out.iterdir() if p.is_dir()):  # every cam folder holds a complete set
        names = {p.name for p in folder.iterdir()}
        assert {"check.json", f"{folder.name}.xlsx"} <= names <= {"check.json", f"{folder.name}.xlsx",
                                                                  f"{folder.name}.dxf"}, names


class _FailingCadquery:
    """A meta-path finder whose import of ``cadquery`` fails as OCP's does when Ctrl-C comes during it: the
    interrupt raised (``signal``: by a real SIGINT to this process, through the handler in place) and turned into
    ``ImportError('initialization failed')``, or swallowed and followed by another ``ImportError``."""

    def __init__(self, how: str):
        self.how = how

    def find_spec(self, name, path=None, target=None):
        if name != "cadquery":
            return None
        if self.how == "chained":
            try:
                raise KeyboardInterrupt
            except KeyboardInterrupt:
                raise ImportError("initialization failed") from None  # (the interrupt stays its __context__)
        if self.how == "signal":
            try:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(1.0)  # (the handler runs here)
            except KeyboardInterrupt:
                pass  # swallowed, as cadquery's optional imports do
            raise ImportError("cannot import name 'IVtkOCC_Shape' from 'OCP.IVtkOCC'")
        raise ImportError("No module named 'cadquery'")


@pytest.mark.parametrize("how", ["chained", "signal", "missing"])
def test_ctrl_c_during_the_cadquery_import_is_an_interrupt(monkeypatch, how):
    """A Ctrl-C during ``import cadquery`` (a second or more of ``export --step``) is ``KeyboardInterrupt`` (exit
    130), not "this install lacks cadquery" (exit 3): with the interrupt in the ``ImportError``'s chain, or with
    SIGINT noted during the import and the interrupt swallowed; a plain ``ImportError`` is still the missing
    dependency, and the SIGINT handler in place is restored."""
    from camfab.cad.step import cadquery
    from camfab.errors import MissingDependencyError

    monkeypatch.delitem(sys.modules, "cadquery", raising=False)
    monkeypatch.setattr(sys, "meta_path", [_FailingCadquery(how)] + sys.meta_path)
    before = signal.getsignal(signal.SIGINT)
    expected = MissingDependencyError if how == "missing" else KeyboardInterrupt
    with pytest.raises(expected):
        cadquery()
    assert signal.getsignal(signal.SIGINT) is before


def _swallowed_ctrl_c_then(error: BaseException):
    """A stage that gets Ctrl-C while an extension module initialises, as pybind11's import turns it into
    ``ImportError('initialization failed')`` (OCP's, matplotlib's: seen once in 39 timed SIGINTs to ``import
    matplotlib.pyplot``) or an optional import swallows it, and then fails with ``error``."""
    def stage(*args, **kwargs):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)  # (the handler runs here)
        except KeyboardInterrupt:
            pass
        raise error
    return stage


@linux_only
@pytest.mark.parametrize("error", [ImportError("initialization failed"), OSError(5, "Input/output error"),
                                   AttributeError("partially initialized module 'matplotlib'")],
                         ids=["import", "os", "other"])
def test_an_error_after_ctrl_c_is_the_interrupt(monkeypatch, capsys, tmp_path, error):
    """Whatever a command fails with after a Ctrl-C came is the interrupt: exit 130 and "interrupted", not the
    error's message or traceback, nothing written, and the SIGINT handler restored; without a Ctrl-C the same
    error is still itself."""
    from camfab.errors import MissingDependencyError
    from camfab.terminal import interrupt_came

    monkeypatch.setattr(pipeline, "build_files", _swallowed_ctrl_c_then(error))
    out = tmp_path / "out"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert main(["run", str(EXAMPLES / "ejemplo9rt.toml"), "-o", str(out)]) == 130
    assert capsys.readouterr().err.strip().splitlines() == ["camfab run: interrupted"]
    assert not out.exists()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert not interrupt_came()  # (cleared with the command: the API's package after it contains errors again)

    def plain(*args, **kwargs):
        raise MissingDependencyError("the report needs matplotlib")

    monkeypatch.setattr(pipeline, "build_files", plain)
    assert main(["run", str(EXAMPLES / "ejemplo9rt.toml"), "-o", str(out)]) == 3  # (no Ctrl-C: its own exit)
    assert "needs matplotlib" in capsys.readouterr().err


@linux_only
def test_a_contained_design_failure_after_ctrl_c_is_the_interrupt(monkeypatch, capsys, designs, tmp_path):
    """``package --jobs 1`` contains a design's failure and goes on with the others; a failure after a Ctrl-C
    is the interrupt instead: exit 130, no cam folder, no leftovers."""
    import camfab.package as package_mod

    monkeypatch.setattr(package_mod, "build_files", _swallowed_ctrl_c_then(ImportError("initialization failed")))
    out = tmp_path / "out"
    assert main(["package", str(designs), "-o", str(out), "--jobs", "1", "--outputs", FAST]) == 130
    assert capsys.readouterr().err.strip().splitlines()[-1] == "camfab package: interrupted"
    assert not out.exists() or (not [p for p in out.iterdir() if p.is_dir()] and _leftovers(out) == [])


@linux_only
@pytest.mark.parametrize("argv", [["run", "ejemplo9rt"], ["export", "ejemplo9rt", "--dxf", "--stl", "--step"]],
                         ids=["run", "export"])
def test_ctrl_c_during_run_or_export_writes_nothing(tmp_path, argv):
    out = tmp_path / "out"
    proc = Proc(tmp_path, *argv, "-o", str(out))
    _until(lambda: (out / LOCK).exists(), 120, "the command to start working")
    time.sleep(0.3)
    os.killpg(proc.pid, signal.SIGINT)
    _interrupted_cleanly(proc, argv[0], out)
    assert not out.exists()  # the folder it created for its files is gone with them


@linux_only
@pytest.mark.slow
def test_a_second_ctrl_c_ends_at_once(designs, tmp_path):
    out = tmp_path / "out"
    proc = Proc(tmp_path, "package", str(designs), "-o", str(out), "--jobs", "2", "--outputs", FAST)
    _until(lambda: len(proc.group()) >= 3, 120, "the worker processes")
    _until(lambda: any("1/4" in line for line in proc.err), 120, "the first design")
    os.killpg(proc.pid, signal.SIGINT)
    time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGINT)
    t = time.monotonic()
    rc = proc.wait(30)
    assert time.monotonic() - t < 3.0
    assert rc in (130, -signal.SIGINT)  # 130 if the first one's cleanup had finished, else killed by SIGINT
    _until(lambda: not proc.group(), 10, "the process group to end")
    # what the killed process left (a lock file, a staging folder) goes with the next package
    assert main(["package", str(designs), "-o", str(out), "--outputs", FAST]) == 0
    assert _leftovers(out) == []
    _assert_manifest_matches(out)


# ---------------------------------------------------------------------------
# 2. kill -9 of package: the workers die with it
@linux_only
@pytest.mark.slow
def test_kill_9_of_package_takes_its_workers_along(designs, tmp_path):
    out = tmp_path / "out"
    proc = Proc(tmp_path, "package", str(designs), "-o", str(out), "--jobs", "2", "--outputs", FAST)
    _until(lambda: any("1/4" in line for line in proc.err), 120, "the first design")
    members = proc.group()
    assert len(members) >= 3  # the parent, two workers (and multiprocessing's resource tracker)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(10)
    _until(lambda: not _group(proc.pid), 5, f"the workers {members} to die")
    before = _snapshot(out)
    time.sleep(0.5)
    assert _snapshot(out) == before  # nobody goes on writing
    assert main(["package", str(designs), "-o", str(out), "--outputs", FAST]) == 0
    assert _leftovers(out) == []
    _assert_manifest_matches(out)


@linux_only
@pytest.mark.slow
def test_package_with_two_jobs_leaves_no_process_behind(designs, tmp_path):
    """When ``package --jobs 2`` has exited, nothing of it is left in its process group: not its workers, not
    multiprocessing's resource tracker (which used to outlive it for a moment)."""
    (designs / "ejemplo10ex.toml").unlink()
    (designs / "ejemplo11ro.toml").unlink()
    p = subprocess.Popen([sys.executable, "-m", "camfab", "package", str(designs), "-o", str(tmp_path / "out"),
                          "--jobs", "2", "--outputs", "xlsx"], cwd=tmp_path, env=ENV, start_new_session=True,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    assert p.wait(300) == 0
    assert _group(p.pid) == []


@linux_only
def test_a_worker_whose_parent_is_already_gone_exits():
    """The race the worker initializer closes: the parent died before the worker asked to die with it."""
    code = "import sys; from camfab.package import _worker_init; _worker_init(1); print('still here')"
    r = subprocess.run([sys.executable, "-c", code], env=ENV, capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "still here" not in r.stdout


# ---------------------------------------------------------------------------
# 3. stale and withheld files
def test_rerun_of_a_design_become_unacceptable_removes_its_shop_files(tmp_path, capsys):
    d = _unacceptable(tmp_path)
    out = tmp_path / "out"
    shop = "dxf,stl,gcode,drawing,lift_table,xlsx"
    assert main(["run", str(d), "-o", str(out), "--outputs", shop, "--force"]) == 1
    written = {p.name for p in out.iterdir()}
    cam = pipeline.load(d)
    assert written - {"check.json", "Ejemplo9RT.xlsx"} <= pipeline.shop_file_names(cam)
    assert {"Ejemplo9RT.nc", "Ejemplo9RT.dxf", "Ejemplo9RT.stl", "Ejemplo9RT_drawing.dxf"} <= written
    (out / "notes.txt").write_text("mine")
    (out / "Other.nc").write_text("another design's program")
    capsys.readouterr()
    assert main(["run", str(d), "-o", str(out), "--outputs", "xlsx"]) == 1  # not forced, whatever is asked
    assert {p.name for p in out.iterdir()} == {"check.json", "Ejemplo9RT.xlsx", "notes.txt", "Other.nc"}
    assert json.loads((out / "check.json").read_text())["verdict"] == "unacceptable"
    assert "removed" in capsys.readouterr().out


def test_shop_file_names_cover_a_conjugate_pair(tmp_path):
    cam = pipeline.load("ejemplo8da_conjugate")
    res = pipeline.run(cam, tmp_path / "o", pipeline.Request(frozenset({pipeline.Output.DXF, pipeline.Output.GCODE,
                                                                          pipeline.Output.LIFT_TABLE}), force=True))
    assert set(res.files) - {"check.json"} <= pipeline.shop_file_names(cam)
    assert {"Ejemplo8DA_cam1.nc", "Ejemplo8DA_cam2.nc", "Ejemplo8DA_pair.step"} <= pipeline.shop_file_names(cam)


def test_repackaging_removes_what_it_wrote_before_and_keeps_the_rest(designs, tmp_path):
    out = tmp_path / "out"
    assert main(["package", str(designs), "-o", str(out), "--outputs", "dxf,xlsx,lift_table"]) == 0
    first = _assert_manifest_matches(out)
    folder = out / "Ejemplo9RT"
    (folder / "notes.txt").write_text("mine")  # user files: in a cam folder, in a subfolder, beside the cams
    (folder / "sub").mkdir()
    (folder / "sub" / "photo.jpg").write_bytes(b"\xff\xd8")
    (out / "README.txt").write_text("mine too")
    (designs / "ejemplo11ro.toml").unlink()  # a design leaves the package
    assert main(["package", str(designs), "-o", str(out), "--outputs", "xlsx"]) == 0
    m = _assert_manifest_matches(out)
    listed = {f["path"] for c in m["cams"] for f in c["files"]}
    on_disk = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    mine = {"Ejemplo9RT/notes.txt", "Ejemplo9RT/sub/photo.jpg", "README.txt"}
    assert on_disk == listed | mine | {"manifest.json", "index.html"}
    assert not (out / "Ejemplo11RO").exists()  # its files were camfab's: gone, and its folder with them
    assert len(first["cams"]) == 4 and len(m["cams"]) == 3


def test_package_of_a_design_become_unacceptable_leaves_no_shop_file(designs, tmp_path):
    out = tmp_path / "out"
    assert main(["package", str(designs), "-o", str(out), "--outputs", "dxf,lift_table,xlsx"]) == 0
    assert (out / "Ejemplo9RT" / "Ejemplo9RT.dxf").is_file()
    f = designs / "ejemplo9rt.toml"
    f.write_text(f.read_text().replace("base_radius_mm = 35.0", "base_radius_mm = 12.0"))
    assert main(["package", str(designs), "-o", str(out), "--outputs", "dxf,lift_table,xlsx"]) == 1
    assert {p.name for p in (out / "Ejemplo9RT").iterdir()} == {"check.json", "Ejemplo9RT.xlsx"}
    _assert_manifest_matches(out)


def test_a_cam_folder_is_swapped_whole(tmp_path):
    old, new = tmp_path / "cam", tmp_path / ".cam.camfab-staging-1"
    old.mkdir()
    (old / "a.nc").write_text("old")
    (old / "b.dxf").write_text("old")
    new.mkdir()
    (new / "a.nc").write_text("new")
    cio.swap_dir(new, old)
    assert {p.name: p.read_text() for p in old.iterdir()} == {"a.nc": "new"} and not new.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cam"]



def _sigint_once_made(monkeypatch) -> None:
    """``tempfile.mkstemp`` as camfab's writers call it, followed at once by a real SIGINT to this process: the
    interrupt is due the moment the temporary exists, before its name is back in the writer's hands."""
    real = cio.tempfile.mkstemp

    def mkstemp(*args, **kwargs):
        made = real(*args, **kwargs)
        os.kill(os.getpid(), signal.SIGINT)
        return made

    monkeypatch.setattr(cio.tempfile, "mkstemp", mkstemp)


def _write_as(how: str, folder: Path) -> None:
    """One of camfab's writers into ``folder``: a set of files (``a.dxf``, ``b.nc``), a stream (``b.nc``) or the
    output folder's probe."""
    if how == "write_all":
        write_all({folder / "a.dxf": b"0", folder / "b.nc": b"G0"})
    elif how == "atomic_stream":
        with cio.atomic_stream(folder / "b.nc") as fh:
            fh.write(b"G0")
    else:
        cio._probe(folder)


def _other_thread_takes_sigint(monkeypatch) -> None:
    """As :func:`_sigint_once_made`, in a process where another thread has SIGINT unblocked (a BLAS worker, a pool's
    thread): the kernel hands it the signal the main thread holds back, and Python runs the handler in the main
    thread at its next chance (here: right after a pause that lets the other thread take it, still inside
    ``mkstemp``)."""
    real = cio.tempfile.mkstemp

    def mkstemp(*args, **kwargs):
        made = real(*args, **kwargs)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)
        return made

    monkeypatch.setattr(cio.tempfile, "mkstemp", mkstemp)


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX: Ctrl-C held back by the signal mask")
@pytest.mark.parametrize("how", ["write_all", "atomic_stream", "probe"])
def test_ctrl_c_taken_by_another_thread_still_waits_for_the_writer(tmp_path, monkeypatch, how):
    """The CI run of 2026-11-27 (fifth sitting) lost the test below to a Ctrl-C that landed after ``pytest.raises``
    had ended: another thread of the test process took the signal, so the main thread's mask held nothing.  With a
    thread that does not block SIGINT alive, every writer still ends with the interrupt, no temporary, and the
    replaced file untouched."""
    (tmp_path / "b.nc").write_text("old")
    _other_thread_takes_sigint(monkeypatch)
    stop = threading.Event()
    other = threading.Thread(target=stop.wait, daemon=True)
    other.start()  # (made here, with SIGINT unblocked: the kernel's only choice while the writer holds it back)
    try:
        with pytest.raises(KeyboardInterrupt):
            _write_as(how, tmp_path)
    finally:
        stop.set()
        other.join()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.nc"]
    assert (tmp_path / "b.nc").read_text() == "old"


def test_a_held_ctrl_c_goes_to_the_handler_it_replaced_once():
    """Nested holds pass one recorded SIGINT outward to the handler in place before them, once; without one, none;
    an ignored SIGINT stays ignored."""
    seen = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: seen.append(signum))
    try:
        with cio.hold_sigint(), cio.hold_sigint():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)
            assert seen == []
        assert seen == [signal.SIGINT]
        with cio.hold_sigint():
            pass
        assert seen == [signal.SIGINT]
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # ignored before the hold: dropped after it, and kept ignored
        with cio.hold_sigint():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN and seen == [signal.SIGINT]
    finally:
        signal.signal(signal.SIGINT, previous)


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX: Ctrl-C held back by the signal mask")
@pytest.mark.parametrize("how", ["write_all", "atomic_stream", "probe"])
def test_ctrl_c_the_instant_a_temporary_exists_leaves_none(tmp_path, monkeypatch, how):
    """The window that once left ``.Ejemplo9RT.nc.camfab-tmp-…`` after ``camfab run`` was interrupted at 0.8 s
    (tests/test_interrupt_timing.py): a Ctrl-C between ``mkstemp`` and the writer's cleanup list.  Every writer
    (a set of files, a stream, the output folder's probe) ends with the interrupt and no temporary, and the file
    it was replacing is untouched."""
    (tmp_path / "b.nc").write_text("old")
    _sigint_once_made(monkeypatch)
    with pytest.raises(KeyboardInterrupt):
        _write_as(how, tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.nc"]
    assert (tmp_path / "b.nc").read_text() == "old"


# ---------------------------------------------------------------------------
# 4. one writer per output folder
def test_a_locked_folder_is_refused_with_exit_3_naming_it(tmp_path, capsys):
    out = tmp_path / "out"
    with output_folder(out):
        assert (out / LOCK).exists()
        for argv in (["run", "ejemplo9rt", "--outputs", "xlsx"], ["package", str(EXAMPLES / "ejemplo9rt.toml")],
                     ["export", "ejemplo9rt", "--dxf"], ["report", "ejemplo9rt"],
                     ["compare", "ejemplo9rt", "ejemplo1rt"]):
            assert main([*argv, "-o", str(out)]) == 3
            err = capsys.readouterr().err
            assert "another camfab command is writing into this folder" in err and str(out) in err
        with pytest.raises(BlockingIOError, match="another camfab command"), output_folder(out):
            pass
    assert not out.exists()  # nothing was written: the folder it made is gone, lock file included
    assert main(["run", "ejemplo9rt", "--outputs", "xlsx", "-o", str(out)]) == 0
    assert _leftovers(out) == []


@linux_only
@pytest.mark.slow
def test_two_packages_into_one_folder(designs, tmp_path):
    out = tmp_path / "out"
    argv = ("package", str(designs), "-o", str(out), "--outputs", FAST)
    first = Proc(tmp_path, *argv)
    _until(lambda: (out / LOCK).exists(), 120, "the first package to lock the folder")
    second = Proc(tmp_path, *argv, "--jobs", "2")
    assert second.wait(120) == 3
    assert any(str(out) in line and "another camfab command" in line for line in second.err), second.err
    assert first.wait(300) == 0
    _assert_manifest_matches(out)
    assert _leftovers(out) == []
    # started together, in either order: one refuses or they run one after the other; the manifest holds
    procs = [Proc(tmp_path, *argv), Proc(tmp_path, *argv, "--jobs", "2")]
    assert sorted(p.wait(300) for p in procs) in ([0, 0], [0, 3])
    _assert_manifest_matches(out)


# ---------------------------------------------------------------------------
# 5. I/O errors: exit 3 naming the path, nothing partial; early for a folder that cannot be written
def _disk_full_on(monkeypatch, suffix: str) -> None:
    real = cio.write_bytes

    def write_bytes(fh, raw, path):
        if path.name.endswith(suffix):
            fh.write(raw[: len(raw) // 2])  # half of it fits
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real(fh, raw, path)

    monkeypatch.setattr(cio, "write_bytes", write_bytes)


def test_disk_full_in_run_names_the_file_and_leaves_the_old_set(tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    argv = ["run", "ejemplo9rt", "-o", str(out), "--outputs", "dxf,gcode,xlsx"]
    _disk_full_on(monkeypatch, ".xlsx")
    assert main(argv) == 3
    err = capsys.readouterr().err
    assert "No space left on device" in err and str(out / "Ejemplo9RT.xlsx") in err
    assert not out.exists()  # not the shop files without the rest: nothing
    monkeypatch.undo()
    assert main(argv) == 0
    before = _snapshot(out)
    _disk_full_on(monkeypatch, ".xlsx")
    assert main(argv) == 3
    assert _snapshot(out) == before and _leftovers(out) == []  # the old complete set, untouched


def test_disk_full_in_package_is_an_io_error_and_the_index_is_still_written(designs, tmp_path, monkeypatch,
                                                                           capsys):
    out = tmp_path / "out"
    (designs / "ejemplo10ex.toml").unlink()
    (designs / "ejemplo11ro.toml").unlink()
    real = cio.write_bytes

    def write_bytes(fh, raw, path):  # the disk fills up while one cam's spreadsheet is written
        if path.name == "Ejemplo1RT.xlsx":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real(fh, raw, path)

    monkeypatch.setattr(cio, "write_bytes", write_bytes)
    assert main(["package", str(designs), "-o", str(out), "--outputs", FAST]) == 3
    m = _assert_manifest_matches(out)
    bad = next(c for c in m["cams"] if c["name"] == "Ejemplo1RT")
    assert bad["status"] == "error" and bad["error_kind"] == "io"
    assert "No space left on device" in bad["error"] and str(out / "Ejemplo1RT" / "Ejemplo1RT.xlsx") in bad["error"]
    assert "I/O error" in (out / "index.html").read_text()
    assert not (out / "Ejemplo1RT").exists() and (out / "Ejemplo9RT" / "Ejemplo9RT.xlsx").is_file()
    assert _leftovers(out) == []


def test_disk_full_on_the_manifest_still_writes_the_index(designs, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    _disk_full_on(monkeypatch, "manifest.json")
    assert main(["package", str(designs / "ejemplo9rt.toml"), "-o", str(out), "--outputs", "xlsx"]) == 3
    assert str(out / "manifest.json") in capsys.readouterr().err
    assert (out / "index.html").is_file() and not (out / "manifest.json").exists()
    assert _leftovers(out) == []


@pytest.mark.parametrize("argv", [["run", "ejemplo9rt"], ["export", "ejemplo9rt", "--dxf"],
                                  ["package", str(EXAMPLES / "ejemplo9rt.toml")], ["report", "ejemplo9rt"],
                                  ["compare", "ejemplo9rt", "ejemplo1rt"], ["gcode", "ejemplo9rt"],
                                  ["gcode", "ejemplo9rt", "--lift-table", "LIFT"]], ids=lambda a: "-".join(a[::2]))
def test_a_folder_that_cannot_be_written_fails_before_any_computing(tmp_path, monkeypatch, capsys, argv):
    def no(*a, **k):
        raise AssertionError("computed before the output folder was proved writable")

    monkeypatch.setattr(pipeline.Cam, "check", no)
    plain = tmp_path / "plain"
    plain.write_text("a file, not a folder")
    for target in (Path("/proc/camfab-x"), plain / "sub", plain):
        if argv[0] != "gcode":
            args = [*argv, "-o", str(target)]
        elif "LIFT" in argv:  # the program's folder is fine, the lift table's is not
            args = [a if a != "LIFT" else str(target / "lift.csv") for a in argv] + ["-o", str(tmp_path / "p.nc")]
        else:  # gcode -o names a file: its folder is the one proved writable
            args = [*argv, "-o", str(target / "p.nc")]
        assert main(args) == 3
        err = capsys.readouterr().err
        assert str(target) in err and "output folder" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain"]  # nothing written, no folder left


# ---------------------------------------------------------------------------
# 6. leftovers of a kill between the temporary write and the rename
@linux_only
def test_a_temp_file_left_by_kill_9_is_removed_by_the_next_run(tmp_path):
    out = tmp_path / "out"
    code = f"""
import time, camfab.io as cio
from camfab.cli import main
real = cio.write_bytes
def slow(fh, raw, path):
    real(fh, raw, path); fh.flush(); time.sleep(600)   # killed here: after the write, before the rename
cio.write_bytes = slow
main(["run", "ejemplo9rt", "-o", {str(out)!r}, "--outputs", "xlsx"])
"""
    p = subprocess.Popen([sys.executable, "-c", code], env=ENV, start_new_session=True)
    # the xlsx's own temporary file: the output folder's probe makes one too, which lives only for an instant
    temps = _until(lambda: list(out.glob(".Ejemplo9RT.xlsx.camfab-tmp-*")), 120, "the xlsx's temporary file")
    os.kill(p.pid, signal.SIGKILL)
    p.wait(10)
    assert temps[0].exists() and (out / LOCK).exists()
    user = [out / ".Ejemplo9RT.xlsx.tmp", out / "x.camfab-tmp-1", out / ".notes.camfab-tmp-abc"]
    for u in user:  # not camfab's pattern: kept
        u.write_text("mine")
    assert main(["run", "ejemplo9rt", "-o", str(out), "--outputs", "xlsx"]) == 0
    assert sorted(out.iterdir()) == sorted([out / "Ejemplo9RT.xlsx", out / "check.json", *user])


def test_clean_stale_removes_only_dead_writers_leftovers(tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        mine = [tmp_path / f".a.nc.camfab-tmp-{live.pid}-x1", tmp_path / f".b.camfab-staging-{os.getpid()}"]
        gone = [tmp_path / f".a.nc.camfab-tmp-{dead.pid}-k2_z", tmp_path / "cam" / f".c.dxf.camfab-tmp-{dead.pid}-q",
                tmp_path / f".cam.camfab-staging-{dead.pid}", tmp_path / f".cam.camfab-old-{dead.pid}"]
        (tmp_path / "cam").mkdir()
        for p in mine + gone:
            if "staging" in p.name or "old" in p.name:
                p.mkdir()
                (p / "f.nc").write_text("x")
            else:
                p.write_text("x")
        assert sorted(clean_stale(tmp_path)) == sorted(gone)
        assert all(p.exists() for p in mine) and not any(p.exists() for p in gone)
    finally:
        live.kill()
        live.wait()


# ---------------------------------------------------------------------------
# 7. durability
def test_files_and_their_folder_are_fsynced(tmp_path, monkeypatch):
    synced: list[str] = []
    real = os.fsync

    def fsync(fd):
        synced.append(os.readlink(f"/proc/self/fd/{fd}") if Path("/proc/self/fd").exists() else "?")
        real(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    write_all({tmp_path / "a.nc": b"G0", tmp_path / "sub" / "b.dxf": b"0"})
    if Path("/proc/self/fd").exists():
        assert [Path(s).name.split(".camfab-tmp-")[0] for s in synced] == [".a.nc", ".b.dxf", tmp_path.name, "sub"]
    else:
        assert len(synced) == 4
    synced.clear()
    write_all({tmp_path / "c.nc": b"G0"}, durable=False)
    assert synced == []
