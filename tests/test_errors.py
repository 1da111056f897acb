"""Every deliberate error is a :class:`camfab.errors.CamfabError`, as a gate: no ``raise`` of a builtin
exception anywhere in the package (an AST walk), every exception class camfab defines derives from
CamfabError, and the classes that replaced builtins are still caught as those builtins."""
from __future__ import annotations

import ast
import builtins
import importlib
import inspect
import pkgutil
from pathlib import Path

import pytest

import camfab
from camfab import errors
from camfab.cli import main
from camfab.errors import ApiError, CamfabError, InputError, InternalError

PACKAGE = Path(camfab.__file__).resolve().parent
BUILTIN_EXCEPTIONS = {n for n, v in vars(builtins).items() if isinstance(v, type) and issubclass(v, BaseException)}


def _is_abstract_body(fn: ast.AST) -> bool:
    """A method whose whole body is ``raise NotImplementedError`` (after an optional docstring)."""
    if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
        return False
    body = fn.body[1:] if fn.body and isinstance(fn.body[0], ast.Expr) and \
        isinstance(fn.body[0].value, ast.Constant) and isinstance(fn.body[0].value.value, str) else fn.body
    return len(body) == 1 and isinstance(body[0], ast.Raise)


def _builtin_raises(path: Path, root: Path = PACKAGE) -> list[str]:
    """``raise`` statements of a builtin exception class in one module, except the two protocols Python
    asks for: ``raise NotImplementedError`` as the whole body of a method of a class (an abstract method a
    subclass overrides) and ``raise AttributeError`` in ``__getattr__``.  A bare ``raise``, a re-raise of a
    caught exception (``raise exc``) and a raise of camfab's own classes pass."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    shadowed = {n.name for n in ast.walk(tree) if isinstance(n, ast.ClassDef)}
    out = []

    def visit(node: ast.AST, cls: ast.ClassDef | None, fn: ast.AST | None) -> None:
        if isinstance(node, ast.Raise) and node.exc is not None:
            exc = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
            name = exc.id if isinstance(exc, ast.Name) else None
            if name in BUILTIN_EXCEPTIONS and name not in shadowed:
                abstract = name == "NotImplementedError" and cls is not None and fn is not None \
                    and _is_abstract_body(fn)
                protocol = name == "AttributeError" and getattr(fn, "name", None) == "__getattr__"
                if not (abstract or protocol):
                    out.append(f"{path.relative_to(root.parent)}:{node.lineno}: {ast.unparse(node)}")
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef):
                visit(child, child, None)
            elif isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                visit(child, cls if fn is None else None, child)  # a nested function is no method
            else:
                visit(child, cls, fn)

    visit(tree, None, None)
    return out


def test_no_builtin_exception_raised_in_the_package():
    found = [hit for p in sorted(PACKAGE.rglob("*.py")) for hit in _builtin_raises(p)]
    assert not found, ("raise a camfab.errors class (InputError for a ValueError, ApiError for a TypeError, "
                       "InternalError for a broken invariant) instead of:\n" + "\n".join(found))


def test_the_gate_catches_a_builtin_raise(tmp_path):
    src = tmp_path / "m.py"
    src.write_text("class A:\n    def f(self):\n        raise NotImplementedError\n"
                   "    def g(self, x):\n        if x:\n            raise NotImplementedError('no')\n        return x\n"
                   "def h(x):\n    try:\n        return 1 / x\n    except ZeroDivisionError as exc:\n"
                   "        raise exc\n    raise ValueError(x)\n", encoding="utf-8")
    hits = _builtin_raises(src, root=tmp_path)
    assert [h.split(": ", 1)[1] for h in hits] == ["raise NotImplementedError('no')", "raise ValueError(x)"]


def _camfab_modules():
    for info in pkgutil.walk_packages(camfab.__path__, "camfab."):
        if info.name != "camfab.__main__":
            yield importlib.import_module(info.name)


def test_every_exception_class_of_camfab_is_a_camfab_error():
    classes = {obj for mod in _camfab_modules() for obj in vars(mod).values()
               if inspect.isclass(obj) and issubclass(obj, BaseException) and obj.__module__.startswith("camfab")}
    assert {"InputError", "ApiError", "InternalError", "SpecError", "GcodeError", "UsageError"} <= \
        {c.__name__ for c in classes}
    assert [c.__qualname__ for c in classes if not issubclass(c, CamfabError)] == []


def test_the_errors_module_lists_and_documents_every_class():
    defined = {n for n, v in vars(errors).items() if inspect.isclass(v) and issubclass(v, BaseException)
               and v.__module__ == "camfab.errors"}
    assert defined <= set(errors.__all__)
    for name in defined:
        assert (getattr(errors, name).__doc__ or "").strip(), f"{name} needs a docstring saying when it is raised"
    assert issubclass(InputError, ValueError) and issubclass(ApiError, TypeError)
    assert issubclass(InternalError, RuntimeError)
    assert {"InputError", "ApiError", "InternalError"} <= set(camfab.__all__)


def test_bad_argument_values_raise_input_error_still_a_value_error():
    from camfab.gcode import get_post
    from camfab.numeric import root

    with pytest.raises(InputError, match="unknown post-processor 'heidenhain'; valid: fanuc, grbl, linuxcnc"):
        get_post("heidenhain")
    with pytest.raises(ValueError, match="program_number must be an integer"):
        get_post("fanuc").check_options({"program_number": 0})
    with pytest.raises(InputError, match="bracket a sign change"):
        root(lambda x: x + 5.0, 0.0, 1.0)


def test_wrong_kind_of_object_raises_api_error_still_a_type_error():
    from camfab.design.sizing import optimal_offset
    from camfab.gcode import get_post

    with pytest.raises(ApiError, match="got str"):
        get_post("linuxcnc").dumps("G0 X0")
    cam = camfab.load("ejemplo11ro")  # an oscillating roller
    with pytest.raises(TypeError, match="not a OscillatingRoller"):
        optimal_offset(cam.geometry.mechanism, cam.spec.program())


def test_broken_invariant_raises_internal_error(monkeypatch):
    from camfab.cad import plate

    monkeypatch.setattr(plate, "_KEYWAYS", plate._KEYWAYS[:3])  # the table no longer reaches 230 mm
    with pytest.raises(InternalError, match="no key for bore 100") as info:
        plate.keyway_size(100.0)
    assert isinstance(info.value, RuntimeError)
    assert plate.keyway_size(10.0) == (3.0, 1.4)


def test_cli_maps_camfab_errors_to_exit_2_and_bugs_to_a_traceback(tmp_path, capsys, monkeypatch):
    # a real invalid option combination: GRBL has no cutter compensation (ExportError) → 2, nothing written
    out = tmp_path / "out.nc"
    assert main(["gcode", "ejemplo9rt", "--post", "grbl", "--compensation", "G41", "--tool-diameter", "10",
                 "-o", str(out)]) == 2
    assert "no cutter radius compensation" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
    # an InputError from an API call reached by the command → 2; ApiError/InternalError are bugs: traceback
    for exc, expected in ((InputError("step = 0: must be > 0"), 2), (ApiError("wrong"), ApiError),
                          (InternalError("broken"), InternalError)):
        monkeypatch.setattr("camfab.cli._cam", lambda name, exc=exc: (_ for _ in ()).throw(exc))
        if isinstance(expected, int):
            assert main(["check", "ejemplo9rt"]) == expected
            assert "camfab check: error: step = 0" in capsys.readouterr().err
        else:
            with pytest.raises(expected):
                main(["check", "ejemplo9rt"])
