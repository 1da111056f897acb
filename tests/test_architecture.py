"""The shape of the package, as gates: the layer contract (imports only downwards, function-local imports
included), and the size limits of modules and core functions (``tools/shape.py``)."""
from __future__ import annotations

import ast
import importlib.util
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "camfab"

#: what each part of the package may import from camfab (module-name prefixes); a module not listed here
#: fails the test, so a new package must take its place in the layers
BASE = ("camfab.version", "camfab.errors", "camfab.units", "camfab.tolerances", "camfab.results", "camfab.numeric",
        "camfab.geom2d", "camfab.textsafe", "camfab.limits", "camfab.threads", "camfab.brent", "camfab.sets",
        "camfab.words", "camfab.records", "camfab.installed")
LAYERS: dict[str, tuple[str, ...]] = {
    "camfab.version": (),
    "camfab.errors": ("camfab.textsafe", "camfab.records"),  # messages quote values through textsafe.excerpt
    "camfab.units": (),
    "camfab.tolerances": (),
    "camfab.limits": ("camfab.errors", "camfab.textsafe"),
    "camfab.io": ("camfab.errors",),
    "camfab.textsafe": (),
    "camfab.threads": (),
    "camfab.assets": ("camfab.errors",),
    "camfab.results": ("camfab.errors", "camfab.records"),
    "camfab.numeric": ("camfab.errors", "camfab.quadrature", "camfab.records"),
    "camfab.quadrature": (),
    "camfab.brent": ("camfab.errors", "camfab.textsafe"),  # InputError / InternalError, as numeric
    "camfab.sets": (),
    "camfab.words": (),
    "camfab.records": (),
    "camfab.geom2d": ("camfab.errors", "camfab.tolerances", "camfab.records"),
    "camfab.design": BASE + ("camfab.design",),
    "camfab.discretize": BASE + ("camfab.discretize",),
    "camfab.offset": BASE + ("camfab.design", "camfab.discretize", "camfab.offset"),
    "camfab.formats": BASE + ("camfab.io", "camfab.design", "camfab.formats"),
    "camfab.cad": BASE + ("camfab.io", "camfab.design", "camfab.discretize", "camfab.offset", "camfab.formats",
                          "camfab.cad", "camfab.assets"),
    "camfab.gcode": BASE + ("camfab.io", "camfab.design", "camfab.discretize", "camfab.offset", "camfab.gcode"),
    "camfab.report": BASE + ("camfab.io", "camfab.design", "camfab.discretize", "camfab.offset", "camfab.formats",
                             "camfab.report", "camfab.assets"),
    "camfab.pipeline": BASE + ("camfab.io", "camfab.design", "camfab.discretize", "camfab.offset",
                               "camfab.formats", "camfab.cad", "camfab.gcode", "camfab.report", "camfab.assets",
                               "camfab.pipeline"),
    # (camfab.terminal: its Ctrl-C record tells the containment an interrupt turned into an error from a failure)
    "camfab.package": BASE + ("camfab.io", "camfab.design", "camfab.formats", "camfab.pipeline",
                              "camfab.assets", "camfab.package", "camfab.package_dask", "camfab.cad",
                              "camfab.report", "camfab.terminal"),
    "camfab.package_dask": BASE + ("camfab.kernels",),  # Dask imported inside its functions only
    "camfab.cli": ("camfab",),
    "camfab.terminal": (),
    "camfab.exitcodes": (),
    "camfab.installed": (),
    "camfab.kernels": ("camfab.installed",),
    "camfab.__main__": ("camfab.cli", "camfab.exitcodes", "camfab.kernels"),
    "camfab": ("camfab",),  # the façade re-exports
}
#: calls that read or write files
_FILE_CALLS = ("open", "read_text", "write_text", "read_bytes", "write_bytes", "load_workbook", "mkdir", "unlink")
#: modules that may never be imported at the top of a core module (heavy or optional)
HEAVY = ("cadquery", "OCP", "matplotlib", "jinja2", "playwright")


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports(path: Path) -> list[tuple[int, str, bool]]:
    """(line, absolute module name, at module level) of every import in a module, relative ones resolved."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    me = _module_name(path)
    package = me if path.name == "__init__.py" else me.rpartition(".")[0]
    top = set(id(n) for n in tree.body)
    top |= {id(n) for stmt in tree.body if isinstance(stmt, (ast.If, ast.Try)) for n in ast.walk(stmt)}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name, id(node) in top) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            if not node.module and node.level:  # "from . import x": the submodules themselves
                out += [(node.lineno, f"{name}.{a.name}", id(node) in top) for a in node.names]
            else:
                out.append((node.lineno, name, id(node) in top))
    return out


def _layer(module: str) -> str | None:
    best = None
    for key in LAYERS:
        if (module == key or module.startswith(key + ".")) and (best is None or len(key) > len(best)):
            best = key
    return best


def _modules():
    return sorted(p for p in PACKAGE.rglob("*.py"))


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(ROOT)))
def test_imports_only_go_down(path):
    """Every camfab import, function-local ones included, stays within the module's allowed layers."""
    me = _module_name(path)
    layer = _layer(me)
    assert layer is not None, f"{me} has no place in the layer contract (tests/test_architecture.py)"
    allowed = LAYERS[layer]
    bad = [f"line {line}: {name}" for line, name, _ in _imports(path)
           if name.startswith("camfab") and _layer(name) != layer
           and not any(name == a or name.startswith(a + ".") for a in allowed)]
    assert not bad, f"{me} ({layer}) may import only {allowed}: " + "; ".join(bad)


@pytest.mark.parametrize("path", [p for p in _modules() if _module_name(p).startswith(("camfab.design",
                                                                                       "camfab.numeric",
                                                                                       "camfab.quadrature",
                                                                                       "camfab.discretize"))],
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_core_does_no_io_and_loads_nothing_heavy(path):
    names = [name for _, name, _ in _imports(path)]
    assert not [n for n in names if n.split(".")[0] in HEAVY], names
    assert "camfab.io" not in names
    io = [f"line {n.lineno}" for n in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
          if isinstance(n, ast.Call) and ((isinstance(n.func, ast.Name) and n.func.id == "open") or (
              isinstance(n.func, ast.Attribute) and n.func.attr in _FILE_CALLS))]
    assert not io, f"file access in the core: {io}"


def test_code_shape_limits():
    """No module over 600 lines; no function in the core over 60 lines or McCabe complexity 20."""
    spec = importlib.util.spec_from_file_location("shape", ROOT / "tools" / "shape.py")
    shape = importlib.util.module_from_spec(spec)
    sys.modules["shape"] = shape
    spec.loader.exec_module(shape)
    assert shape.violations() == []


def test_no_private_name_crosses_a_module():
    """A name with a leading underscore is its module's own: no camfab module imports one from another."""
    bad = []
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                bad += [f"{path.relative_to(ROOT)}:{node.lineno} {a.name}" for a in node.names
                        if a.name.startswith("_") and not a.name.startswith("__")]
    assert not bad, "private names imported across modules: " + "; ".join(bad)


#: citations of the team's private digests, which live outside the repository (written with character classes,
#: so this file does not match itself); a parenthesis opening prose on spec, not a call or tuple of a variable
_OUTSIDE = re.compile(
    r"camdas[-]reference|motion[-]laws|profiles[.]md|textbook[.]md|valve[-]case|shared[/]spec"
    r"|spec[/][a-z-]+[.]md|\bspec[ ](?:§|D[0-9])|\bspec['’]s\b"
    r"|(?<![\w.])[(]spec\b(?!\s*(?:[,)\].:=]|$))")
_SCANNED = ("camfab", "tests", "templates", "tools", "benchmarks", "docs", "README.md")


def _text_files():
    for top in _SCANNED:
        base = ROOT / top
        paths = [base] if base.is_file() else sorted(p for p in base.rglob("*") if p.is_file())
        for path in paths:
            rel = path.relative_to(ROOT)
            if rel.parts[:2] == ("tests", "golden") or "__pycache__" in rel.parts:
                continue
            data = path.read_bytes()
            if b"\0" in data:
                continue
            try:
                yield rel, data.decode("utf-8")
            except UnicodeDecodeError:
                continue


def test_no_reference_outside_the_repository():
    """Code, tests, shipped data and docs cite ``docs/decisions.md`` or the original sources by name (the CAM-DAS
    thesis, the textbook chapter, the valve case), never the team's digests outside the repository."""
    bad = [f"{rel}:{n}: {line.strip()}" for rel, text in _text_files()
           for n, line in enumerate(text.splitlines(), 1) if _OUTSIDE.search(line)]
    assert not bad, "references outside the repository:\n" + "\n".join(bad)
