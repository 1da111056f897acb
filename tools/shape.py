"""Code-shape limits: module length, and function length and cyclomatic complexity in the core.

    python3 tools/shape.py            # list every violation; exit 1 if any

Limits (the core issue): no module in ``camfab/`` over :data:`MAX_MODULE_LINES` lines; no function in
``camfab/design/``, ``camfab/numeric.py``, ``camfab/quadrature.py`` or ``camfab/discretize/`` over
:data:`MAX_FUNCTION_LINES` lines (its whole ``def`` including the docstring) or over :data:`MAX_COMPLEXITY`
(McCabe: 1 + one per branch — ``if``/``elif``, conditional expression, loop, ``except``, ``case``,
comprehension and its ``if``s, and each extra operand of ``and``/``or``; nested functions count on their own).
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "camfab"
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 60
MAX_COMPLEXITY = 20
#: where the function limits apply (paths relative to the package)
CORE = ("design/", "numeric.py", "quadrature.py", "discretize/")


class _Complexity(ast.NodeVisitor):
    def __init__(self) -> None:
        self.n = 1

    def generic_visit(self, node: ast.AST) -> None:
        if isinstance(node, (ast.If, ast.IfExp, ast.For, ast.AsyncFor, ast.While, ast.ExceptHandler,
                             ast.match_case)):
            self.n += 1
        elif isinstance(node, ast.BoolOp):
            self.n += len(node.values) - 1
        elif isinstance(node, ast.comprehension):
            self.n += 1 + len(node.ifs)
        for child in ast.iter_child_nodes(node):
            if not isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
                self.visit(child)


def complexity(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """McCabe complexity of one function body (nested functions excluded)."""
    v = _Complexity()
    for stmt in fn.body:
        v.visit(stmt)
    return v.n


def functions(tree: ast.AST):
    """Every function definition in a module, nested ones included, with its qualified name."""
    stack: list[tuple[ast.AST, str]] = [(tree, "")]
    while stack:
        node, prefix = stack.pop()
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield f"{prefix}{child.name}", child
                stack.append((child, f"{prefix}{child.name}."))
            elif isinstance(child, ast.ClassDef):
                stack.append((child, f"{prefix}{child.name}."))


def violations() -> list[str]:
    out: list[str] = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        text = path.read_text(encoding="utf-8")
        nlines = text.count("\n")
        if nlines > MAX_MODULE_LINES:
            out.append(f"camfab/{rel}: {nlines} lines (> {MAX_MODULE_LINES})")
        if not rel.startswith(CORE):
            continue
        for name, fn in functions(ast.parse(text)):
            length = (fn.end_lineno or fn.lineno) - fn.lineno + 1
            cc = complexity(fn)
            if length > MAX_FUNCTION_LINES:
                out.append(f"camfab/{rel}:{fn.lineno} {name}: {length} lines (> {MAX_FUNCTION_LINES})")
            if cc > MAX_COMPLEXITY:
                out.append(f"camfab/{rel}:{fn.lineno} {name}: complexity {cc} (> {MAX_COMPLEXITY})")
    return out


def main() -> int:
    found = violations()
    for v in found:
        print(v)
    print(f"{len(found)} violation(s)")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
