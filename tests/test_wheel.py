"""The layout of the package as shipped: the top-level ``templates/`` and the example designs
(``camfab/examples/``) go into the wheel, and a wheel installed into a fresh virtual environment runs
``camfab run`` and the Python API from another folder with its own templates and examples."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
import tomllib
import zipfile
from pathlib import Path

import pytest

from camfab import assets
from camfab.formats import EXAMPLES_DIR

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
#: what a build needs from the checkout is everything but these
_NOT_SOURCES = shutil.ignore_patterns(".git", "build", "dist", "*.egg-info", "__pycache__", ".*_cache", ".hypothesis",
                                      ".benchmarks", "out", "*.pyc")


def _tree(root: Path) -> list[str]:
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc")


# ---------------------------------------------------------------------------
# fast: the declarations and the checkout
def test_pyproject_lists_every_package_and_maps_the_templates():
    setup = PYPROJECT["tool"]["setuptools"]
    found = {".".join(p.relative_to(ROOT).parts[:-1]) for p in (ROOT / "camfab").rglob("__init__.py")}
    assert set(setup["packages"]) == found | {"camfab.templates"}, "a package is missing from pyproject.toml"
    assert setup["package-dir"] == {"camfab.templates": "templates"}
    assert "examples/**/*" in setup["package-data"]["camfab"] and setup["package-data"]["camfab.templates"] == ["**/*"]
    assert not (ROOT / "camfab" / "templates").exists(), "the templates live in the top-level templates/"


def test_templates_and_examples_are_found_in_the_checkout():
    assert Path(str(assets.templates())).resolve() == ROOT / "templates"
    assert EXAMPLES_DIR == ROOT / "camfab" / "examples"
    assert {"report", "package", "drawing"} <= {p.name for p in (ROOT / "templates").iterdir()}
    assert not any(name.startswith("examples") for name in _tree(ROOT / "templates")), "examples are data, apart"
    assert assets.read_template("package", "index.html.j2").startswith("<!DOCTYPE html>")


def test_a_leftover_empty_folder_is_not_taken_for_the_templates(tmp_path):
    assert not assets._complete(tmp_path)
    for name in ("report", "package"):
        (tmp_path / name).mkdir()
    assert not assets._complete(tmp_path)
    (tmp_path / "drawing").mkdir()
    assert assets._complete(tmp_path)


# ---------------------------------------------------------------------------
# slow: build, install, run elsewhere
def _env() -> dict[str, str]:
    """The environment of the installed interpreter: nothing that points back at the checkout."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "PYTHONSTARTUP")}
    env.update(PYTHONNOUSERSITE="1", PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_ROOT_USER_ACTION="ignore",
               MPLBACKEND="Agg")
    return env


def _sh(argv: list, cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    res = subprocess.run([str(a) for a in argv], cwd=cwd, env=_env(), capture_output=True, text=True,
                         timeout=timeout)
    assert res.returncode == 0, f"{argv}\nstdout:\n{res.stdout}\nstderr:\n{res.stderr}"
    return res


def _can_build_offline() -> bool:
    """setuptools with a bdist_wheel (its own, or the wheel package's) in this interpreter."""
    probe = ("import importlib.util as u, sys; sys.exit(0 if u.find_spec('setuptools') and "
             "(u.find_spec('wheel') or u.find_spec('setuptools.command.bdist_wheel')) else 1)")
    return subprocess.run([sys.executable, "-c", probe], env=_env()).returncode == 0


def _build_wheel(tmp: Path) -> Path:
    """The wheel of a copy of the checkout (a stale ``build/`` in the checkout cannot leak into it).

    With setuptools and wheel installed (the ``test`` extra) the build runs offline in this interpreter;
    otherwise pip gets the build backend of ``[build-system]`` from the configured index."""
    src, dist = tmp / "src", tmp / "dist"
    shutil.copytree(ROOT, src, ignore=_NOT_SOURCES)
    isolation = [] if not _can_build_offline() else ["--no-build-isolation"]
    _sh([sys.executable, "-m", "pip", "wheel", "--no-deps", *isolation, "-q", "-w", dist, "."], cwd=src)
    (wheel,) = dist.glob("camfab-*.whl")
    return wheel


_API = textwrap.dedent("""
    import json, sys
    from pathlib import Path
    import camfab
    from camfab import assets
    from camfab.cad.drawing import load_template
    from camfab.formats import EXAMPLES_DIR
    from camfab.report.overview import index_html

    cam = camfab.load("ejemplo9rt")
    result = cam.run(Path(sys.argv[1]))
    valve = camfab.load("valve_exhaust_ej1")
    print(json.dumps({
        "camfab": camfab.__file__, "templates": str(assets.templates()), "examples_dir": str(EXAMPLES_DIR),
        "templates_hash": assets.templates_hash(), "verdict": str(cam.check().verdict),
        "examples": camfab.examples(), "files": sorted(result.files), "withheld": result.withheld,
        "valve_sources": list(valve.spec.sources), "valve_verdict": str(valve.check().verdict),
        "title_block": sorted(load_template()), "index": index_html({"cams": [], "camfab_version": "0"})[:15],
    }))
""")


def _see_this_environment(python: Path, cwd: Path) -> None:
    """When the tests run in a virtual environment (the project's .venv), its site-packages hold dependencies the
    base interpreter may lack (threadpoolctl on a fresh machine): a ``.pth`` file makes the new environment see
    them after its own site-packages. Their ``.pth`` files are not processed, so the checkout's editable install
    stays out and camfab comes from the wheel."""
    if sys.prefix == sys.base_prefix:
        return
    import site

    purelib = _sh([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=cwd).stdout.strip()
    Path(purelib, "camfab_test_parent_env.pth").write_text("\n".join(site.getsitepackages()) + "\n", encoding="utf-8")


def _verdict(name: str) -> str:
    import camfab

    return str(camfab.load(name).check().verdict)


@pytest.mark.slow
def test_the_wheel_installs_and_runs_from_another_folder(tmp_path):
    wheel = _build_wheel(tmp_path)

    # every template, every example (with its knot files) and every module is inside the wheel
    names = set(zipfile.ZipFile(wheel).namelist())
    expected = ([f"camfab/templates/{n}" for n in _tree(ROOT / "templates")]
                + [f"camfab/examples/{n}" for n in _tree(EXAMPLES_DIR)]
                + [f"camfab/{n}" for n in _tree(ROOT / "camfab") if n.endswith(".py")] + ["camfab/py.typed"])
    assert not set(expected) - names, sorted(set(expected) - names)
    assert any(n.endswith(".csv") for n in names if n.startswith("camfab/examples/"))
    assert not [n for n in names if n.startswith("templates/")], "templates go under camfab/, not top level"

    # a fresh environment: the heavy dependencies come from this one, camfab only from the wheel
    venv = tmp_path / "venv"
    _sh([sys.executable, "-m", "venv", "--system-site-packages", "--without-pip", venv], cwd=tmp_path)
    bindir = venv / ("Scripts" if os.name == "nt" else "bin")
    python = bindir / ("python.exe" if os.name == "nt" else "python")
    _see_this_environment(python, tmp_path)
    _sh([python, "-m", "pip", "install", "--no-deps", "--no-index", "-q", wheel], cwd=tmp_path)

    elsewhere = tmp_path / "elsewhere"  # not the checkout
    elsewhere.mkdir()
    camfab = bindir / ("camfab.exe" if os.name == "nt" else "camfab")
    # the designs' own [outputs]: the built-in example writes its STEP and the assembly STEP (cadquery is a dependency)
    _sh([camfab, "run", "-o", "out"], cwd=elsewhere)  # the built-in example
    _sh([camfab, "run", "valve_exhaust_ej1", "-o", "out2"], cwd=elsewhere)  # an example with a knot file
    for out, name in (("out", "Ejemplo9RT"), ("out2", "ValveExhaustEj1")):
        made = {p.relative_to(elsewhere / out).as_posix() for p in (elsewhere / out).rglob("*") if p.is_file()}
        assert {"report.html", "check.json", f"{name}.dxf", f"{name}_drawing.dxf", f"{name}_drawing.pdf",
                "plots/profile.svg", f"{name}.step", f"{name}_assembly.step"} <= made, (out, sorted(made))
        assert b"<!DOCTYPE html>" in (elsewhere / out / "report.html").read_bytes()[:100]

    api = json.loads(_sh([python, "-c", _API, "api_out"], cwd=elsewhere).stdout)
    inside = venv.resolve()
    for key in ("camfab", "templates", "examples_dir"):
        assert Path(api[key]).resolve().is_relative_to(inside), (key, api[key])
    assert all(Path(s).resolve().is_relative_to(inside) for s in api["valve_sources"])
    assert api["valve_sources"][1].endswith("valve_recon_ej1.csv")
    assert api["templates_hash"] == assets.templates_hash()  # the very templates of the checkout
    assert api["verdict"] == str(_verdict("ejemplo9rt"))
    assert api["valve_verdict"] == str(_verdict("valve_exhaust_ej1"))
    assert api["examples"] == sorted(p.stem for p in EXAMPLES_DIR.glob("*.toml"))
    assert {"report.html", "check.json", "Ejemplo9RT_drawing.dxf"} <= set(api["files"]) and not api["withheld"]
    assert (elsewhere / "api_out" / "report.html").is_file() and api["title_block"] and api["index"]


def test_missing_templates_are_a_broken_install_exit_3_and_nothing_written(tmp_path, monkeypatch, capsys):
    from camfab.cli import main

    monkeypatch.setattr(assets, "_complete", lambda node: False)
    assets.templates.cache_clear()
    try:
        out = tmp_path / "out"
        assert main(["report", "ejemplo9rt", "-o", str(out)]) == 3
        assert "templates are missing" in capsys.readouterr().err
        assert not out.exists() or not any(out.rglob("*"))
    finally:
        assets.templates.cache_clear()
