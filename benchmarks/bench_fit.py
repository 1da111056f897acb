"""Benchmark: CPU time of the verified arc fit (:func:`camfab.discretize.arcs`) on three profiles.

- the roller cam of issue 15 (Rb 50 mm, Rr 5 mm; cycloidal rise 25 mm over 120°, dwell 60°, cycloidal
  return over 120°, dwell 60°) at 1 µm: arcs, measured deviation and the fit's CPU time;
- the constant-width example (``camfab/examples/constant_width.toml``) at its 1 µm: both profiles;
- 1000 cycloidal segments of ±0.001 mm over 0.36° each (``bench_limits.py``'s smooth case) at 1 µm.

Every figure is CPU time (``time.process_time``, the fit's own process; BLAS is on one thread inside the fit)
averaged over ``--repeat`` runs after one warm-up run: on a shared machine wall time is noisy.  The deviation
printed is the fit's own measurement, and next to it an independent re-measurement with ten times the curve
samples (``measure_deviation(..., samples=200 000)``).

Run:  PYTHONPATH=. python3 benchmarks/bench_fit.py [--repeat 20]
"""
from __future__ import annotations

import argparse
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
    """CPU seconds of one fit of every curve (mean of ``repeat`` after a warm-up) and the fits."""
    fits = [arcs(c, tol=tol) for c in curves]
    t0 = time.process_time()
    for _ in range(repeat):
        for c in curves:
            arcs(c, tol=tol)
    return (time.process_time() - t0) / repeat, fits


def report(label: str, curves: list[ParametricCurve], tol: float, repeat: int) -> None:
    cpu, fits = cpu_per_fit(curves, tol, repeat)
    n = "+".join(str(f.n_entities) for f in fits)
    dev = max(f.max_deviation for f in fits)
    indep = max(measure_deviation(f, c, samples=200_000).max for f, c in zip(fits, curves, strict=True))
    print(f"{label:<44} {n:>9} arcs  dev {dev:.3e} (indep. {indep:.3e}) mm  {1e3 * cpu:9.1f} ms CPU", flush=True)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=20, help="fits averaged (the 1000-segment case: a fifth)")
    args = ap.parse_args(argv)
    report("issue-15 roller cam, 1 µm", [issue_cam_curve()], 1e-3, args.repeat)
    import camfab

    examples = Path(camfab.__file__).resolve().parent / "examples"
    cw = design_curves((examples / "constant_width.toml").read_text(), examples)
    report("constant-width example, 1 µm", cw, 1e-3, max(1, args.repeat // 4))
    report("1000 cycloidal segments ±0.001 mm, 1 µm", design_curves(segments_design(1000, 0.001), HERE), 1e-3,
           max(1, args.repeat // 10))


if __name__ == "__main__":
    main()
