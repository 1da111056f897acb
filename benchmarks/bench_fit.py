"""Benchmark: CPU time of the verified arc fit (:func:`camfab.discretize.arcs`) on three profiles.

- the roller cam of issue 15 (Rb 50 mm, Rr 5 mm; cycloidal rise 25 mm over 120°, dwell 60°, cycloidal
  return over 120°, dwell 60°) at 1 µm: arcs, measured deviation and the fit's CPU time;
- the constant-width example (``camfab/examples/constant_width.toml``) at its 1 µm: both profiles;
- 1000 cycloidal segments of ±0.001 mm over 0.36° each (``bench_limits.py``'s smooth case) at 1 µm.

Every figure is CPU time (``time.process_time``, the fit's own process; BLAS is on one thread inside the fit),
the best of ``--repeat`` fits after one warm-up fit: on a shared machine wall time is noisy.  The deviation
printed is the fit's own measurement, and next to it an independent re-measurement with ten times the curve
samples (``measure_deviation(..., samples=200 000)``).

``--root DIR`` compares with the camfab of another tree (e.g. ``--root /work/main``): every case runs in a fresh
process per tree, the trees alternating ``--rounds`` times, and the best CPU time of each tree is printed with
both fits' arc counts and deviations (and whether the arcs are the same bit for bit).

``--examples`` fits every profile of every example design (``camfab/examples/*.toml``) at 1e-3 and 1e-4 mm and
lists per fit the arcs, the measured deviation and the CPU time; with ``--root`` both trees' fits side by side
(arcs before/after, whether they are the same bit for bit) and the totals.

``--floor`` times what this fit's verification by measurement cannot skip on the issue cam, whatever its search:
the Hermite stand-in's exact evaluations (points and derivatives at its nodes, points at its midpoints), the
certificate's exact curve samples (one evaluation at the nodes the local certificate asks for,
``certify.LocalBound.nodes``) and their distances to the fitted chain (each sample against its own entity and the two
beside it, as the fit's measurement takes them).

``--yardstick`` times the issue cam's fit against the issue's yardstick, a lean numpy evaluation of the same profile
at 361 angles (:func:`lean_evaluation`), and prints the ratio.  ``--examples`` also counts each fit's
equioscillations (the count search's unit of cost).

``--stages`` times the issue cam's fit by stage (CPU around each: the Hermite stand-in, cutting the spans, the
spans' arc-count search, laying the arcs, the certification; the rest), what a faster fitter has to cut.

Run:  PYTHONPATH=. python3 benchmarks/bench_fit.py [--repeat 20] [--root /work/main --rounds 3] [--examples]
      [--stages] [--floor] [--yardstick]
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from camfab.discretize import ParametricCurve, arcs, measure_deviation

HERE = Path(__file__).resolve().parent


def issue_cam_curve() -> ParametricCurve:
    """The profile of issue 15's roller cam (Rb 50, Rr 5, cycloidal ±25 mm over 120°, dwells of 60°)."""
    from camfab.design.assemble import geometry_from_spec
    from camfab.design.spec import design_from_dict
    from camfab.offset import profile_curve

    spec = design_from_dict({
        "name": "issue15",
        "cam": {"kind": "disc", "rotation": "cw", "omega_rad_s": 1.0},
        "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 50.0,
                     "roller_radius_mm": 5.0, "offset_mm": 0.0},
        "motion": [{"law": "cycloidal", "lift": 25.0, "angle_deg": 120.0},
                   {"law": "dwell", "lift": 0.0, "angle_deg": 60.0},
                   {"law": "cycloidal", "lift": -25.0, "angle_deg": 120.0},
                   {"law": "dwell", "lift": 0.0, "angle_deg": 60.0}],
        "manufacturing": {"thickness_mm": 10.0, "bore_mm": 20.0, "tool_diameter_mm": 6.0, "tolerance_mm": 0.001},
    })
    return profile_curve(geometry_from_spec(spec).profiles[0])


def design_curves(text: str, base: Path) -> list[ParametricCurve]:
    """The profile curves of a design given as TOML text (knot files relative to ``base``)."""
    import tomllib

    from camfab.design.assemble import geometry_from_spec
    from camfab.formats.toml_design import design_from_data
    from camfab.offset import profile_curve

    spec = design_from_data(tomllib.loads(text), base_dir=base)
    return [profile_curve(p) for p in geometry_from_spec(spec).profiles]


def segments_design(n: int, lift: float) -> str:
    """``bench_limits.py``'s design of ``n`` alternating cycloidal segments of ``±lift`` mm."""
    sys.path.insert(0, str(HERE))
    from bench_limits import segments

    return segments(n, lift)


def cpu_per_fit(curves: list[ParametricCurve], tol: float, repeat: int) -> tuple[float, list]:
    """CPU seconds of one fit of every curve (best of ``repeat`` after a warm-up) and the fits."""
    fits = [arcs(c, tol=tol) for c in curves]
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        for c in curves:
            arcs(c, tol=tol)
        best = min(best, time.process_time() - t0)
    return best, fits


def cases(repeat: int) -> list[tuple[str, list[ParametricCurve], float, int]]:
    """``(label, curves, tol, repeats)`` of the three benchmark cases."""
    import camfab

    examples = Path(camfab.__file__).resolve().parent / "examples"
    cw = design_curves((examples / "constant_width.toml").read_text(), examples)
    return [("issue-15 roller cam, 1 µm", [issue_cam_curve()], 1e-3, repeat),
            ("constant-width example, 1 µm", cw, 1e-3, max(1, repeat // 4)),
            ("1000 cycloidal segments ±0.001 mm, 1 µm", design_curves(segments_design(1000, 0.001), HERE), 1e-3,
             max(1, repeat // 10))]


def measure_case(index: int, repeat: int) -> dict:
    """One case measured in this process: CPU time, arcs, deviations and a hash of the arcs' bytes."""
    label, curves, tol, rep = cases(repeat)[index]
    cpu, fits = cpu_per_fit(curves, tol, rep)
    digest = hashlib.sha256(b"".join(f.chain().start.tobytes() + f.chain().curvature.tobytes()
                                     + f.chain().length.tobytes() for f in fits)).hexdigest()[:12]
    return {"label": label, "cpu": cpu, "arcs": "+".join(str(f.n_entities) for f in fits),
            "dev": max(f.max_deviation for f in fits), "hash": digest,
            "indep": max(measure_deviation(f, c, samples=200_000).max for f, c in zip(fits, curves, strict=True))}


def report(label: str, curves: list[ParametricCurve], tol: float, repeat: int) -> None:
    cpu, fits = cpu_per_fit(curves, tol, repeat)
    n = "+".join(str(f.n_entities) for f in fits)
    dev = max(f.max_deviation for f in fits)
    indep = max(measure_deviation(f, c, samples=200_000).max for f, c in zip(fits, curves, strict=True))
    print(f"{label:<44} {n:>9} arcs  dev {dev:.3e} (indep. {indep:.3e}) mm  {1e3 * cpu:9.1f} ms CPU", flush=True)


def _run_tree(root: Path, index: int, repeat: int) -> dict:
    """:func:`measure_case` in a fresh process importing camfab from ``root``."""
    env = dict(os.environ, PYTHONPATH=str(root))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--case", str(index), "--repeat",
                          str(repeat)], env=env, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def compare(root: Path, repeat: int, rounds: int, which: list[int]) -> None:
    """The cases ``which`` with this tree and ``root`` alternating in fresh processes: best CPU time of each."""
    here = HERE.parent
    for index in which:
        runs: dict = {"new": [], "old": []}
        for _ in range(rounds):
            runs["old"].append(_run_tree(root, index, repeat))
            runs["new"].append(_run_tree(here, index, repeat))
        old, new = (min(runs[k], key=lambda r: r["cpu"]) for k in ("old", "new"))
        same = "same arcs" if old["hash"] == new["hash"] else "arcs differ"
        print(f"{new['label']:<44} old {old['arcs']:>9} arcs dev {old['dev']:.4e} (indep. {old['indep']:.4e}) "
              f"{1e3 * old['cpu']:8.1f} ms | new {new['arcs']:>9} arcs dev {new['dev']:.4e} "
              f"(indep. {new['indep']:.4e}) {1e3 * new['cpu']:8.1f} ms CPU  ({same})", flush=True)


def example_fits() -> list[dict]:
    """Every profile of every example design fitted at 1e-3 and 1e-4 mm in this process: arcs, deviation, CPU."""
    import camfab
    import camfab.discretize.arcspline as spline

    examples = Path(camfab.__file__).resolve().parent / "examples"
    out = []
    runs = [0]  # equioscillations of the fit (the count search's unit of cost)
    equi = spline.equioscillate

    def counted(*args, **kwargs):
        runs[0] += 1
        return equi(*args, **kwargs)

    spline.equioscillate = counted
    for path in sorted(examples.glob("*.toml")):
        try:
            curves = design_curves(path.read_text(), examples)
        except (AttributeError, TypeError, ValueError):  # no plane profile (the cylindrical cam)
            continue
        for i, c in enumerate(curves):
            for tol in (1e-3, 1e-4):
                runs[0] = 0
                t0 = time.process_time()
                f = arcs(c, tol=tol)
                cpu = time.process_time() - t0
                ch = f.chain()
                digest = hashlib.sha256(ch.start.tobytes() + ch.curvature.tobytes() + ch.length.tobytes())
                out.append({"label": f"{path.stem}[{i}] {tol:g}", "arcs": f.n_entities, "dev": f.max_deviation,
                            "tol": tol, "cpu": cpu, "hash": digest.hexdigest()[:12], "equi": runs[0]})
    return out


def _examples_tree(root: Path) -> list[dict]:
    env = dict(os.environ, PYTHONPATH=str(root))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--examples-json"], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def compare_examples(root: Path | None) -> None:
    """The example fits of this tree (and of ``root``): per fit arcs, deviation, CPU; the totals."""
    new = _examples_tree(HERE.parent)
    old = _examples_tree(root) if root is not None else new
    grow = []
    for o, n in zip(old, new, strict=True):
        same = "same" if o["hash"] == n["hash"] else "differ"
        grow.append(n["arcs"] - o["arcs"])
        flag = "" if n["dev"] <= n["tol"] else "  DEVIATION ABOVE TOL"
        print(f"{n['label']:<40} arcs {o['arcs']:5d} -> {n['arcs']:5d}  dev {o['dev']:.3e} -> {n['dev']:.3e}  "
              f"{1e3 * o['cpu']:8.1f} -> {1e3 * n['cpu']:8.1f} ms  ({same}){flag}", flush=True)
    to, tn = sum(r["arcs"] for r in old), sum(r["arcs"] for r in new)
    print(f"{len(new)} fits: arcs {to} -> {tn} ({100.0 * (tn - to) / to:+.2f} %), largest growth {max(grow)}, "
          f"identical {sum(o['hash'] == n['hash'] for o, n in zip(old, new, strict=True))}, equioscillations "
          f"{sum(r.get('equi', 0) for r in old)} -> {sum(r.get('equi', 0) for r in new)}, CPU "
          f"{sum(r['cpu'] for r in old):.2f} -> {sum(r['cpu'] for r in new):.2f} s, all within tol: "
          f"{all(r['dev'] <= r['tol'] for r in new)}")


def stages(repeat: int) -> None:
    """CPU per stage of the issue cam's 1 µm fit, averaged over ``repeat`` fits after a warm-up (timers wrapped
    around the stages' functions where the fit calls them)."""
    from collections import Counter

    import camfab.discretize.arcspline as spline
    import camfab.discretize.fit as fit

    spent: Counter = Counter()

    def timed(module, name: str, label: str) -> None:
        inner = getattr(module, name)

        def run(*a, **k):
            t = time.process_time()
            try:
                return inner(*a, **k)
            finally:
                spent[label] += time.process_time() - t
        setattr(module, name, run)

    for module, name, label in ((fit, "fit_surrogate", "Hermite stand-in"), (spline, "cut_spans", "cutting spans"),
                                (spline, "_fit_spans", "arc-count search"), (spline, "_span_chains", "laying arcs"),
                                (spline, "certified_deviation", "certification")):
        timed(module, name, label)
    curve = issue_cam_curve()
    arcs(curve, tol=1e-3)
    spent.clear()
    t = time.process_time()
    for _ in range(repeat):
        arcs(curve, tol=1e-3)
    total = (time.process_time() - t) / repeat * 1e3
    print(f"issue-15 roller cam, 1 µm: {total:.1f} ms CPU per fit (mean of {repeat})")
    for label, cpu in spent.items():
        print(f"  {label:18}{cpu / repeat * 1e3:7.1f} ms")
    print(f"  {'the rest':18}{total - sum(spent.values()) / repeat * 1e3:7.1f} ms")


def floor(repeat: int) -> None:
    """CPU of the verification's unavoidable parts on the issue cam (module notes, ``--floor``), mean of ``repeat``."""
    import numpy as np

    from camfab.discretize.certify import CERTIFY_SHARE, LocalBound, curvature_bound
    from camfab.discretize.curve import points_at
    from camfab.discretize.measure import _near_entities, fit_chain_to_curve
    from camfab.discretize.surrogate import HermiteSurrogate, fit_surrogate

    curve = issue_cam_curve()
    fit = arcs(curve, tol=1e-3)
    chain = fit.chain()
    sur, _ = fit_surrogate(curve, 1e-3)
    K, _ = curvature_bound(sur, chain, 1e-3)
    # the certificate's samples: the local bound's nodes (the entities' feet from the chain-to-curve half)
    foot = fit_chain_to_curve(chain, sur)[2]
    nodes = LocalBound(sur, chain, K, foot).nodes(CERTIFY_SHARE * 1e-3, 8 * chain.n)
    assert nodes is not None
    t = nodes[:-1]
    pts = points_at(curve, t)
    # each sample's entity: the chain's entities by their start's nearest sample (the fit's measurement takes them
    # from its projected feet; any assignment costs the same)
    start = np.searchsorted(t, np.linspace(0.0, curve.period, chain.n, endpoint=False))
    owner = np.clip(np.searchsorted(start, np.arange(t.size), side="right") - 1, 0, chain.n - 1)

    def mean(f) -> float:
        f()
        t0 = time.process_time()
        for _ in range(repeat):
            f()
        return (time.process_time() - t0) / repeat * 1e3

    parts = [(f"stand-in, {sur.x.size} nodes (points, derivatives, midpoints)",
              mean(lambda: HermiteSurrogate(curve, x=sur.x).interval_errors())),
             (f"certificate's {t.size} exact samples", mean(lambda: points_at(curve, t))),
             ("their distances to the chain (3 entities each)", mean(lambda: _near_entities(chain, pts, owner)))]
    total = mean(lambda: arcs(curve, tol=1e-3))
    print(f"issue-15 roller cam, 1 µm: {total:.1f} ms CPU per fit (mean of {repeat}); what its verification "
          "cannot skip:")
    for label, ms in parts:
        print(f"  {label:52}{ms:7.2f} ms")
    label = "floor of this fitter's verification"
    print(f"  {label:52}{sum(ms for _, ms in parts):7.2f} ms")


def lean_evaluation(angles: int = 361):
    """The issue cam's profile as a lean numpy evaluation at ``angles`` angles, the issue's yardstick: the two
    cycloids by ``clip`` (their derivative vanishes at both ends, so no mask), the pitch point and its derivative,
    the roller offset along the unit normal.  ``(n, 2)`` points: the profile camfab evaluates, mirrored (the
    angle runs the other way), to the sampling's resolution."""
    import numpy as np

    h, beta, r0, rr = 25.0, 2.0 * np.pi / 3.0, 55.0, 5.0
    th = np.linspace(0.0, 2.0 * np.pi, angles)
    x, y = np.clip(th / beta, 0.0, 1.0), np.clip((th - np.pi) / beta, 0.0, 1.0)
    s = h * (x - y - (np.sin(2.0 * np.pi * x) - np.sin(2.0 * np.pi * y)) / (2.0 * np.pi))
    ds = h / beta * (np.cos(2.0 * np.pi * y) - np.cos(2.0 * np.pi * x))
    c, sn = np.cos(th), np.sin(th)
    r = r0 + s
    px, py = r * sn, r * c
    dx, dy = ds * sn + r * c, ds * c - r * sn
    norm = np.hypot(dx, dy)
    return np.column_stack([px + rr * dy / norm, py - rr * dx / norm])  # (inward: the pitch curve runs clockwise)


def yardstick(repeat: int) -> None:
    """The issue cam's 1 µm fit against :func:`lean_evaluation` at 361 angles: both CPU times (best of many) and
    their ratio (the issue's goal: 300×)."""
    curve = issue_cam_curve()
    fit, _ = cpu_per_fit([curve], 1e-3, repeat)
    lean = float("inf")
    for _ in range(20):
        t0 = time.process_time()
        for _ in range(200):
            lean_evaluation()
        lean = min(lean, (time.process_time() - t0) / 200)
    print(f"issue-15 roller cam: fit {1e3 * fit:.2f} ms CPU, lean numpy evaluation at 361 angles {1e3 * lean:.4f} ms: "
          f"{fit / lean:.0f}x (goal 300x)")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=20, help="fits timed, the best kept (constant width: a quarter, "
                    "1000 segments: a tenth)")
    ap.add_argument("--root", type=Path, help="compare with the camfab of this tree (alternating processes)")
    ap.add_argument("--rounds", type=int, default=3, help="alternations with --root")
    ap.add_argument("--cases", default="0,1,2", help="with --root: the cases compared (0 issue cam, 1 constant "
                    "width, 2 1000 segments)")
    ap.add_argument("--examples", action="store_true", help="every example profile at 1e-3 and 1e-4 mm: arcs, "
                    "deviation, CPU per fit (with --root: both trees)")
    ap.add_argument("--stages", action="store_true", help="the issue cam's fit timed by stage")
    ap.add_argument("--floor", action="store_true", help="what the issue cam's verification cannot skip, timed")
    ap.add_argument("--yardstick", action="store_true", help="the issue cam's fit against a lean numpy evaluation "
                    "of its profile at 361 angles")
    ap.add_argument("--case", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--examples-json", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.examples_json:
        print(json.dumps(example_fits()))
        return
    if args.stages:
        stages(args.repeat)
        return
    if args.floor:
        floor(args.repeat)
        return
    if args.yardstick:
        yardstick(args.repeat)
        return
    if args.examples:
        compare_examples(args.root.resolve() if args.root is not None else None)
        return
    if args.case is not None:
        print(json.dumps(measure_case(args.case, args.repeat)))
        return
    if args.root is not None:
        compare(args.root.resolve(), args.repeat, args.rounds, [int(c) for c in args.cases.split(",")])
        return
    for label, curves, tol, rep in cases(args.repeat):
        report(label, curves, tol, rep)


if __name__ == "__main__":
    main()
