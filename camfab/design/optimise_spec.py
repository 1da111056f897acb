"""The ``[optimise]`` table of a design (``camfab optimise``): free variables, objective weights, constraints,
the solver and the trade-off sweep — read and checked for shape here; the names are checked against the
design (which segments, knots and follower keys exist) by :func:`camfab.design.optimise.build_problem`.

```toml
[optimise]
method = "slsqp"                  # or "differential_evolution" (seeded: deterministic)
seed = 1
max_iterations = 100
variables = [{ name = "motion[1].angle_deg", lo = 40.0, hi = 80.0 },
             { name = "motion[3].angle_deg", lo = 40.0, hi = 80.0 }]
objectives = { min_radius_mm = 1.0, peak_contact_force_n = 0.5 }   # weights (>= 0)
constraints = { min_radius_mm = 2.0 }                               # limits
pareto = ["min_radius_mm", "peak_contact_force_n"]                 # weight sweep of two objectives
pareto_points = 5
```
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from enum import StrEnum
from typing import Any

from ..records import dataclass
from .validator import Validator

__all__ = ["OptimiseSpec", "VariableSpec", "Method", "OBJECTIVE_NAMES", "CONSTRAINT_NAMES", "optimise_section"]

#: objectives by their key in ``[optimise] objectives`` (weights); the computing is design/optimise.py's
OBJECTIVE_NAMES = ("min_radius_mm", "peak_contact_force_n", "peak_acceleration", "peak_pressure_angle_deg")
#: constraints by their key in ``[optimise] constraints`` (limits)
CONSTRAINT_NAMES = ("min_radius_mm", "max_pressure_angle_deg", "min_contact_force_n", "max_contact_force_n")
_KEYS = ("method", "seed", "max_iterations", "variables", "objectives", "constraints", "pareto", "pareto_points")
MAX_VARIABLES = 64
MAX_PARETO_POINTS = 21


class Method(StrEnum):
    SLSQP = "slsqp"
    DIFFERENTIAL_EVOLUTION = "differential_evolution"


@dataclass(frozen=True, slots=True)
class VariableSpec:
    """A free variable as written: its design-file name and its bounds (the design's units)."""

    name: str
    lo: float
    hi: float
    path: str  # where it is written: optimise.variables[i]


@dataclass(frozen=True, slots=True)
class OptimiseSpec:
    """``[optimise]``, read (see the module docstring)."""

    variables: tuple[VariableSpec, ...]
    objectives: Mapping[str, float]
    constraints: Mapping[str, float]
    method: Method = Method.SLSQP
    seed: int = 1
    max_iterations: int = 100
    pareto: tuple[str, str] | None = None
    pareto_points: int = 5


def optimise_section(v: Validator, t: Mapping[str, Any]) -> OptimiseSpec:
    """Read ``[optimise]`` (problems collected in ``v``)."""
    v.keys(t, _KEYS, "optimise")
    method = v.choice(t, "method", "optimise", Method, Method.SLSQP)
    seed = _integer(v, t, "seed", 1, 0, 2**32 - 1)
    iters = _integer(v, t, "max_iterations", 100, 1, 10000)
    points = _integer(v, t, "pareto_points", 5, 2, MAX_PARETO_POINTS)
    variables = _variables(v, t.get("variables"))
    objectives = _weights(v, t.get("objectives", {"min_radius_mm": 1.0}), "optimise.objectives", OBJECTIVE_NAMES)
    if objectives and not any(w > 0 for w in objectives.values()):
        v.add("optimise.objectives", dict(objectives), "needs at least one weight > 0",
              "e.g. objectives = { min_radius_mm = 1.0 }")
    constraints = _weights(v, t.get("constraints", {}), "optimise.constraints", CONSTRAINT_NAMES, signed=True)
    pareto = t.get("pareto")
    pair: tuple[str, str] | None = None
    if pareto is not None:
        if (not isinstance(pareto, list) or len(pareto) != 2 or not all(p in OBJECTIVE_NAMES for p in pareto)
                or pareto[0] == pareto[1]):
            v.add("optimise.pareto", pareto, "must name two different objectives",
                  'e.g. pareto = ["min_radius_mm", "peak_contact_force_n"]; objectives: ' + ", ".join(OBJECTIVE_NAMES))
        else:
            pair = (str(pareto[0]), str(pareto[1]))
    return OptimiseSpec(variables, objectives, constraints, method, seed, iters, pair, points)


def _integer(v: Validator, t: Mapping[str, Any], key: str, default: int, lo: int, hi: int) -> int:
    val = t.get(key, default)
    if isinstance(val, bool) or not isinstance(val, int) or not lo <= val <= hi:
        v.add(f"optimise.{key}", val, f"must be a whole number from {lo} to {hi}", f"e.g. {key} = {default}")
        return default
    return val


def _variables(v: Validator, rows: Any) -> tuple[VariableSpec, ...]:
    if rows is None:
        v.add("optimise.variables", None, "is required",
              'name the free variables, e.g. variables = [{ name = "follower.base_radius_mm", lo = 30, hi = 60 }]')
        return ()
    if not isinstance(rows, list) or not rows or not all(isinstance(r, Mapping) for r in rows):
        v.add("optimise.variables", rows, "must be a non-empty list of tables { name, lo, hi }",
              'e.g. variables = [{ name = "motion[1].angle_deg", lo = 40, hi = 80 }, ...]')
        return ()
    if len(rows) > MAX_VARIABLES:
        v.add("optimise.variables", f"{len(rows)} variables", f"more than the limit of {MAX_VARIABLES}",
              "free fewer values")
        return ()
    out: list[VariableSpec] = []
    seen: set[str] = set()
    for i, r in enumerate(rows):
        p = f"optimise.variables[{i}]"
        v.keys(r, ("name", "lo", "hi"), p)
        name = r.get("name")
        if not isinstance(name, str) or not name:
            v.add(f"{p}.name", name, "is required (a design key)", 'e.g. name = "follower.base_radius_mm"')
            continue
        if name in seen:
            v.add(f"{p}.name", name, "is named twice", "name each variable once")
            continue
        seen.add(name)
        lo = v.number(r, "lo", p, None, lo=-1e7, hi=1e7)
        hi = v.number(r, "hi", p, None, lo=-1e7, hi=1e7)
        if "lo" not in r or "hi" not in r:
            v.add(f"{p}.{'lo' if 'lo' not in r else 'hi'}", None, "is required (the variable's bounds)",
                  "give lo and hi in the design's units for that key")
            continue
        if lo is None or hi is None:
            continue
        if not lo < hi:
            v.add(f"{p}.hi", hi, f"must be greater than lo = {lo:g}", "give lo < hi")
            continue
        out.append(VariableSpec(name, lo, hi, p))
    return tuple(out)


def _weights(v: Validator, t: Any, path: str, names: tuple[str, ...], *, signed: bool = False) -> dict[str, float]:
    if not isinstance(t, Mapping):
        v.add(path, t, "must be a table of numbers", f"e.g. {path.rsplit('.', 1)[-1]} = {{ {names[0]} = 1.0 }}")
        return {}
    v.keys(t, names, path)
    out: dict[str, float] = {}
    for k in names:
        if k in t:
            val = v.number(t, k, path, None, lo=-1e9 if signed else 0.0, hi=1e9,
                           fix="a limit in the key's unit" if signed else "a weight >= 0")
            if val is not None and math.isfinite(val):
                out[k] = val
    return out
