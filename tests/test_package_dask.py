"""`camfab package` on Dask distributed (camfab/package_dask.py): the same files and manifest as the built-in pool
on a local cluster of two worker processes, a dead worker's cam retried (and recorded when it dies again), a broken
design contained, the incremental rebuild, the command-line errors (docs/decisions.md, "Dask executor")."""
from __future__ import annotations

import hashlib
import json
import logging
import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

import camfab.package
from camfab.cli import main
from tests.conftest import EXAMPLES

ROOT = Path(__file__).resolve().parents[1]
#: outputs of these tests: a drawing, a spreadsheet and a program, quick to make
OUTPUTS = "dxf,xlsx,gcode"
#: the parts of an entry that depend on the run, not on the cam
RUN_KEYS = ("seconds", "cpu_seconds", "timings", "rebuilt")


@pytest.fixture(scope="module")
def cluster():
    """A local Dask cluster of two worker processes with camfab's settings (one retry of a cam whose worker
    dies), made once for the module and closed after it."""
    distributed = pytest.importorskip("distributed", reason="Dask distributed is not installed "
                                                            "(pip install camfab[dask])")
    import dask

    from camfab.package_dask import LOCAL_CONFIG, NO_DASHBOARD

    with dask.config.set(LOCAL_CONFIG):  # read when the scheduler and the nannies start
        c = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                     scheduler_kwargs=NO_DASHBOARD, silence_logs=logging.CRITICAL)
    try:
        yield c
    finally:
        c.close()


def _designs(root: Path, *names: str) -> Path:
    src = root / "designs"
    src.mkdir()
    for name in names:
        shutil.copy(EXAMPLES / name, src)
    return src


def _manifest(out: Path) -> dict:
    return json.loads((out / "manifest.json").read_text())


def _cams(manifest: dict) -> dict[str, dict]:
    """Each cam's entry without what depends on the run (times, rebuilt), by name."""
    return {c["name"]: {k: v for k, v in c.items() if k not in RUN_KEYS} for c in manifest["cams"]}


def _files(out: Path) -> dict[str, str]:
    """Every file camfab wrote under ``out`` but the package's own (manifest, index) with its sha256."""
    return {p.relative_to(out).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(out.rglob("*"))
            if p.is_file() and p.parent != out}


def _dask(cluster, *argv: str) -> int:
    return main(["package", *argv, "--executor", "dask", "--scheduler", cluster.scheduler_address])


def _wait_for_workers(cluster, n: int = 2, timeout: float = 60) -> None:
    """A killed worker is started again by its nanny: wait for it before the next test."""
    t = time.monotonic()
    while len(cluster.scheduler_info.get("workers", {})) < n and time.monotonic() - t < timeout:
        time.sleep(0.2)


# ---------------------------------------------------------------------------
# the workers' numeric kernels (docs/decisions.md, "The same bytes on every x86-64 CPU with AVX2")
def test_local_workers_compute_with_this_processs_kernels(cluster, caplog):
    """They inherit the pinned kernels from this process's environment: no warning.  This process has loaded
    scipy's OpenBLAS beside numpy's and the workers have not (the first full run counted the copies)."""
    import scipy.linalg  # noqa: F401
    from distributed import Client

    from camfab.package_dask import other_kernels

    with Client(cluster, set_as_default=False) as client, caplog.at_level(logging.WARNING, logger="camfab"):
        assert other_kernels(client) == []
    assert not [r for r in caplog.records if r.name.startswith("camfab")]


@pytest.mark.slow
def test_a_worker_with_other_kernels_is_named(caplog, monkeypatch):
    """A worker started with another OpenBLAS core (as a remote machine would pick its own) is named, with the
    variables that give it this machine's kernels."""
    distributed = pytest.importorskip("distributed", reason="Dask distributed is not installed")
    import dask

    from camfab.kernels import OPENBLAS_CORE, cpu_flags, fingerprint
    from camfab.package_dask import LOCAL_CONFIG, NO_DASHBOARD, other_kernels

    flags, mine = cpu_flags(), fingerprint()
    if flags is None or "avx" not in flags or not any(b.startswith("openblas") for b in mine["blas"]) \
            or any(b.endswith(":Sandybridge") for b in mine["blas"]):
        pytest.skip("needs OpenBLAS on an x86-64 CPU with AVX, not already on its Sandybridge core")
    # the worker process inherits it when it starts (a nanny's ``env`` is set after numpy has loaded OpenBLAS)
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Sandybridge")
    with dask.config.set(LOCAL_CONFIG):
        c = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                     scheduler_kwargs=NO_DASHBOARD, silence_logs=logging.CRITICAL)
    try:
        with distributed.Client(c, set_as_default=False) as client, \
                caplog.at_level(logging.WARNING, logger="camfab"):
            other = other_kernels(client)
            workers = list(client.scheduler_info()["workers"])
    finally:
        c.close()
    assert other == workers and len(other) == 1
    text = caplog.text
    assert other[0] in text and "Sandybridge" in text and f"OPENBLAS_CORETYPE={OPENBLAS_CORE}" in text


# ---------------------------------------------------------------------------
# the same package as the built-in pool, and the incremental rebuild
@pytest.mark.slow
def test_dask_builds_the_same_files_and_manifest_as_the_builtin_pool(cluster, tmp_path):
    # a knot file travels with the design that names it (valve_exhaust_ej1 reads valve_recon_ej1.csv)
    src = _designs(tmp_path, "ejemplo9rt.toml", "ejemplo1rt.toml", "ejemplo10ex.toml", "valve_exhaust_ej1.toml",
                   "valve_recon_ej1.csv")
    builtin, dask = tmp_path / "builtin", tmp_path / "dask"
    assert main(["package", str(src), "-o", str(builtin), "--outputs", OUTPUTS, "--jobs", "2"]) == 0
    assert _dask(cluster, str(src), "-o", str(dask), "--outputs", OUTPUTS) == 0
    mb, md = _manifest(builtin), _manifest(dask)
    assert len(md["cams"]) == 4 and md["executor"] == "dask" and mb["executor"] == "builtin"
    assert _cams(md) == _cams(mb)  # verdicts, figures, deviations, file hashes: all identical
    assert _files(dask) == _files(builtin) and len(_files(dask)) == 4 * 4  # check.json, dxf, xlsx, nc per cam
    assert {f["path"]: f["sha256"] for c in md["cams"] for f in c["files"]} == _files(dask)

    # incremental: nothing rebuilt; then a touched design rebuilds alone
    assert _dask(cluster, str(src), "-o", str(dask), "--outputs", OUTPUTS) == 0
    assert not any(c["rebuilt"] for c in _manifest(dask)["cams"])
    f = src / "ejemplo1rt.toml"
    f.write_text(f.read_text().replace("roller_radius_mm = 5.0", "roller_radius_mm = 6.0"))
    assert _dask(cluster, str(src), "-o", str(dask), "--outputs", OUTPUTS) == 0
    m = _manifest(dask)
    assert {c["name"]: c["rebuilt"] for c in m["cams"]} == {"Ejemplo9RT": False, "Ejemplo1RT": True,
                                                             "Ejemplo10EX": False, "ValveExhaustEj1": False}
    assert _cams(m)["Ejemplo1RT"]["files"] != _cams(md)["Ejemplo1RT"]["files"]
    # the key does not depend on the executor: the built-in pool finds the Dask-built cams up to date
    assert main(["package", str(src), "-o", str(dask), "--outputs", OUTPUTS]) == 0
    assert not any(c["rebuilt"] for c in _manifest(dask)["cams"])


# ---------------------------------------------------------------------------
# a worker that dies loses only its cam: retried once, then recorded
def _dies_on(name: str, marker: Path, always: bool = False):
    """``build_cam`` whose worker process dies (``os._exit``) when it takes the cam ``name``: the first time
    only (it leaves ``marker``), or every time.  Shipped to the workers by value (a closure)."""
    real = camfab.package.build_cam

    def build(job):
        if job.name == name and (always or not marker.exists()):
            marker.touch()
            os._exit(1)
        return real(job)

    return build


def test_a_cam_whose_worker_dies_is_retried(cluster, tmp_path, monkeypatch):
    src = _designs(tmp_path, "ejemplo9rt.toml", "ejemplo1rt.toml")
    marker = tmp_path / "died"
    monkeypatch.setattr(camfab.package, "build_cam", _dies_on("Ejemplo1RT", marker))
    out = tmp_path / "out"
    assert _dask(cluster, str(src), "-o", str(out), "--outputs", "xlsx") == 0
    assert marker.exists()  # its worker did die once
    m = _manifest(out)
    assert {c["name"]: c["status"] for c in m["cams"]} == {"Ejemplo9RT": "ok", "Ejemplo1RT": "ok"}
    assert (out / "Ejemplo1RT" / "Ejemplo1RT.xlsx").is_file()
    _wait_for_workers(cluster)


def test_a_cam_whose_worker_dies_twice_is_recorded_and_the_others_built(cluster, tmp_path, monkeypatch, capsys):
    src = _designs(tmp_path, "ejemplo9rt.toml", "ejemplo1rt.toml")
    monkeypatch.setattr(camfab.package, "build_cam", _dies_on("Ejemplo1RT", tmp_path / "died", always=True))
    out = tmp_path / "out"
    t = time.monotonic()
    assert _dask(cluster, str(src), "-o", str(out), "--outputs", "xlsx") == 3  # a lost worker: exit 3, no hang
    assert time.monotonic() - t < 300
    cams = {c["name"]: c for c in _manifest(out)["cams"]}
    lost = cams["Ejemplo1RT"]
    assert lost["status"] == "error" and lost["error_kind"] == "worker" and lost["files"] == []
    assert "died, and again on a retry" in lost["error"]
    assert cams["Ejemplo9RT"]["status"] == "ok" and (out / "Ejemplo9RT" / "Ejemplo9RT.xlsx").is_file()
    assert not (out / "Ejemplo1RT").exists()
    assert "Ejemplo1RT" in capsys.readouterr().err
    _wait_for_workers(cluster)


# ---------------------------------------------------------------------------
# a broken design is contained: one that cannot be read, one that fails on its worker
def test_broken_designs_are_contained(cluster, tmp_path):
    src = _designs(tmp_path, "ejemplo9rt.toml")
    (src / "broken.toml").write_text('name = "Broken"\n[follower]\ntype = "roller"\nbase_radius_mm = -3\n')
    under = (EXAMPLES / "ejemplo9rt.toml").read_text().replace('name = "Ejemplo9RT"', 'name = "Undercut"')
    (src / "undercut.toml").write_text(under.replace("base_radius_mm = 35.0", "base_radius_mm = 12.0")
                                       .replace("roller_radius_mm = 7.0", "roller_radius_mm = 30.0"))
    out = tmp_path / "out"
    assert _dask(cluster, str(src), "-o", str(out), "--outputs", "dxf", "--force") == 2
    cams = {c["name"]: c for c in _manifest(out)["cams"]}
    assert cams["Ejemplo9RT"]["status"] == "ok"
    assert cams["broken"]["status"] == "error" and "follower.base_radius_mm" in cams["broken"]["error"]
    worker = cams["Undercut"]  # read on the worker from its bytes, failed there
    assert worker["status"] == "error" and worker["error_kind"] == "input" and worker["error_type"] == "GeometryError"
    assert "UNDERCUT" in worker["error"] and worker["files"] == []
    assert not (out / "Undercut").exists() and "follower.base_radius_mm" in (out / "index.html").read_text()


def test_a_worker_error_names_the_real_files(tmp_path):
    """A design read on a worker from its bytes: its messages name the files where the user has them."""
    src = _designs(tmp_path, "valve_exhaust_ej1.toml", "valve_recon_ej1.csv")
    (src / "valve_recon_ej1.csv").write_text("angle,s,v,a\n0,0,0,0\n10,oops,0,0\n")
    design = src / "valve_exhaust_ej1.toml"
    job = camfab.package.Job(str(design), "V", "V", "k", {"outputs": ["xlsx"]},
                             tuple((str(p), p.read_bytes()) for p in (design, src / "valve_recon_ej1.csv")))
    entry = camfab.package.build_cam(job)
    assert entry["status"] == "error" and str(src / "valve_recon_ej1.csv") in entry["error"], entry["error"]
    assert "camfab-design-" not in entry["error"]


# ---------------------------------------------------------------------------
# command-line errors: exit 2 naming the option and the fix; an unreachable scheduler exit 3, nothing written
@pytest.mark.parametrize("argv, words", [
    (["--scheduler", "tcp://127.0.0.1:8786"], ["--scheduler", "only with --executor dask"]),
    (["--executor", "dask-local", "--scheduler", "tcp://127.0.0.1:8786"], ["--scheduler", "--executor dask"]),
    (["--executor", "dask"], ["--executor dask needs --scheduler ADDRESS", "dask-local"]),
    (["--dask-workers", "2"], ["--dask-workers 2", "only with --executor dask-local"]),
    (["--executor", "dask-local", "--dask-workers", "0"], ["--dask-workers 0", "at least 1"]),
    (["--executor", "dask-local", "--jobs", "2"], ["--jobs 2", "--dask-workers"]),
    (["--dask-config", "a=1"], ["--dask-config", "only with --executor dask"]),
], ids=["scheduler-without-dask", "scheduler-with-local", "dask-without-scheduler", "workers-without-local",
        "zero-workers", "jobs-with-dask", "config-without-dask"])
def test_executor_option_errors(tmp_path, capsys, argv, words):
    out = tmp_path / "out"
    assert main(["package", str(EXAMPLES / "ejemplo9rt.toml"), "-o", str(out), *argv]) == 2
    err = capsys.readouterr().err
    assert all(w in err for w in words), err
    assert not out.exists()


def test_an_unreachable_scheduler_is_an_error_and_writes_nothing(tmp_path, capsys):
    pytest.importorskip("distributed", reason="Dask distributed is not installed (pip install camfab[dask])")
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    out = tmp_path / "out"
    t = time.monotonic()
    rc = main(["package", str(EXAMPLES / "ejemplo9rt.toml"), "-o", str(out), "--executor", "dask",
               "--scheduler", f"tcp://127.0.0.1:{port}"])
    assert rc == 3 and time.monotonic() - t < 60
    err = capsys.readouterr().err
    assert f"cannot reach the Dask scheduler at tcp://127.0.0.1:{port}" in err and "Traceback" not in err
    assert not out.exists()


def test_without_dask_the_error_names_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    out = tmp_path / "out"
    assert main(["package", str(EXAMPLES / "ejemplo9rt.toml"), "-o", str(out), "--executor", "dask-local"]) == 3
    assert "pip install camfab[dask]" in capsys.readouterr().err
    assert not out.exists()


def test_the_builtin_pool_does_not_import_dask(tmp_path):
    design, out = EXAMPLES / "ejemplo9rt.toml", tmp_path / "o"
    code = ("import sys\nfrom camfab.cli import main\n"
            f"rc = main(['package', r'{design}', '-o', r'{out}', '--outputs', 'xlsx'])\n"
            "print(rc, 'dask' in sys.modules, 'distributed' in sys.modules)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                       env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert r.stdout.splitlines()[-1] == "0 False False", r.stdout + r.stderr


# ---------------------------------------------------------------------------
# Ctrl-C of dask-local: the command reports it; the local workers, in the terminal's process group, stay quiet
@pytest.mark.slow
def test_ctrl_c_of_dask_local_prints_no_worker_traceback(tmp_path):
    """SIGINT to the whole process group (what a terminal's Ctrl-C does) once the first cam is written: exit 130,
    camfab's one-line message, no KeyboardInterrupt from Dask's workers (they ignore SIGINT:
    ``camfab.dask_worker``) and no log of theirs, and no process of the group left a few seconds later."""
    pytest.importorskip("distributed", reason="Dask distributed is not installed (pip install camfab[dask])")
    import signal

    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(Path(camfab.package.__file__).parents[1]))
    p = subprocess.Popen([sys.executable, "-m", "camfab", "package", str(EXAMPLES), "--executor", "dask-local",
                          "--dask-workers", "2", "--outputs", "dxf", "-o", str(out)], env=env, text=True,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    try:
        deadline = time.monotonic() + 240
        while not any(d.is_dir() and not d.name.startswith(".") for d in out.glob("*")) and p.poll() is None:
            assert time.monotonic() < deadline, "no cam was written within 240 s"
            time.sleep(0.05)
        assert p.poll() is None, "the package ended before the interrupt: give it more cams"
        os.killpg(p.pid, signal.SIGINT)
        err = p.communicate(timeout=120)[1]
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
    assert p.returncode == 130, err  # never killed by the signal (camfab.__main__.main)
    # no worker's KeyboardInterrupt traceback, and no heartbeat of a worker that found the scheduler already
    # closed (the workers close first: camfab.package_dask.close_workers_first)
    assert "interrupted" in err and "KeyboardInterrupt" not in err, err
    assert "Traceback" not in err and "heartbeat" not in err, err
    deadline = time.monotonic() + 15
    while subprocess.run(["pgrep", "-g", str(p.pid)], capture_output=True).returncode == 0:
        assert time.monotonic() < deadline, "a process of the command's group is still running"
        time.sleep(0.2)
