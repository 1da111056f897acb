"""The HTML report of one design: plots, conclusions, follower dynamics, findings, inputs and an animation.

:func:`render_report` returns the files of a report directory as
``{relative path: bytes}`` — ``report.html`` plus ``plots/<name>.svg`` (and, when asked,
``plots/<name>.png``) — and writes nothing (see :func:`write_files`).  The page is
rendered from the jinja2 templates in the repository's ``templates/report/``
(shipped in the wheel, found by :mod:`camfab.assets`); it needs no network: the stylesheet and
the animation script are inlined, the plots are relative ``<img>`` links (or
``data:`` URIs with ``standalone=True``).  The output is deterministic: no
timestamps, rounded animation frames, byte-stable plots.
"""
from __future__ import annotations

import base64
import dataclasses
import functools
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..assets import read_template
from ..errors import MissingDependencyError
from ..results import DynamicsSummary, IssueCode, Severity
from ._common import (
    VERDICT_CLASS,
    VERDICT_TEXT,
    axis_of,
    conclusions_rows,
    fmt,
    fmt_at,
    key_values,
    mechanism_text,
    range_text,
    table_cell,
)

__all__ = ["render_report", "write_files", "template_environment", "report_context", "dynamics_rows", "PLOT_TEXT",
           "CURVED_PLOT_TEXT", "plot_text", "require_report_dependencies"]

#: file stem → (title, caption) of every report plot
PLOT_TEXT = {
    "svaj": ("Motion diagrams S, V, A, J",
             "Displacement, velocity, acceleration and jerk at the design speed; dotted lines are segment "
             "junctions, dots the exact extremes."),
    "profile": ("Cam profile",
                "Cam frame (the follower sits at +Y at 0°); contact points every 30°, labelled every 90°; "
                "R min/R max are the smallest and largest radii of the profile (Ø min/Ø max their diameters)."),
    "curvature": ("Radius of curvature",
                  "Signed: positive is convex. A roller needs the convex pitch radius to exceed the roller radius "
                  "(else undercut); red bands mark undercuts, cusps and stretches too tight for the cutter."),
    "pressure_angle": ("Pressure angle",
                       "Angle between the line of action and the follower's motion; red beyond the limit."),
    "face_position": ("Flat-face contact position",
                      "Where the cam touches the face; the green band is the face length needed."),
    "dynamics": ("Follower dynamics",
                 "Contact force between cam and follower (spring, inertia, damping and loads at the design "
                 "speed) against the safety force; red bands: the follower leaves the cam, orange: below the "
                 "safety force, purple: self-locking. Below: the drive torque (drive force of a translating "
                 "cam) that keeps the speed constant."),
    "contact_stress": ("Contact stress",
                       "Hertz line-contact stress between cam and follower from the contact force, the radii of "
                       "curvature and the face width; the dashed line is the allowable contact stress of the "
                       "materials, red bands the stretches above it."),
}
#: what changes in :data:`PLOT_TEXT` for a curved-face follower (its pitch curve is the path of the face's
#: centre of curvature; its contact runs along the face)
CURVED_PLOT_TEXT = {
    "profile": ("Cam profile",
                "Cam frame (the follower sits at +Y at 0°); contact points every 30°, labelled every 90°; "
                "R min/R max are the smallest and largest radii of the profile (Ø min/Ø max their diameters). "
                "The path of the face's centre "
                "of curvature, a face radius further out, is in the workbook and on the DXF's PITCH_CURVE layer."),
    "curvature": ("Radius of curvature",
                  "Signed: positive is convex. A curved face touches the cam as a roller of the face radius centred "
                  "at the face's centre of curvature, so ρ is the radius of that centre's path less the face "
                  "radius and must stay positive (else undercut); red bands mark undercuts, cusps and stretches "
                  "too tight for the cutter."),
    "face_position": ("Curved-face contact position",
                      "Where the cam touches the face (from the stem axis for a translating face, the arc length "
                      "from the vertex for a face on an arm); the green band is the face length needed."),
}


def plot_text(geometry) -> dict[str, tuple[str, str]]:
    """The (title, caption) of every report plot for ``geometry``: :data:`PLOT_TEXT`, with the curved face's
    words when a contact is one."""
    if any(c.curved_face for c in geometry.profiles):
        return {**PLOT_TEXT, **CURVED_PLOT_TEXT}
    return PLOT_TEXT


#: finding codes of the follower dynamics (the contact-force row of the dynamics table)
_DYNAMICS_CODES = ((IssueCode.SELF_LOCKING, "Friction wedges the follower: see the findings"),
                   (IssueCode.FOLLOWER_JUMP, "The follower leaves the cam (N < 0): see the findings"),
                   (IssueCode.CONTACT_FORCE_BELOW_SAFETY, "Below the safety force {fs:g} N: see the findings"))
_SEVERITY_ORDER = {Severity.ERROR: 0, Severity.WARNING: 1, Severity.INFO: 2}


def require_report_dependencies() -> None:
    """Raise :class:`~camfab.errors.MissingDependencyError` (exit code 3) without jinja2 or matplotlib."""
    for mod in ("jinja2", "matplotlib"):
        try:
            __import__(mod)
        except ImportError as exc:
            raise MissingDependencyError(f"HTML reports need {mod}: pip install {mod}") from exc


def _read_asset(name: str) -> str:
    return read_template("report", name)


@functools.lru_cache(maxsize=1)
def template_environment():
    """The jinja2 environment of the report templates (autoescaping on, loaded from the package); one per
    process, so each template is compiled once, not on every page (27 ms CPU each time otherwise)."""
    import jinja2

    def load(name: str):
        try:
            return _read_asset(name)
        except FileNotFoundError:
            return None

    return jinja2.Environment(loader=jinja2.FunctionLoader(load), autoescape=True, trim_blocks=False,
                              keep_trailing_newline=True, undefined=jinja2.StrictUndefined)


def script_json(data: Any) -> str:
    """JSON safe to put inside ``<script type="application/json">``."""
    text = json.dumps(data, separators=(",", ":"), ensure_ascii=False, allow_nan=False)
    return text.replace("&", "\\u0026").replace("<", "\\u003c").replace(">", "\\u003e")


def common_context(source: str | None) -> dict[str, Any]:
    """Keys every page template needs: version, css, source name."""
    from markupsafe import Markup

    from ..version import __version__

    return {"version": __version__, "css": Markup(_read_asset("report.css")),
            "source": Path(source).name if source else None}


def plot_files(figures: Mapping[str, Any], *, standalone: bool = False, png: bool = False,
               text: Mapping[str, tuple[str, str]] | None = None) -> tuple[dict[str, bytes], list[dict]]:
    """Render figures to ``plots/<name>.svg`` (and ``.png`` with ``png``) and describe them for the templates
    (titles and captions from ``text``, default :data:`PLOT_TEXT`).  The page shows the SVG; each format is a
    full render of the figure, so the PNG is made only when asked (docs/decisions.md, "Report plots")."""
    text = PLOT_TEXT if text is None else text
    from .plots import figure_bytes

    files: dict[str, bytes] = {}
    plots = []
    for name, fig in figures.items():
        svg = figure_bytes(fig, "svg")
        files[f"plots/{name}.svg"] = svg
        if png:
            files[f"plots/{name}.png"] = figure_bytes(fig, "png")
        w, h = (fig.get_size_inches() * 110).round().astype(int)
        title, caption = text.get(name, (name.replace("_", " ").capitalize(), ""))
        src = ("data:image/svg+xml;base64," + base64.b64encode(svg).decode("ascii")) if standalone \
            else f"plots/{name}.svg"
        plots.append({"name": name, "title": title, "caption": caption, "src": src,
                      "png": f"plots/{name}.png" if png else None, "svg": f"plots/{name}.svg",
                      "width": int(w), "height": int(h)})
    return files, plots


def _highlights(spec, report) -> list[str]:
    """The worst values in words (for the verdict box)."""
    xu = "°" if report.x_unit == "deg" else " mm"
    out = []
    lu = spec.follower.lift_unit
    units = {"V": f"{lu}/s", "A": f"{lu}/s²", "J": f"{lu}/s³"}
    if report.motion is not None:
        for q, word, p in (("V", "velocity", report.motion.peaks.V), ("A", "acceleration", report.motion.peaks.A),
                           ("J", "jerk", report.motion.peaks.J)):
            big, at = (p.max, p.at_max) if abs(p.max) >= abs(p.min) else (p.min, p.at_min)
            out.append(f"Largest {word} {fmt(big)} {units[q]} at {at:.1f}{xu}")
    pa = report.pressure_angle
    if pa is not None:
        big, at = (pa.max, pa.at_max) if abs(pa.max) >= abs(pa.min) else (pa.min, pa.at_min)
        out.append(f"Largest pressure angle {fmt(big)}° at {at:.1f}{xu} (limit ±{pa.limit:g}°)")
    roc = report.curvature
    if roc is not None and roc.min_convex is not None:
        out.append(f"Smallest convex radius of curvature {fmt(roc.min_convex)} mm at {roc.at_min_convex:.1f}{xu}")
    face = report.face_length
    if face is not None and face.left is not None:
        out.append(f"Face length needed {fmt(face.left)} mm left and {fmt(face.right)} mm right of the stem")
    dyn = report.dynamics
    if dyn is not None and dyn.form_closed:
        n = len(dyn.load_reversals or ())
        between = "the groove's flanks" if dyn.flanks else "the followers"
        out.append(f"Form-closed follower: the load passes between {between} {n} time{'s' if n != 1 else ''} "
                   "per cycle")
    elif dyn is not None:
        cf = dyn.contact_force
        out.append(f"Smallest contact force {fmt(cf.min)} N at {fmt_at(cf.at_min, xu.strip())} "
                   f"(safety force {dyn.safety_force_n:g} N)")
    cs = report.contact_stress
    if cs is not None and cs.max_mpa is not None:
        out.append(f"Largest contact stress {fmt(cs.max_mpa)} MPa at {fmt_at(cs.at, xu.strip())} (allowable "
                   f"{cs.allowable_mpa:g} MPa, safety factor {cs.safety_factor:.3g})")
    return out


def _row(concept: str, mx: dict, mn: dict, comment: str, status: str = "ok") -> dict[str, Any]:
    return {"concept": concept, "max": mx, "min": mn, "comment": comment, "status": status}


def dynamics_rows(spec, report) -> list[dict[str, Any]]:
    """The follower-dynamics table (rows as :func:`~camfab.report._common.conclusions_rows`: ``concept``,
    ``max`` and ``min`` cells, ``comment``, ``status``); single values sit in the ``max`` cell.
    Empty without a ``dynamics`` summary."""
    dyn = report.dynamics
    if dyn is None:
        return []
    xu = "°" if report.x_unit == "deg" else "mm"
    if dyn.form_closed:
        return _pair_rows(dyn, report, xu)
    fs, codes, none = dyn.safety_force_n, report.codes(), table_cell(None)
    cf = dyn.contact_force
    bad = next((text.format(fs=fs) for code, text in _DYNAMICS_CODES if code in codes), None)
    ok_text = f"Never below the safety force {fs:g} N" if fs > 0 else "The follower stays on the cam"
    rows = [_row("Contact force (N)", table_cell(cf.max, cf.at_max, xu), table_cell(cf.min, cf.at_min, xu),
                 bad or ok_text, "bad" if bad else "ok"),
            _row("Safety force (N)", table_cell(fs), none, "Smallest acceptable contact force (design input)")]
    return rows + _drive_rows(dyn, report, xu) + _limit_rows(spec, dyn, xu)


def _pair_rows(dyn: DynamicsSummary, report, xu: str) -> list[dict[str, Any]]:
    """The dynamics table of a form-closed follower: both contact forces and the load reversals."""
    none, rows = table_cell(None), []
    second = dyn.second_contact_force
    assert second is not None  # a form-closed summary carries follower 2's contact force
    names, other = dyn.contact_names, "flank" if dyn.flanks else "follower"
    for k, cf in ((0, dyn.contact_force), (1, second)):
        rows.append(_row(f"Contact force, {names[k]} (N)", table_cell(cf.max, cf.at_max, xu),
                         table_cell(cf.min, cf.at_min, xu),
                         "Form closure: the follower cannot leave the cam" if k == 0 else
                         f"Pushes where the {names[0]} cannot (the load has changed sides)"))
    rev = dyn.load_reversals or ()
    where = ", ".join(f"{a:.1f}{xu}" for a, _ in rev) or "never"
    rows.append(_row("Load reversals", {**none, "text": str(len(rev))}, none,
                     f"The load passes to the other {other} at {where}: across a clearance the follower knocks"))
    return rows + _drive_rows(dyn, report, xu)


def _drive_rows(dyn: DynamicsSummary, report, xu: str) -> list[dict[str, Any]]:
    """Bearing force, drive torque (force), work per cycle and mean power rows."""
    none, rows = table_cell(None), []
    b = dyn.bearing_force
    rows.append(_row("Bearing force (N)", table_cell(b.max, b.at_max, xu), none,
                     "Largest load on the camshaft bearings" if report.x_unit == "deg"
                     else "Largest load on the plate's guides"))
    torque, t = dyn.torque, dyn.drive
    rows.append(_row("Drive torque (N·m)" if torque else "Drive force (N)", table_cell(t.max, t.at_max, xu),
                     table_cell(t.min, t.at_min, xu),
                     f"{'Torque' if torque else 'Force'} that keeps the speed constant (negative: the follower "
                     "drives the cam)"))
    rows.append(_row("Work per cycle (J)", table_cell(dyn.work_per_cycle_j), none,
                     "Energy lost to damping and friction in one cycle"))
    rows.append(_row("Mean power (W)", table_cell(dyn.mean_power_w), none, "Mean drive power at the design speed"))
    return rows


def _limit_rows(spec, dyn: DynamicsSummary, xu: str) -> list[dict[str, Any]]:
    """The preload-needed and jump-speed rows of :func:`dynamics_rows` (bad when the design misses them)."""
    fs, none, rows = dyn.safety_force_n, table_cell(None), []
    # a spring-loaded (not form-closed) summary carries both
    assert dyn.preload_needed is not None and dyn.jump_speed is not None
    pre, have = dyn.preload_needed, spec.dynamics.spring_preload if spec.dynamics is not None else None
    short = have is not None and not have >= pre.value - 1e-9 * max(1.0, abs(pre.value))
    rows.append(_row(f"Preload needed ({pre.unit})", table_cell(pre.value, pre.at, xu), none,
                     f"Spring preload that keeps the contact force ≥ {fs:g} N"
                     + (f" (the design has {have:g} {pre.unit})" if have is not None else ""),
                     "bad" if short else "ok"))
    js = dyn.jump_speed
    design = spec.speed * 30 / math.pi if xu == "°" else spec.speed
    cell = table_cell(js.value, js.at, xu) if js.value is not None else {**none, "text": "never"}
    slow = js.value is not None and js.value <= design
    rows.append(_row(f"Jump speed ({js.unit})", cell, none,
                     f"Speed at which the contact force first falls to {fs:g} N (design: {design:.6g} "
                     f"{js.unit})", "bad" if slow else "ok"))
    return rows


def _inputs(spec) -> list[dict[str, Any]]:
    c, f, m = spec.cam, spec.follower, spec.manufacturing
    if spec.is_translating_cam:
        speed = f"{spec.speed:g} mm/s"
    else:
        speed = f"{c.omega_rad_s:.6g} rad/s ({c.omega_rad_s * 30 / math.pi:.6g} rpm)"
    cam = [("kind", c.kind), ("direction" if spec.is_translating_cam else "rotation",
                              c.direction if spec.is_translating_cam else c.rotation),
           ("speed", speed + ("" if c.speed_given else " (default)"))]
    fol = [("type", f.type), ("motion", f.motion)]
    for key in (fl.name for fl in dataclasses.fields(f)):
        v = getattr(f, key)
        if key not in ("type", "motion") and v is not None:
            fol.append((key, f"{v:g}"))
    mfg = [(k, (f"{v:g}" if isinstance(v, float) else str(v))) for k in (fl.name for fl in dataclasses.fields(m))
           if (v := getattr(m, k)) not in (None, "")]
    checks = [("pressure_angle_limit_deg", f"{spec.pressure_angle_limit_deg:g}" if spec.pressure_angle_limit_deg
               else "default (30° translating, 35° oscillating)"), ("face_margin_mm", f"{spec.face_margin_mm:g}")]
    groups = [{"title": "Cam", "rows": cam}, {"title": "Follower", "rows": fol},
              {"title": "Manufacturing", "rows": mfg}, {"title": "Checks", "rows": checks}]
    if spec.dynamics is not None:
        from ..design.spec import dynamics_items

        groups.append({"title": "Dynamics", "rows": [(k, f"{v:g}") for k, v in dynamics_items(spec.dynamics)]})
    if spec.motion_table is not None:
        groups.append({"title": "Knot table", "rows": [(k, json.dumps(v) if isinstance(v, dict) else str(v))
                                                       for k, v in spec.motion_table.items() if k != "rows"]})
    return groups


def _segments(prog) -> list[dict[str, Any]]:
    ax = axis_of(prog)
    starts = np.array([s.start for s in prog.segments])
    ends = np.array([s.start + s.span for s in prog.segments])
    eps = 1e-12 * prog.period
    s0 = prog.evaluate(starts + eps, (0,))[0]
    s1 = prog.evaluate(ends - eps, (0,))[0]
    return [{"index": i + 1, "title": s.title or s.law, "lift": f"{s1[i] - s0[i]:+.4f}",
             "start": f"{starts[i] * ax.scale:.4f}", "end": f"{ends[i] * ax.scale:.4f}",
             "s0": f"{s0[i]:.4f}", "s1": f"{s1[i]:.4f}"} for i, s in enumerate(prog.segments)]


def report_context(spec, geometry, report, plots: list[dict], anim: dict) -> dict[str, Any]:
    """Everything ``report.html.j2`` renders (plain data; see the template)."""
    from markupsafe import Markup

    xu = "°" if report.x_unit == "deg" else "mm"
    findings = sorted(report.findings, key=lambda f: _SEVERITY_ORDER.get(f.severity, 3))
    counts = {k: sum(f.severity == k for f in report.findings) for k in ("error", "warning", "info")}
    ctx = common_context(spec.source)
    ctx.update({
        "name": spec.name, "description": spec.description, "mechanism": mechanism_text(spec),
        "verdict": report.verdict, "verdict_text": VERDICT_TEXT[report.verdict],
        "verdict_class": VERDICT_CLASS[report.verdict], "counts": counts, "highlights": _highlights(spec, report),
        "rows": conclusions_rows(spec, report), "key_values": key_values(report),
        "dynamics_rows": dynamics_rows(spec, report),
        "findings": [{"code": f.code, "severity": f.severity, "where": range_text(f, xu), "message": f.message}
                     for f in findings],
        "plots": plots, "plots_by_name": {p["name"]: p for p in plots}, "inputs": _inputs(spec),
        "segments": _segments(spec.program()), "lift_unit": spec.follower.lift_unit, "x_unit": xu,
        "closed": geometry.closed, "anim_json": Markup(script_json(anim)),
        "anim_js": Markup(_read_asset("animation.js")),
    })
    return ctx


def render_report(spec, geometry, report, *, standalone: bool = False, frames: int = 360,
                  png: bool = False) -> dict[str, bytes]:
    """The files of a design's HTML report.

    Parameters
    ----------
    spec : DesignSpec
    geometry : CamGeometry
        From :func:`camfab.design.assemble.geometry_from_spec`.
    report : Report
        From :func:`camfab.design.assemble.check_design` (knot-table warnings may be added).
    standalone : bool
        Embed the SVG plots as ``data:`` URIs so ``report.html`` alone is complete
        (the ``plots/`` files are returned either way).
    frames : int
        Animation frames per cycle.
    png : bool
        Also write each plot as PNG (``plots/<name>.png``, linked under the plot).

    Returns
    -------
    dict[str, bytes]
        ``{"report.html": ..., "plots/svaj.svg": ..., ...}`` (and ``"plots/svaj.png"``… with ``png``).
    """
    from .animation import animation_data
    from .cylinder_animation import CYLINDER_ANIMATION_CAPTION, cylinder_animation_data, is_cylindrical
    from .cylinder_plot import UNROLLED_PLOT_TEXT
    from .figpool import reusing_figures
    from .plots import plot_style, report_figures
    from .vibration_plot import VIBRATION_PLOT_TEXT, vibration_figures

    # the figures of the previous design drawn again (byte-identical, cheaper); one style block around every
    # figure and save (the ones each enters inside it cost nothing)
    with reusing_figures(), plot_style():
        files, plots = plot_files({**report_figures(spec, geometry, report),
                                   **vibration_figures(spec, geometry, report)},
                                  standalone=standalone, png=png,
                                  text={**plot_text(geometry), **VIBRATION_PLOT_TEXT, **UNROLLED_PLOT_TEXT})
    ctx = report_context(spec, geometry, report, plots, animation_data(spec, geometry, report, frames=frames)
                         if not is_cylindrical(geometry) else {})
    if is_cylindrical(geometry):  # the cylinder turning, the roller along its axis (report/cylinder_animation.py)
        from markupsafe import Markup

        data = cylinder_animation_data(spec, geometry, report, frames=frames)
        ctx.update(closed=True, anim_json=Markup(script_json(data)), anim_caption=CYLINDER_ANIMATION_CAPTION,
                   anim_js=Markup(_read_asset("cylinder_animation.js") + _read_asset("animation.js")))
    html = template_environment().get_template("report.html.j2").render(ctx)
    return {"report.html": html.encode("utf-8"), **files}


def write_files(files: Mapping[str, bytes], out_dir: str | Path) -> list[Path]:
    """Write ``{relative path: bytes}`` under ``out_dir`` as one set (:func:`camfab.io.write_all`: every file or
    none, old files untouched on a failure); returns the paths in order."""
    from ..io import inside, write_all

    out = Path(out_dir)
    targets = [inside(out, rel) for rel in files]  # all proved inside out_dir before any write
    return write_all(dict(zip(targets, files.values(), strict=True)))
