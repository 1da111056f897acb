"""Golden manifest: the sha256 of every artifact of every built-in example, and every machine-readable
output, so that a refactoring can prove it changed nothing.

    python3 tools/golden.py write            # (re)write tests/golden/manifest.json
    python3 tools/golden.py check            # compare the current outputs with it; exit 1 on a difference
    python3 tools/golden.py check --only ejemplo9rt,constant_width
    python3 tools/golden.py write --only ejemplo11ro   # replace those examples' records (a named bug fix)

What is recorded per example (each command run in-process through ``camfab.cli.main``):
``check --json`` (the object itself, so a difference can be read), the ``check`` and ``motion`` tables,
``motion --json`` and ``--csv``, every file of ``run --outputs <all> --force``, the DXF flavours r12 and
spline, G-code for every post, with G41 compensation and as lines only, ``verify --json`` of the
LinuxCNC program, and a ``compare`` of two examples.  Exit codes are recorded too.

Hashes of files made by outside libraries (matplotlib PNG/SVG, cadquery STEP, ezdxf headers) depend on
their versions, so the manifest records the versions; ``check`` compares those files only when the
versions are the same and says so otherwise.  BLAS is pinned to one thread (the arc fit's small
least-squares problems round differently with more threads), and numpy's and OpenBLAS's kernels as the command
line pins them (``camfab.kernels``: AVX-512 machines gave 230 differences before).
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
from camfab.kernels import same_kernels_by_default  # noqa: E402  (imports no numpy)

same_kernels_by_default()  # numpy's and OpenBLAS's kernels as the command line pins them, before numpy is imported

import argparse  # noqa: E402
import concurrent.futures  # noqa: E402
import contextlib  # noqa: E402
import hashlib  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
from importlib import metadata  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = ROOT / "tests" / "golden" / "manifest.json"
#: files whose bytes come from an outside library's writer (compared only at equal versions)
_LIBRARY_MADE = (".png", ".svg", ".step", ".xlsx", ".pdf", ".igs")
_VERSIONED = ("numpy", "scipy", "matplotlib", "ezdxf", "cadquery", "cadquery-ocp", "openpyxl", "trimesh",
              "shapely", "jinja2", "mapbox_earcut")
_ALL = "dxf,step,stl,gcode,lift_table,xlsx,report,drawing,pdf,assembly,iges"


def _versions() -> dict[str, str | None]:
    out: dict[str, str | None] = {}
    for name in _VERSIONED:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def _examples() -> list[str]:
    from camfab.formats import EXAMPLES_DIR

    return sorted(p.stem for p in EXAMPLES_DIR.glob("*.toml"))


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _cli(argv: list[str]) -> tuple[int, str]:
    from camfab.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue()


def _files(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): _sha(p.read_bytes()) for p in sorted(root.rglob("*")) if p.is_file()}


def record(name: str, tmp: Path) -> dict:
    """Every output of one example."""
    rec: dict = {"exit": {}, "sha256": {}}
    code, text = _cli(["check", name, "--json"])
    rec["exit"]["check"] = code
    rec["check_json"] = json.loads(text)
    for label, argv in (("check_table", ["check", name]), ("motion_table", ["motion", name]),
                        ("motion_json", ["motion", name, "--json"])):
        code, text = _cli(argv)
        rec["exit"][label] = code
        rec["sha256"][label] = _sha(text.encode())
    csv = tmp / f"{name}_motion.csv"
    rec["exit"]["motion_csv"], _ = _cli(["motion", name, "--csv", str(csv)])
    if csv.exists():
        rec["sha256"]["motion.csv"] = _sha(csv.read_bytes())
    run = tmp / f"{name}_run"
    rec["exit"]["run"], _ = _cli(["run", name, "-o", str(run), "--outputs", _ALL, "--force"])
    if run.exists():
        rec["sha256"].update({f"run/{k}": v for k, v in _files(run).items()})
    for flavour in ("r12", "spline"):
        d = tmp / f"{name}_{flavour}"
        rec["exit"][f"export_{flavour}"], _ = _cli(["export", name, "--dxf", "--dxf-flavour", flavour, "--force",
                                                   "-o", str(d)])
        if d.exists():
            rec["sha256"].update({f"export_{flavour}/{k}": v for k, v in _files(d).items()})
    variants = {"fanuc": ["--post", "fanuc"], "grbl": ["--post", "grbl"],
                "g41": ["--post", "linuxcnc", "--compensation", "G41"],
                "lines": ["--post", "linuxcnc", "--lines-only"], "linuxcnc": ["--post", "linuxcnc"]}
    for label, extra in variants.items():
        d = tmp / f"{name}_gcode_{label}"
        d.mkdir()
        code, _ = _cli(["gcode", name, *extra, "--force", "-o", str(d / "cam.nc")])
        rec["exit"][f"gcode_{label}"] = code
        rec["sha256"].update({f"gcode_{label}/{k}": v for k, v in _files(d).items()})
    prog = tmp / f"{name}_gcode_linuxcnc" / "cam.nc"
    if prog.exists():
        code, text = _cli(["verify", str(prog), "--design", name, "--json"])
        rec["exit"]["verify"] = code
        rec["verify_json"] = json.loads(text) if text.strip() else None  # refused (exit 2): no report
    return rec


def _record_one(name: str, d: Path) -> dict:
    print(f"  {name}", file=sys.stderr)
    return record(name, d)


def build(names: list[str], jobs: int = 1) -> dict:
    out: dict = {"versions": _versions(), "examples": {}}
    with tempfile.TemporaryDirectory() as t:
        tmp = Path(t)
        dirs = [tmp / name for name in names]
        for d in dirs:
            d.mkdir()
        if jobs > 1:  # each example in its own process: the bytes must not depend on the process's history
            with concurrent.futures.ProcessPoolExecutor(jobs) as pool:
                for name, rec in zip(names, pool.map(_record_one, names, dirs), strict=True):
                    out["examples"][name] = rec
        else:
            for name, d in zip(names, dirs, strict=True):
                out["examples"][name] = _record_one(name, d)
        if {"ejemplo9rt", "ejemplo1rt"} <= set(names):
            cmp_dir = tmp / "compare"
            code, _ = _cli(["compare", "ejemplo9rt", "ejemplo1rt", "-o", str(cmp_dir)])
            out["compare"] = {"exit": code, "sha256": _files(cmp_dir) if cmp_dir.exists() else {}}
    return out


def _diff(old: dict, new: dict, same_versions: bool) -> list[str]:
    probs: list[str] = []
    for name, rec in new["examples"].items():
        ref = old["examples"].get(name)
        if ref is None:
            probs.append(f"{name}: not in the manifest")
            continue
        if ref["exit"] != rec["exit"]:
            probs.append(f"{name}: exit codes {ref['exit']} -> {rec['exit']}")
        for key in ("check_json", "verify_json"):
            if ref.get(key) != rec.get(key):
                probs.append(f"{name}: {key} differs: " + _first_difference(ref.get(key), rec.get(key)))
        keys = set(ref["sha256"]) | set(rec["sha256"])
        for k in sorted(keys):
            if not same_versions and k.endswith(_LIBRARY_MADE):
                continue
            if ref["sha256"].get(k) != rec["sha256"].get(k):
                probs.append(f"{name}: {k} " + ("missing" if k not in rec["sha256"] else
                                                 "new" if k not in ref["sha256"] else "differs"))
    if "compare" in new and old.get("compare") != new["compare"] and same_versions:
        probs.append("compare differs")
    return probs


def _first_difference(a, b, path: str = "") -> str:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if a.get(k) != b.get(k):
                return _first_difference(a.get(k), b.get(k), f"{path}.{k}")
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            if x != y:
                return _first_difference(x, y, f"{path}[{i}]")
    return f"{path or '.'}: {a!r} -> {b!r}"[:400]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mode", choices=("write", "check"))
    ap.add_argument("--only", help="comma list of examples")
    ap.add_argument("--jobs", type=int, default=1, help="examples built in parallel processes")
    args = ap.parse_args(argv)
    names = _examples()
    if args.only:
        names = [n for n in names if n in args.only.split(",")]
    new = build(names, args.jobs)
    if args.mode == "write":
        if args.only:  # replace the named examples' records, keep the rest
            old = json.loads(MANIFEST.read_text())
            if old["versions"] != new["versions"]:
                print("library versions differ from the manifest's: write them all", file=sys.stderr)
                return 2
            old["examples"].update(new["examples"])
            new = old
        MANIFEST.parent.mkdir(parents=True, exist_ok=True)
        MANIFEST.write_text(json.dumps(new, indent=1, sort_keys=True) + "\n")
        print(f"wrote {MANIFEST}")
        return 0
    old = json.loads(MANIFEST.read_text())
    same = old["versions"] == new["versions"]
    if not same:
        print("library versions differ from the manifest's: files written by them are not compared",
              file=sys.stderr)
    probs = _diff(old, new, same)
    for p in probs:
        print(p)
    print(f"{len(names)} example(s): " + ("identical" if not probs else f"{len(probs)} difference(s)"))
    return 1 if probs else 0


if __name__ == "__main__":
    sys.exit(main())
