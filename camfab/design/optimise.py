"""``camfab optimise``: free variables of a design, objectives and constraints, solved with scipy.

The design is handled as its dict (the TOML structure, knot rows inline): a :class:`Variable` writes its value
into a copy, :func:`~camfab.design.spec.design_from_dict` validates it, and the cam is measured on the dense
grid of its breakpoints (:func:`measure`).  The objective is the weighted sum of the objectives, each divided by
its value at the start (so the weights compare like with like; a radius is maximised, the others minimised);
the constraints are inequalities on the measures.  Solvers: SLSQP (gradients by finite differences of the
variables scaled to [0, 1]) or differential evolution with a fixed seed; both deterministic.  The result is never
worse than the start: a solver's answer that is infeasible or scores worse is dropped for the start.

Segment angles keep the 360° sum: the last named angle takes up the change of the others (its bounds become
two constraints).  A new objective or constraint (e.g. the peak contact stress) is one entry of
:data:`OBJECTIVES` / :data:`CONSTRAINTS` and one measure in :func:`measure`.
"""
from __future__ import annotations

import copy
import dataclasses
import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .. import numeric
from ..errors import InputError, Problem, SpecError
from ..records import dataclass, field
from .assemble import is_form_closed, loads_from_spec
from .checks import DEFAULT_PRESSURE_LIMIT_DEG
from .dynamics import ContactDynamics, pair_of
from .kinds import CamKind, ContactKind, FollowerMotion
from .mechanisms import geometry_from_spec, mechanism_from_spec
from .optimise_spec import Method, OptimiseSpec, VariableSpec
from .resolve import END_KEYS
from .spec import DesignSpec, design_from_dict

__all__ = ["Objective", "Constraint", "OBJECTIVES", "CONSTRAINTS", "Variable", "OptimisationProblem", "OptimiseResult",
           "measure", "build_problem", "solve", "pareto_sweep", "change_summary"]


@dataclass(frozen=True)
class Objective:
    """An objective: its measure's key, its title and unit, +1 to minimise or −1 to maximise."""

    measure: str
    title: str
    unit: str
    sense: int


@dataclass(frozen=True)
class Constraint:
    """A constraint: measure ≥ limit (``lower``) or ≤ limit."""

    measure: str
    title: str
    lower: bool


OBJECTIVES: dict[str, Objective] = {
    "min_radius_mm": Objective("min_radius_mm", "minimum radius of curvature", "mm", -1),
    "peak_contact_force_n": Objective("peak_contact_force_n", "peak contact force", "N", +1),
    "peak_acceleration": Objective("peak_acceleration", "peak |acceleration|", "lift unit/s²", +1),
    "peak_pressure_angle_deg": Objective("peak_pressure_angle_deg", "peak |pressure angle|", "°", +1),
}
CONSTRAINTS: dict[str, Constraint] = {
    "min_radius_mm": Constraint("min_radius_mm", "minimum radius of curvature", True),
    "max_pressure_angle_deg": Constraint("peak_pressure_angle_deg", "peak |pressure angle|", False),
    "min_contact_force_n": Constraint("min_contact_force_n", "smallest contact force", True),
    "max_contact_force_n": Constraint("peak_contact_force_n", "peak contact force", False),
}
#: the measures each needs: rollers (a pressure angle), [dynamics] (forces)
_NEEDS_ROLLER = ("peak_pressure_angle_deg",)
_NEEDS_DYNAMICS = ("peak_contact_force_n", "min_contact_force_n")
_BAD = 1e6  # the score of a design that cannot be built


# ---------------------------------------------------------------------------
def measure(spec: DesignSpec, *, fast: bool = False) -> dict[str, float]:
    """The measures of a design, sampled on the dense grid of its breakpoints (every profile): the smallest
    convex radius of curvature (mm; a roller's profile radius 1/κ_p − R_r, a face's ρ), the peak |pressure angle|
    (°, rollers), the peak |acceleration| (lift unit/s²) and, with ``[dynamics]``, the largest and smallest
    contact force (N).

    Raises SpecError (a design whose geometry cannot be built)."""
    if fast:  # a trial of the optimiser: no exact peak search (the result is validated in full at the end)
        prog = spec.knot_table.program(check=False) if spec.knot_table is not None else spec.program()
        mech = mechanism_from_spec(spec)
        found = mech.validate() or mech.validate_motion(prog, bore_mm=spec.manufacturing.bore_mm or None)
        if found:
            raise SpecError(found)
        xs = numeric.dense_grid(np.asarray(prog.breakpoints, float)).x
        if float(np.min(prog.evaluate(xs, (0,))[0])) < -1e-9:
            raise SpecError(Problem("motion_table.rows", None, "the lift goes below the base circle", ""))
        geom = mech.geometry(prog, bore_mm=spec.manufacturing.bore_mm or None)
    else:
        geom = geometry_from_spec(spec)
        prog = spec.program()
    out: dict[str, float] = {}
    radii, angles = [], []
    for c in geom.profiles:
        x = numeric.dense_grid(c.breakpoints).x
        s = c.evaluate_fixed(x)
        if c.kind is ContactKind.ROLLER:
            kmax = float(np.max(np.asarray(s.curvature_pitch)))
            radii.append(1.0 / kmax - c.roller_radius if kmax > 0 else math.inf)
            if s.pressure_angle is not None:
                angles.append(float(np.degrees(np.max(np.abs(s.pressure_angle)))))
        else:
            radii.append(float(np.min(s.rho)))
    out["min_radius_mm"] = min(radii)
    if angles:
        out["peak_pressure_angle_deg"] = max(angles)
    xm = numeric.dense_grid(np.asarray(prog.breakpoints, float)).x
    out["peak_acceleration"] = float(np.max(np.abs(prog.evaluate(xm, (2,))[0]))) * spec.speed ** 2
    if spec.dynamics is not None:
        loads = loads_from_spec(spec.dynamics)
        c0 = geom.profiles[0]
        xs = numeric.dense_grid(c0.breakpoints).x
        if is_form_closed(spec):
            d = pair_of(geom, loads, spec.speed).evaluate(xs)
            n = np.maximum(d.contact_force, d.contact_force_2 if d.contact_force_2 is not None else 0.0)
            out["peak_contact_force_n"] = float(np.max(n))
        else:
            n = ContactDynamics(c0, loads, spec.speed).evaluate(xs).contact_force
            out["peak_contact_force_n"] = float(np.max(n))
            out["min_contact_force_n"] = float(np.min(n))
    return out


# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Variable:
    """A free value of the design dict: where it is (keys and indices), its bounds and how it is named."""

    name: str
    where: tuple[Any, ...]
    lo: float
    hi: float
    start: float
    angle: bool = False  # a segment angle (the 360° sum)

    def put_spec(self, spec: DesignSpec, value: float) -> DesignSpec:
        """A copy of ``spec`` with this variable set to ``value`` (no validation: a trial of the optimiser)."""
        head = self.where[0]
        if head == "follower":
            fol: Any = dataclasses.replace(spec.follower, **{self.where[1]: value})  # type: ignore[arg-type]
            return dataclasses.replace(spec, follower=fol)
        if head == "motion":
            segs = list(spec.motion or ())
            seg, key = segs[self.where[1]], self.where[2]
            if key in END_KEYS:
                ends = list(seg.ends)
                ends[END_KEYS.index(key)] = value
                segs[self.where[1]] = dataclasses.replace(seg, ends=tuple(ends))  # type: ignore[arg-type]
            else:
                segs[self.where[1]] = dataclasses.replace(seg, span=value)
            return dataclasses.replace(spec, motion=tuple(segs))
        mt = dict(spec.motion_table or {})
        rows = [list(r) for r in mt.get("rows", ())]
        rows[self.where[2]][self.where[3]] = value
        mt["rows"] = rows
        return dataclasses.replace(spec, motion_table=mt)

    def put(self, data: dict[str, Any], value: float) -> None:
        node: Any = data
        for k in self.where[:-1]:
            node = node[k]
        node[self.where[-1]] = float(value)


_SEGMENT = re.compile(r"motion\[(\d+)\]\.(angle_deg|length_mm)")
_END = re.compile(r"motion\[(\d+)\]\.(end_v|end_a|end_j)")
_KNOT = re.compile(r"motion_table\.rows\[(\d+)\]\.(s|v|a)")
_FOLLOWER = ("base_radius_mm", "offset_mm", "pivot_distance_mm", "arm_length_mm", "roller_radius_mm")


def _variable(vs: VariableSpec, data: Mapping[str, Any], spec: DesignSpec) -> Variable:
    """The :class:`Variable` a ``[optimise] variables`` entry names, its start value within its bounds."""
    m = _SEGMENT.fullmatch(vs.name)
    if m:
        return _segment_variable(vs, data, int(m.group(1)), m.group(2))
    m = _END.fullmatch(vs.name)
    if m:
        return _end_variable(vs, data, int(m.group(1)), m.group(2))
    m = _KNOT.fullmatch(vs.name)
    if m:
        return _knot_variable(vs, data, int(m.group(1)), "sva".index(m.group(2)) + 1)
    if vs.name.startswith("follower.") and vs.name.split(".", 1)[1] in _FOLLOWER:
        return _follower_variable(vs, data, spec, vs.name.split(".", 1)[1])
    raise _problem(f"{vs.path}.name", vs.name, "unknown optimisation variable",
                   "name motion[i].angle_deg (or length_mm), motion[i].end_v|end_a|end_j (a generic polynomial's "
                   "joint values), motion_table.rows[i].s|v|a, or follower."
                   + "|".join(_FOLLOWER))


def _segment_variable(vs: VariableSpec, data: Mapping[str, Any], i: int, key: str) -> Variable:
    name, p = vs.name, vs.path
    segs = data.get("motion")
    if not isinstance(segs, list) or i >= len(segs):
        raise _problem(f"{p}.name", name, f"the design has {len(segs) if isinstance(segs, list) else 0} "
                       "[[motion]] segments (counted from 0)", "name a segment that exists")
    start = segs[i].get(key)
    if not isinstance(start, (int, float)) or isinstance(start, bool):
        raise _problem(f"{p}.name", name, f"segment {i} has no numeric {key} (\"auto\" spans are solved, not "
                       "free)", "give the segment a numeric span, or free another segment")
    if vs.lo <= 0 or vs.hi > (360.0 if key == "angle_deg" else 1e6):
        raise _problem(f"{p}.lo", [vs.lo, vs.hi], "a segment span must stay in (0, 360]°",
                       "give 0 < lo < hi <= 360")
    return _within(Variable(name, ("motion", i, key), vs.lo, vs.hi, float(start), angle=True), p)


def _end_variable(vs: VariableSpec, data: Mapping[str, Any], i: int, key: str) -> Variable:
    """A generic polynomial's joint value with a generic next segment (the design gives its start)."""
    segs = data.get("motion")
    start = segs[i].get(key) if isinstance(segs, list) and i < len(segs) else None
    if not isinstance(start, (int, float)) or isinstance(start, bool):
        raise _problem(f"{vs.path}.name", vs.name, f"the design gives no {key} on segment {i} (a joint value of "
                       "two adjacent generic polynomials, the start of the search)",
                       f"write {key} on motion[{i}] (a poly5/poly7 followed by another), or free another value")
    return _within(Variable(vs.name, ("motion", i, key), vs.lo, vs.hi, float(start)), vs.path)


def _knot_variable(vs: VariableSpec, data: Mapping[str, Any], i: int, col: int) -> Variable:
    table = data.get("motion_table")
    rows = table.get("rows") if isinstance(table, Mapping) else None
    if not isinstance(rows, list) or not 0 < i < len(rows) - 1:
        n = len(rows) if isinstance(rows, list) else 0
        raise _problem(f"{vs.path}.name", vs.name, f"a knot value of an inner row of the knot table (1 to {n - 2}); "
                       f"the design has {n} rows" if n else "the design has no knot table ([motion_table])",
                       "name an inner knot row (the first and last rows close the cycle)")
    return _within(Variable(vs.name, ("motion_table", "rows", i, col), vs.lo, vs.hi, float(rows[i][col])), vs.path)


def _follower_variable(vs: VariableSpec, data: Mapping[str, Any], spec: DesignSpec, key: str) -> Variable:
    have = _follower_keys(spec)
    val = data.get("follower", {}).get(key)
    if key == "offset_mm" and val is None and key in have:
        val = 0.0
    if not isinstance(val, (int, float)) or isinstance(val, bool) or key not in have:
        raise _problem(f"{vs.path}.name", vs.name, "is not a dimension of this design's follower",
                       "free one of: " + ", ".join(f"follower.{k}" for k in have))
    if key != "offset_mm" and vs.lo <= 0:
        raise _problem(f"{vs.path}.lo", vs.lo, f"{key} must stay a positive length", "give lo > 0")
    return _within(Variable(vs.name, ("follower", key), vs.lo, vs.hi, float(val)), vs.path)


def _follower_keys(spec: DesignSpec) -> tuple[str, ...]:
    from .mechanisms import mechanism_class

    cls = mechanism_class(spec.cam.kind, spec.follower.type, spec.follower.motion)
    have = set(getattr(cls, "required", ())) | set(getattr(cls, "optional", ()))
    return tuple(k for k in _FOLLOWER if k in have)


def _within(v: Variable, p: str) -> Variable:
    if not v.lo <= v.start <= v.hi:
        raise _problem(f"{p}.lo", [v.lo, v.hi], f"the bounds leave out the design's own value {v.start:g}",
                       f"widen the bounds to include {v.start:g} (the start of the search)")
    return v


def _problem(path: str, value: Any, rule: str, fix: str) -> SpecError:
    return SpecError(Problem(path, value, rule, fix))


# ---------------------------------------------------------------------------
@dataclass
class OptimisationProblem:
    """An optimisation problem built from a design: variables, weights, constraints (measure, limit, ≥?)."""

    data: dict[str, Any]
    spec: DesignSpec
    variables: list[Variable]
    weights: dict[str, float]
    limits: list[tuple[str, str, float, bool]]  # (name, measure, limit, lower)
    start: dict[str, float]
    options: OptimiseSpec
    evaluations: int = 0
    base: DesignSpec | None = None  # the start spec, knot rows inline (set by build_problem)
    _cache: dict[bytes, dict[str, float] | None] = field(default_factory=dict)

    # the parameter vector z (scaled to [0, 1]) leaves out the last angle variable, which takes up the rest
    @property
    def free(self) -> list[Variable]:
        angles = [v for v in self.variables if v.angle]
        return [v for v in self.variables if not (angles and v is angles[-1])]

    def values(self, z: np.ndarray) -> dict[str, float]:
        """Every variable's value (the dependent angle's included) at scaled parameters z."""
        out = {v.name: v.lo + float(zi) * (v.hi - v.lo) for v, zi in zip(self.free, z, strict=True)}
        angles = [v for v in self.variables if v.angle]
        if angles:
            total = sum(v.start for v in angles)
            out[angles[-1].name] = total - sum(out[v.name] for v in angles[:-1])
        return out

    def z0(self) -> np.ndarray:
        return np.array([(v.start - v.lo) / (v.hi - v.lo) for v in self.free])

    def design(self, z: np.ndarray) -> dict[str, Any]:
        data = copy.deepcopy(self.data)
        vals = self.values(z)
        for v in self.variables:
            v.put(data, vals[v.name])
        return data

    def trial(self, z: np.ndarray) -> DesignSpec:
        """The start spec with the variables set (not validated: a trial)."""
        spec = self.base if self.base is not None else self.spec
        vals = self.values(z)
        for v in self.variables:
            spec = v.put_spec(spec, vals[v.name])
        return spec

    def measures(self, z: np.ndarray) -> dict[str, float] | None:
        """The measures at z (None: the design is invalid there); memoised."""
        key = np.asarray(z, float).tobytes()
        if key not in self._cache:
            self.evaluations += 1
            try:
                self._cache[key] = measure(self.trial(z), fast=True)
            except (SpecError, InputError, ValueError, ZeroDivisionError, FloatingPointError):
                self._cache[key] = None
        return self._cache[key]

    def score(self, z: np.ndarray, weights: Mapping[str, float] | None = None) -> float:
        m = self.measures(z)
        if m is None:
            return _BAD
        w = self.weights if weights is None else weights
        return float(sum(wi * OBJECTIVES[k].sense * m[k] / _scale(self.start[k]) for k, wi in w.items() if wi))

    def slack(self, z: np.ndarray) -> np.ndarray:
        """Constraint values, ≥ 0 where met (scaled), the dependent angle's bounds included."""
        m = self.measures(z)
        out = []
        for _, key, lim, lower in self.limits:
            if m is None:
                out.append(-1.0)
                continue
            d = (m[key] - lim) if lower else (lim - m[key])
            out.append(d / _scale(lim, self.start[key]))
        angles = [v for v in self.variables if v.angle]
        if angles:
            last = angles[-1]
            val = self.values(z)[last.name]
            span = last.hi - last.lo
            out += [(val - last.lo) / span, (last.hi - val) / span]
        return np.asarray(out, dtype=float)


def _scale(*xs: float) -> float:
    return max(max(abs(x) for x in xs), 1e-9)


def build_problem(data: Mapping[str, Any], spec: DesignSpec) -> OptimisationProblem:
    """The problem of a design's ``[optimise]`` table, checked against the design and its start.

    Raises
    ------
    SpecError
        No ``[optimise]`` table; a variable, objective or constraint that does not apply to the design; a
        single segment angle (the 360° sum leaves it no freedom); an infeasible start — each naming the field
        and the fix.
    """
    opt = spec.optimise
    if opt is None:
        raise SpecError(Problem("optimise", None, "the design has no [optimise] table",
                                'add [optimise] with variables = [{ name = "...", lo = ..., hi = ... }] and '
                                "objectives = { min_radius_mm = 1.0 }"), spec.source)
    try:
        variables = [_variable(v, data, spec) for v in opt.variables]
        _single_span(opt, variables)
        start = measure(spec)
        weights = {k: w for k, w in opt.objectives.items() if w > 0}
        for k in weights:
            _applies(f"optimise.objectives.{k}", OBJECTIVES[k].measure, start)
        limits = _limits(opt, spec, start)
        for i, k in enumerate(opt.pareto or ()):
            _applies(f"optimise.pareto[{i}]", OBJECTIVES[k].measure, start)
    except SpecError as exc:
        raise SpecError(exc.problems, spec.source) from None
    base = spec
    if spec.motion_table is not None and isinstance(data.get("motion_table"), Mapping):
        base = dataclasses.replace(spec, motion_table=dict(data["motion_table"]))
    prob = OptimisationProblem(dict(data), spec, variables, weights, limits, start, opt, base=base)
    _feasible_start(prob, spec.source)
    return prob


def _single_span(opt: OptimiseSpec, variables: Sequence[Variable]) -> None:
    """A single free span cannot change (the spans keep their sum)."""
    spans = [(vs, var) for vs, var in zip(opt.variables, variables, strict=True) if var.angle]
    if len(spans) == 1:
        raise _problem(f"{spans[0][0].path}.name", spans[0][1].name, "a single segment span cannot change: the "
                       "spans keep their sum (360°, or the cam length)", "free at least two segment spans")


def _feasible_start(prob: OptimisationProblem, source: str | None) -> None:
    """The start must meet every constraint (the result is never worse than the start)."""
    for (n, key, lim, lower), s in zip(prob.limits, prob.slack(prob.z0()), strict=False):
        if s < 0:
            title = CONSTRAINTS[n].title if n in CONSTRAINTS else n
            raise SpecError(Problem(f"optimise.constraints.{n}", lim,
                                    f"the start design does not meet it ({title} = {prob.start[key]:.6g}, must be "
                                    f"{'≥' if lower else '≤'} {lim:.6g})",
                                    "relax the limit, or start from a design that meets it (camfab check, camfab "
                                    "size)"), source)


def _applies(path: str, key: str, start: Mapping[str, float]) -> None:
    if key not in start:
        why = "a roller follower (a pressure angle)" if key in _NEEDS_ROLLER else "a [dynamics] section (forces)"
        raise _problem(path, key, f"needs {why}, which this design has not", "remove it, or add what it needs")


def _limits(opt: OptimiseSpec, spec: DesignSpec, start: Mapping[str, float]) -> list[tuple[str, str, float, bool]]:
    """The constraints: those given, then the defaults (no undercut or cusp; the [checks] pressure-angle limit
    of a roller; the [dynamics] safety force of a spring-loaded follower)."""
    out = []
    for n, lim in opt.constraints.items():
        _applies(f"optimise.constraints.{n}", CONSTRAINTS[n].measure, start)
        out.append((n, CONSTRAINTS[n].measure, lim, CONSTRAINTS[n].lower))
    given = set(opt.constraints)
    if "min_radius_mm" not in given:
        out.append(("min_radius_mm", "min_radius_mm", 0.0, True))
    if "max_pressure_angle_deg" not in given and "peak_pressure_angle_deg" in start:
        osc = spec.follower.motion == FollowerMotion.OSCILLATING and spec.cam.kind != CamKind.TRANSLATING
        lim = spec.pressure_angle_limit_deg or DEFAULT_PRESSURE_LIMIT_DEG["oscillating" if osc else "translating"]
        out.append(("max_pressure_angle_deg", "peak_pressure_angle_deg", lim, False))
    if "min_contact_force_n" not in given and "min_contact_force_n" in start and spec.dynamics is not None:
        out.append(("min_contact_force_n", "min_contact_force_n", spec.dynamics.safety_force_n, True))
    return out


# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class OptimiseResult:
    """The outcome: variable values, the measures and scores at the start and the end, the new design dict."""

    values: Mapping[str, float]
    start_values: Mapping[str, float]
    start: Mapping[str, float]
    best: Mapping[str, float]
    score_start: float
    score: float
    improved: bool
    message: str
    evaluations: int
    data: dict[str, Any]
    weights: Mapping[str, float]

    def to_dict(self) -> dict[str, Any]:
        return {"variables": {k: {"start": self.start_values[k], "optimised": v} for k, v in self.values.items()},
                "objectives": dict(self.weights), "score_start": self.score_start, "score": self.score,
                "start": dict(self.start), "optimised": dict(self.best), "improved": self.improved,
                "message": self.message, "evaluations": self.evaluations}


def solve(prob: OptimisationProblem, weights: Mapping[str, float] | None = None) -> OptimiseResult:
    """Minimise the weighted score within the bounds and constraints; never worse than the start."""
    from scipy.optimize import NonlinearConstraint, differential_evolution, minimize

    w = dict(prob.weights if weights is None else weights)
    z0 = prob.z0()
    n = len(z0)
    s0 = prob.score(z0, w)
    opt = prob.options
    best_z, msg = z0, "no free parameter"
    if n:
        f = lambda z: prob.score(np.clip(z, 0.0, 1.0), w)  # noqa: E731
        g = lambda z: prob.slack(np.clip(z, 0.0, 1.0))  # noqa: E731
        if opt.method == Method.DIFFERENTIAL_EVOLUTION:
            cons = NonlinearConstraint(g, 0.0, np.inf) if len(g(z0)) else ()
            res = differential_evolution(f, [(0.0, 1.0)] * n, seed=opt.seed, maxiter=opt.max_iterations,
                                         constraints=cons, polish=False, init="sobol", x0=z0, tol=1e-6,
                                         popsize=6)
        else:
            cons = [{"type": "ineq", "fun": g}] if len(g(z0)) else []
            res = minimize(f, z0, method="SLSQP", bounds=[(0.0, 1.0)] * n, constraints=cons,
                           options={"maxiter": opt.max_iterations, "ftol": 1e-9, "eps": 1e-5})
        z = np.clip(np.asarray(res.x, float), 0.0, 1.0)
        msg = str(res.message)
        ok = prob.measures(z) is not None and bool(np.all(prob.slack(z) >= -1e-9)) and _valid(prob.design(z))
        if ok and prob.score(z, w) < s0:
            best_z = z
        else:
            msg += "; the start kept (the solver's point was no better or broke a constraint)"
    data = prob.design(best_z)
    m = prob.measures(best_z)
    assert m is not None  # the start is valid (build_problem) and best_z is the start or a valid point
    return OptimiseResult(prob.values(best_z), {v.name: v.start for v in prob.variables}, dict(prob.start), m,
                          s0, prob.score(best_z, w), best_z is not z0, msg, prob.evaluations, data, w)


def _valid(data: Mapping[str, Any]) -> bool:
    """The design passes the full validation (exact checks of the motion and the mechanism)."""
    try:
        design_from_dict(data)
    except SpecError:
        return False
    return True


def pareto_sweep(prob: OptimisationProblem, pair: Sequence[str], points: int) -> list[tuple[float, float, float]]:
    """The trade-off of two objectives: for weights (1 − t, t), t from 0 to 1, the optimum's two measures;
    rows (t, measure 1, measure 2)."""
    a, b = pair
    for i, k in enumerate(pair):
        _applies(f"optimise.pareto[{i}]", OBJECTIVES[k].measure, prob.start)
    out = []
    for t in np.linspace(0.0, 1.0, points):
        r = solve(prob, {a: 1.0 - float(t) or 1e-9, b: float(t) or 1e-9})
        out.append((float(t), r.best[OBJECTIVES[a].measure], r.best[OBJECTIVES[b].measure]))
    return out


def change_summary(result: OptimiseResult) -> list[tuple[str, float, float]]:
    """(variable, start, optimised) rows."""
    return [(k, result.start_values[k], v) for k, v in result.values.items()]

