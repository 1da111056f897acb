"""Report figures (matplotlib): S-V-A-J, profile, radius of curvature, pressure
angle, face contact position (flat and curved faces) and (designs with ``[dynamics]``)
follower dynamics.

Every function returns a :class:`matplotlib.figure.Figure` built without pyplot:
the figure gets its own Agg canvas, so no global backend is switched and
``import camfab`` never imports matplotlib (this module imports it lazily, inside
the functions).  :func:`figure_bytes` renders PNG or SVG deterministically (no
dates, no software stamp, a fixed SVG hash salt), so the same design always gives
byte-identical files.

Curves are sampled on an even grid of 1441 points plus both one-sided limits at
every breakpoint (:func:`camfab.report._common.sample_grid`): jumps show as
vertical lines, kinks are never straddled.  Angles are in degrees (mm of travel
for a translating cam); time quantities at the design speed.
"""
from __future__ import annotations

import contextlib
import io
import math
import threading
from typing import Any

import numpy as np

from ..design.kinds import ContactKind
from ..errors import InputError
from ..results import Extreme, IssueCode, pair_names
from ..textsafe import mpl_text
from ._common import CURVATURE_CODES, Axis, axis_of, finding_spans, fmt, fmt_at, sample_grid
from .figpool import figure_with_axes
from .layout import fixed_layout

__all__ = ["svaj_figure", "profile_figure", "curvature_figure", "pressure_angle_figure", "face_position_figure",
           "dynamics_figure", "report_figures", "figure_bytes", "new_figure", "plot_style", "SVAJ_UNITS",
           "off_view"]

#: (quantity, colour) of the four motion diagrams
_SVAJ = (("S", "#1f77b4"), ("V", "#2ca02c"), ("A", "#ff7f0e"), ("J", "#d62728"))
#: unit suffixes of S, V, A, J for a lift unit
SVAJ_UNITS = {"S": "{u}", "V": "{u}/s", "A": "{u}/s²", "J": "{u}/s³"}
_BAD = "#d62728"
#: finding codes shaded on the dynamics figure: (codes, colour, label)
_DYNAMICS_SHADES = (((IssueCode.FOLLOWER_JUMP,), _BAD, "follower jumps (N < 0)"),
                    ((IssueCode.CONTACT_FORCE_BELOW_SAFETY,), "#ff7f0e", "below the safety force"),
                    ((IssueCode.SELF_LOCKING,), "#9467bd", "self-locking (friction wedges the follower)"))
_N = 1441
_RC = {"font.size": 9, "axes.titlesize": 10, "axes.labelsize": 9, "legend.fontsize": 8, "axes.grid": True,
       "grid.alpha": 0.35, "grid.linewidth": 0.6, "svg.hashsalt": "camfab", "svg.fonttype": "path",
       "axes.formatter.useoffset": False, "axes.formatter.use_mathtext": False, "lines.linewidth": 1.4,
       "figure.dpi": 100, "savefig.dpi": 110}


#: how deep the current thread is in :func:`plot_style` blocks
_STYLE = threading.local()


@contextlib.contextmanager
def plot_style():
    """The report's matplotlib settings (a ``rc_context``; nothing global is changed).

    Inside another ``plot_style`` whose settings still hold, nothing is entered: the outer block restores every
    setting at its end.  A ``rc_context`` copies all ~300 settings on entry (~0.5 ms); a report enters one per
    figure and per save, which :func:`camfab.report.html.render_report` now makes nested in its own."""
    import matplotlib

    depth = getattr(_STYLE, "depth", 0)
    if depth and all(matplotlib.rcParams[k] == v for k, v in _RC.items()):
        yield
        return
    with matplotlib.rc_context(_RC):
        _STYLE.depth = depth + 1
        try:
            yield
        finally:
            _STYLE.depth = depth


def new_figure(width: float, height: float):
    """A pyplot-free figure with its own Agg canvas (constrained layout)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def figure_bytes(fig, fmt: str = "png") -> bytes:
    """Render a figure as ``"png"`` or ``"svg"`` bytes, deterministically.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    fmt : {"png", "svg"}

    Returns
    -------
    bytes
    """
    buf = io.BytesIO()
    with plot_style():
        from matplotlib.layout_engine import ConstrainedLayoutEngine

        if isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine):
            fixed_layout(fig)  # measured once, then fixed: a second format reuses it
        if fmt == "png":
            fig.savefig(buf, format="png", metadata={"Software": None})
        elif fmt == "svg":
            from .svgfig import figure_svg

            fast = figure_svg(fig) if fig.get_layout_engine() is None else None  # written by hand (svgfig.py)
            if fast is not None:
                return fast
            fig.savefig(buf, format="svg", metadata={"Date": None})
        else:
            raise InputError(f"'{fmt}' is not a valid option, must be one of: png, svg")
    return buf.getvalue()


# ---------------------------------------------------------------------------
def boundaries(ax, prog, axis: Axis) -> None:
    """Faint vertical lines at the segment junctions: one collection, from the bottom of the axes to the top (not
    in the data limits: every caller fixes the x view with :func:`x_axis`)."""
    from matplotlib.collections import LineCollection

    xs = np.asarray(prog.junctions_x, dtype=float)[1:-1] * axis.scale
    if len(xs):
        segs = np.stack([np.column_stack([xs, np.zeros_like(xs)]), np.column_stack([xs, np.ones_like(xs)])], axis=1)
        ax.add_collection(LineCollection(list(segs), colors="0.45", linewidths=0.6, linestyles=":", zorder=0.5,
                                         transform=ax.get_xaxis_transform()), autolim=False)


def x_axis(ax, axis: Axis) -> None:
    """Limits and ticks of the cam-angle (or travel) axis."""
    ax.set_xlim(0.0, axis.user_period)
    if axis.closed:
        ax.set_xticks(np.arange(0, 361, 30))
    ax.set_xlabel(axis.label)


def shade(ax, spans, color: str = _BAD, label: str | None = None, alpha: float = 0.15) -> None:
    """Shade finding ranges (a point range becomes a vertical line)."""
    for i, (a, b) in enumerate(spans):
        lab = label if i == 0 else None
        if abs(b - a) < 1e-9:
            ax.axvline(a, color=color, lw=2.0, alpha=0.7, label=lab)
        else:
            ax.axvspan(a, b, color=color, alpha=alpha, lw=0, label=lab)


def _segment_labels(ax, prog, axis: Axis) -> None:
    segs = prog.segments
    if len(segs) > 16:
        ax.text(0.01, 0.97, f"{len(segs)} segments", transform=ax.transAxes, va="top", fontsize=7, color="0.35")
        return
    for s in segs:
        if s.span * axis.scale < 0.055 * axis.user_period or s.law == "dwell" and s.span * axis.scale < 25:
            continue
        title = s.title.replace(" Curve", "").replace("Polynomial", "poly")
        ax.text((s.start + s.span / 2) * axis.scale, 0.97, title, transform=ax.get_xaxis_transform(),
                ha="center", va="top", fontsize=7, color="0.3", clip_on=True,
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.75})


def svaj_figure(spec, prog, *, n: int = _N):
    """Displacement, velocity, acceleration and jerk against the cam angle.

    Parameters
    ----------
    spec : DesignSpec
        For the speed (time units) and the lift unit.
    prog : MotionProgram
    n : int
        Even samples per cycle (breakpoints are added).

    Returns
    -------
    matplotlib.figure.Figure
        Four stacked axes with segment boundaries, law names and the exact peaks marked.
    """
    axis = axis_of(prog)
    x = sample_grid(prog.period, prog.breakpoints, n)
    vals = prog.evaluate(x) * (spec.speed ** np.arange(4))[:, None]
    peaks = prog.peaks("exact")
    lu = spec.follower.lift_unit
    names = {"S": "Displacement S", "V": "Velocity V", "A": "Acceleration A", "J": "Jerk J"}
    with plot_style():
        fig, axes = figure_with_axes("svaj", 9.0, 8.6, lambda f: f.subplots(4, 1, sharex=True))
        # the shared x view fixed first: each axhline below computes the stale view (matplotlib's get_ybound),
        # which with x still automatic also autoscaled x over all four axes (~10 % of a report).  Nothing drawn
        # here puts x into the data limits through the view, and the y limits never depend on the x view
        x_axis(axes[-1], axis)
        for k, ((q, colour), ax) in enumerate(zip(_SVAJ, axes, strict=True)):
            ax.plot(x * axis.scale, vals[k], color=colour)
            ax.axhline(0.0, color="0.2", lw=0.6)
            boundaries(ax, prog, axis)
            pk, sc = peaks[k], spec.speed**k
            for at, v, va in ((pk.at_max, pk.max * sc, "bottom"), (pk.at_min, pk.min * sc, "top")):
                ax.plot([at * axis.scale], [v], "o", ms=3.5, color=colour)
                ax.annotate(_short(v), (at * axis.scale, v), xytext=(4, 3 if va == "bottom" else -3),
                            textcoords="offset points", fontsize=7, va=va, color=colour)
            ax.set_ylabel(f"{q} ({SVAJ_UNITS[q].format(u=lu)})")
            ax.set_title(names[q], loc="left", fontsize=9)
            ax.margins(y=0.18)
        _segment_labels(axes[0], prog, axis)
        speed = (f"ω = {spec.speed:.4g} rad/s ({spec.speed * 30 / math.pi:.4g} rpm)" if axis.closed
                 else f"v = {spec.speed:.4g} mm/s")
        fig.suptitle(f"{mpl_text(spec.name)}: motion diagrams at {speed}", fontsize=11)
    return fig


def _short(v: float) -> str:
    return f"{v:.4g}" if abs(v) < 1e5 else f"{v:.3e}"


# ---------------------------------------------------------------------------
def _circle(ax, r: float, **kw) -> None:
    t = np.linspace(0.0, 2 * math.pi, 361)
    ax.plot(r * np.cos(t), r * np.sin(t), **kw)


def profile_figure(spec, geometry, report):
    """The cam profile(s) in the cam frame with base, prime, R min/R max circles and pitch curve (not for a
    curved face: its centre of curvature runs a face radius further out and would dwarf the cam).

    Parameters
    ----------
    spec : DesignSpec
    geometry : CamGeometry
    report : Report
        For the exact R min/R max (smallest and largest radius).

    Returns
    -------
    matplotlib.figure.Figure
        Equal-aspect view: follower side (+Y) at cam angle 0, contact points labelled every 90°
        and an arrow showing the rotation sense.
    """
    rr = spec.follower.roller_radius_mm or 0.0
    multi = len(geometry.profiles) > 1
    # a curved face's pitch curve (its centre of curvature) lies a face radius out and would dwarf the cam
    curved = any(c.curved_face for c in geometry.profiles)
    with plot_style():
        fig, ax = figure_with_axes("profile", 8.8, 6.6, lambda f: f.subplots())
        ax.set_aspect("equal")
        for k, c in enumerate(geometry.profiles):
            x = sample_grid(c.period, c.breakpoints)
            s = c.evaluate(np.append(x, x[0]))
            col = f"C{k}"
            tag = f"{c.label or f'cam {k + 1}'} " if multi else ""  # a groove's flanks by name
            ax.plot(s.point[:, 0], s.point[:, 1], color=col, lw=2.0, label=f"{tag}profile")
            if s.pitch is not None and c.roller_radius > 0 and not c.curved_face:
                ax.plot(s.pitch[:, 0], s.pitch[:, 1], color=col, lw=0.9, ls="--", label=f"{tag}pitch curve")
            if c.closed:
                _angle_marks(ax, c, col)
        if geometry.closed:
            rb = spec.follower.base_radius_mm
            if rb:
                _circle(ax, rb, color="0.35", lw=0.9, ls=(0, (4, 3)), label=f"base circle Rb = {rb:g} mm")
                if rr > 0 and spec.cam.kind not in ("constant_width",) and not curved:
                    _circle(ax, rb + rr, color="0.35", lw=0.8, ls="-.", label=f"prime circle Rp = {rb + rr:g} mm")
            if report.base_radius_mm is not None:
                _circle(ax, report.base_radius_mm, color=_BAD, lw=0.8,
                        label=f"R min = {fmt(report.base_radius_mm)} mm (Ø min = {fmt(2 * report.base_radius_mm)} mm)")
            if report.max_radius_mm is not None:
                _circle(ax, report.max_radius_mm, color=_BAD, lw=0.8, ls=(0, (1, 1.5)),
                        label=f"R max = {fmt(report.max_radius_mm)} mm (Ø max = {fmt(2 * report.max_radius_mm)} mm)")
            if spec.manufacturing.bore_mm:
                _circle(ax, spec.manufacturing.bore_mm / 2, color="0.1", lw=0.8,
                        label=f"bore Ø{spec.manufacturing.bore_mm:g} mm")
            ax.plot([0], [0], "k+", ms=12, mew=1.2, label="cam centre")
            _rotation_arrow(ax, report.max_radius_mm or 1.0, geometry.profiles[0].sense)
            ax.set_title(f"{mpl_text(spec.name)}: cam profile (cam frame, follower at +Y at 0°)")
        else:
            ax.axhline(spec.follower.base_height_mm or 0.0, color="0.35", lw=0.9, ls="--", label="cam base line")
            ax.set_title(f"{mpl_text(spec.name)}: translating cam profile")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig


def _angle_marks(ax, c, col) -> None:
    deg = np.arange(0, 360, 30)
    s = c.evaluate(np.radians(deg))
    p, nrm = s.point, s.normal
    ax.plot(p[:, 0], p[:, 1], "o", ms=2.5, color=col)
    for a, q, v in zip(deg, p, nrm, strict=True):
        if a % 90 == 0:
            ax.annotate(f"{a}°", q, xytext=(q + 0.08 * np.hypot(*q) * v), fontsize=7, color=col,
                        ha="center", va="center")


def _rotation_arrow(ax, r: float, sense: int) -> None:
    from matplotlib.patches import FancyArrowPatch

    a0, a1 = (math.radians(135), math.radians(105)) if sense > 0 else (math.radians(105), math.radians(135))
    rr = 1.16 * r
    arrow = FancyArrowPatch((rr * math.cos(a0), rr * math.sin(a0)), (rr * math.cos(a1), rr * math.sin(a1)),
                            connectionstyle=f"arc3,rad={-0.15 * sense}", arrowstyle="-|>", mutation_scale=12,
                            color="0.2", lw=1.1)
    ax.add_patch(arrow)
    am = math.radians(120)
    ax.text(1.28 * r * math.cos(am), 1.28 * r * math.sin(am), "cw" if sense > 0 else "ccw", fontsize=8,
            ha="center", va="center", color="0.2")
    ax.plot([0, 0], [0.0, 1.08 * r], color="0.6", lw=0.6, ls=":")


# ---------------------------------------------------------------------------
def _profile_samples(geometry, n: int) -> list[tuple[Any, np.ndarray, Any]]:
    out = []
    for c in geometry.profiles:
        x = sample_grid(c.period, c.breakpoints, n)
        out.append((c, x, c.evaluate(x)))
    return out


def curvature_figure(spec, geometry, report, *, n: int = _N):
    """Radius of curvature against the cam angle, with undercut/cusp/cutter violations shaded.

    ρ is signed (positive = convex); it passes through ±∞ at inflections, so the view is
    clipped to a few times the cam size.  Rollers also show the pitch-curve radius ρₚ; a curved
    face does not (its centre of curvature's path, ρₚ = ρ + R, lies a face radius above ρ: its
    undercut limit ρₚ = R is the line ρ = 0).

    Returns
    -------
    matplotlib.figure.Figure
    """
    axis = axis_of(spec.program())
    roc = report.curvature
    rmax = report.max_radius_mm or 50.0
    lim = 3.0 * rmax
    multi = len(geometry.profiles) > 1
    with plot_style():
        fig, ax = figure_with_axes("curvature", 9.0, 4.4, lambda f: f.subplots())
        lo, hi = 0.0, 0.0
        for k, (c, x, s) in enumerate(_profile_samples(geometry, n)):
            tag = f"{c.label or f'cam {k + 1}'}: " if multi else ""
            rho = off_view(s.rho, lim)
            ax.plot(x * axis.scale, rho, color=f"C{k}", label=f"{tag}profile ρ")
            lo, hi = min(lo, np.nanmin(rho, initial=0.0)), max(hi, np.nanmax(rho, initial=0.0))
            if s.rho_pitch is not None and c.roller_radius > 0 and not c.curved_face:
                ax.plot(x * axis.scale, off_view(s.rho_pitch, lim), color=f"C{k}", lw=0.8, ls="--",
                        label=f"{tag}pitch curve ρₚ")
        ax.axhline(0.0, color="0.1", lw=0.9, label="ρ = 0 (cusp limit)")
        rr = max((c.roller_radius for c in geometry.profiles if c.kind == "roller" and not c.curved_face),
                 default=0.0)
        if rr > 0:
            ax.axhline(rr, color=_BAD, lw=0.9, ls=":", label=f"ρₚ = roller radius {rr:g} mm (undercut limit)")
        tool = spec.manufacturing.tool_diameter_mm
        if tool and lo < 0:
            ax.axhline(-tool / 2, color="#9467bd", lw=0.9, ls="--", label=f"−cutter radius ({tool / 2:g} mm)")
        shade(ax, finding_spans(report.findings, CURVATURE_CODES, axis), label="undercut / cusp / too tight")
        if roc is not None and roc.min_convex is not None and roc.at_min_convex is not None:
            ax.plot([roc.at_min_convex], [roc.min_convex], "v", color=_BAD, ms=6,
                    label=f"min convex ρ = {fmt(roc.min_convex)} mm at {roc.at_min_convex:.1f}{axis.unit}")
        boundaries(ax, spec.program(), axis)
        ax.set_ylim(max(lo, -lim) - 0.08 * lim, min(hi, lim) + 0.08 * lim)
        x_axis(ax, axis)
        ax.set_ylabel("radius of curvature ρ (mm)")
        ax.set_title(f"{mpl_text(spec.name)}: radius of curvature (+ convex, − concave; view clipped at ±{lim:.0f} mm)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig


def off_view(rho: np.ndarray, lim: float) -> np.ndarray:
    """ρ with the values far outside ±lim blanked, so the curve leaves the view at an
    inflection (ρ → ±∞) instead of drawing a vertical line across it."""
    out = np.array(rho, dtype=float)
    out[~np.isfinite(out) | (np.abs(out) > 1.5 * lim)] = np.nan
    return out


def pressure_angle_figure(spec, geometry, report, *, n: int = _N):
    """Pressure angle against the cam angle with the ±limit lines; excess shaded red.

    Returns
    -------
    matplotlib.figure.Figure
    """
    axis = axis_of(spec.program())
    pa = report.pressure_angle
    lim = pa.limit if pa is not None else None
    multi = len(geometry.profiles) > 1
    with plot_style():
        fig, ax = figure_with_axes("pressure_angle", 9.0, 4.2, lambda f: f.subplots())
        for k, (c, x, s) in enumerate(_profile_samples(geometry, n)):
            if s.pressure_angle is None:
                continue
            xu, delta = x * axis.scale, np.degrees(s.pressure_angle)
            ax.plot(xu, delta, color=f"C{k}", label=(c.label or f"cam {k + 1}") if multi else "pressure angle δ")
            if lim is not None:
                ax.fill_between(xu, delta, lim, where=delta > lim, interpolate=True, color=_BAD, alpha=0.45, lw=0)
                ax.fill_between(xu, delta, -lim, where=delta < -lim, interpolate=True, color=_BAD, alpha=0.45, lw=0)
        if lim is not None:
            for sgn in (1, -1):
                ax.axhline(sgn * lim, color=_BAD, lw=1.0, ls="--", label=f"limit ±{lim:g}°" if sgn > 0 else None)
        shade(ax, finding_spans(report.findings, (IssueCode.PRESSURE_ANGLE_EXCEEDED,), axis), label="limit exceeded",
              alpha=0.12)
        if pa is not None:
            for v, at, va in ((pa.max, pa.at_max, "bottom"), (pa.min, pa.at_min, "top")):
                ax.plot([at], [v], "o", color="0.1", ms=3.5)
                ax.annotate(f"{v:.2f}° at {at:.1f}{axis.unit}", (at, v),
                            xytext=(5, 4 if va == "bottom" else -4), textcoords="offset points", fontsize=7, va=va)
        ax.axhline(0.0, color="0.2", lw=0.6)
        boundaries(ax, spec.program(), axis)
        x_axis(ax, axis)
        ax.margins(y=0.15)
        ax.set_ylabel("pressure angle δ (°)")
        ax.set_title(f"{mpl_text(spec.name)}: pressure angle against its limit")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig


def face_position_figure(spec, geometry, report, *, n: int = _N):
    """Contact position along the follower's face (flat or curved) against the cam angle, with the face
    extent needed: from the stem axis for a translating face, from the vertex for a face on an arm (a
    curved face's arc length).

    Returns
    -------
    matplotlib.figure.Figure
    """
    axis = axis_of(spec.program())
    faces = [c for c in geometry.profiles if c.has_face]
    word = "curved-face" if any(c.curved_face for c in faces) else "flat-face"
    if faces and all(c.oscillating for c in faces):
        where = "arc length from the vertex" if word == "curved-face" else "distance from the vertex"
    else:
        where = "+ = right of the stem"
    face = report.face_length
    multi = len(geometry.profiles) > 1
    with plot_style():
        fig, ax = figure_with_axes("face_position", 9.0, 4.0, lambda f: f.subplots())
        for k, (_c, x, s) in enumerate(_profile_samples(geometry, n)):
            if s.face_position is None:
                continue
            ax.plot(x * axis.scale, s.face_position, color=f"C{k}",
                    label=f"cam {k + 1} contact" if multi else "contact position")
        if face is not None and face.left is not None:
            lo, hi = -face.left, face.right
            ax.axhline(0.0, color="0.2", lw=0.8, label="stem axis")
            what = f"face needed: {fmt(face.left)} mm left, {fmt(face.right)} mm right"
        elif face is not None:
            lo, hi = min(face.min, 0.0), face.max + spec.face_margin_mm
            ax.axhline(0.0, color="0.2", lw=0.8, label="face vertex")
            what = f"face needed from the vertex: {fmt(hi)} mm"
        else:
            lo = hi = None
        if lo is not None:
            ax.axhspan(lo, hi, color="#2ca02c", alpha=0.10, lw=0, label=what)
            for v in (lo, hi):
                ax.axhline(v, color="#2ca02c", lw=1.0, ls="--")
        boundaries(ax, spec.program(), axis)
        x_axis(ax, axis)
        ax.margins(y=0.15)
        ax.set_ylabel("contact position on the face (mm)")
        ax.set_title(f"{mpl_text(spec.name)}: {word} contact position ({where})")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig


def _finite_view(v: np.ndarray, clip: bool) -> tuple[np.ndarray, float]:
    """``v`` with non-finite values blanked, and the largest |value| shown; with ``clip``
    (self-locking: N → ±∞ where the lever vanishes) the values far beyond the bulk of the curve
    are blanked too, so the view stays readable."""
    out = np.where(np.isfinite(v), v, np.nan)
    lim = math.inf
    if clip and np.isfinite(out).any():
        lim = 4.0 * float(np.nanpercentile(np.abs(out), 90))
        out[np.abs(out) > lim] = np.nan
    return out, lim


def _mark_extremes(ax, ext: Extreme | None, unit: str, xu: str, colour: str, lim: float = math.inf, *,
                   max_only: bool = False) -> None:
    """Dots and labels at the exact maximum (and minimum, unless ``max_only``) of ``ext`` (those
    beyond ±``lim``, off the view, are left out)."""
    if ext is None:
        return
    marks = [(ext.max, ext.at_max, "bottom")] + ([] if max_only else [(ext.min, ext.at_min, "top")])
    for v, x, va in marks:
        if v is None or x is None or not abs(v) <= lim:
            continue
        ax.plot([x], [v], "o", color=colour, ms=3.5)
        ax.annotate(f"{_short(v)} {unit} at {fmt_at(x, xu)}", (x, v), xytext=(5, 4 if va == "bottom" else -4),
                    textcoords="offset points", fontsize=7, va=va, color=colour)


def dynamics_figure(spec, geometry, report, *, n: int = _N):
    """Contact force and drive torque (drive force of a translating cam) against the cam angle.

    Top panel: the contact force N with the zero line and the safety force, the ranges of the
    ``FOLLOWER_JUMP``, ``CONTACT_FORCE_BELOW_SAFETY`` and ``SELF_LOCKING`` findings shaded and the
    exact extremes of ``report.dynamics`` marked.  Bottom panel: the drive torque (N·m),
    or the drive force (N) along the travel of a translating cam.

    Parameters
    ----------
    spec : DesignSpec
        With a ``[dynamics]`` section.
    geometry : CamGeometry
    report : Report
        From :func:`camfab.design.assemble.check_design` (its ``dynamics`` summary and findings).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from ..design.assemble import dynamics_model

    if spec.dynamics is None:
        raise InputError(f"{spec.name} has no [dynamics] section: add one (mass_kg or inertia_kg_m2, spring, loads) "
                         "to plot the forces")
    prog = spec.program()
    axis = axis_of(prog)
    c = geometry.profiles[0]
    x = sample_grid(c.period, c.breakpoints, n)
    sm = dynamics_model(spec, geometry).evaluate(x)
    pair = sm.contact_force_2 is not None
    dyn = report.dynamics
    locking = bool(report.by_code(IssueCode.SELF_LOCKING))
    xu, fs = axis.unit, spec.dynamics.safety_force_n
    drive_label = "drive torque T (N·m)" if geometry.closed else "drive force (N)"
    with plot_style():
        fig, (ax, ax2) = figure_with_axes("dynamics", 9.0, 6.4,
                                          lambda f: f.subplots(2, 1, sharex=True, height_ratios=(3, 2)))
        force, lim = _finite_view(sm.contact_force, locking)
        names = pair_names(geometry.flank_pair)
        ax.plot(x * axis.scale, force, color="C0", label=names[0] if pair else "contact force N")
        if pair:
            ax.plot(x * axis.scale, sm.contact_force_2, color="C1", label=names[1])
            _mark_extremes(ax, dyn.second_contact_force if dyn else None, "N", xu, "0.1", lim, max_only=True)
        ax.axhline(0.0, color="0.1", lw=0.9, label="N = 0" if pair else "N = 0 (jump limit)")
        if fs:
            ax.axhline(fs, color=_BAD, lw=1.0, ls="--", label=f"safety force {fs:g} N")
        for codes, colour, label in _DYNAMICS_SHADES:
            shade(ax, finding_spans(report.findings, codes, axis), color=colour, label=label)
        # a form-closed pair's minima are the 0 N of the unloaded follower: only the maxima are marked
        _mark_extremes(ax, dyn.contact_force if dyn else None, "N", xu, "0.1", lim, max_only=pair)
        ax.set_ylabel("contact force N (N)")
        ax.set_title("Contact force", loc="left", fontsize=9)
        ax.margins(y=0.15)
        drive, lim = _finite_view(sm.drive, locking)
        ax2.plot(x * axis.scale, drive, color="C2", label=drive_label)
        ax2.axhline(0.0, color="0.2", lw=0.6)
        _mark_extremes(ax2, dyn.drive if dyn else None, "N·m" if geometry.closed else "N", xu, "0.1", lim)
        ax2.set_ylabel(drive_label)
        ax2.set_title("Drive torque" if geometry.closed else "Drive force", loc="left", fontsize=9)
        ax2.margins(y=0.15)
        for a in (ax, ax2):
            boundaries(a, prog, axis)
            a.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        x_axis(ax2, axis)
        speed = (f"{spec.speed * 30 / math.pi:.4g} rpm" if axis.closed else f"{spec.speed:.4g} mm/s")
        fig.suptitle(f"{mpl_text(spec.name)}: follower dynamics at {speed}", fontsize=11)
    return fig


def report_figures(spec, geometry, report) -> dict[str, Any]:
    """The figures of one design's report, by file stem, in reading order.

    ``pressure_angle`` is included when some follower has a pressure angle that varies
    (rollers, curved faces, oscillating faces); ``face_position`` when a follower has a face (flat or
    curved: :attr:`~camfab.design.profile.Contact.has_face`); ``dynamics`` when the design has a
    ``[dynamics]`` section.
    """
    if spec.cam.kind == "cylindrical":  # no plate: the unrolled groove (report/cylinder_plot.py), δ on each radius
        from .cylinder_plot import unrolled_figure
        return {"svaj": svaj_figure(spec, spec.program()), "unrolled": unrolled_figure(spec, geometry),
                "pressure_angle": pressure_angle_figure(spec, geometry, report)}
    figs: dict[str, Any] = {"svaj": svaj_figure(spec, spec.program()),
                            "profile": profile_figure(spec, geometry, report),
                            "curvature": curvature_figure(spec, geometry, report)}
    if any(c.kind is ContactKind.ROLLER or c.oscillating for c in geometry.profiles):
        figs["pressure_angle"] = pressure_angle_figure(spec, geometry, report)
    if any(c.has_face for c in geometry.profiles):
        figs["face_position"] = face_position_figure(spec, geometry, report)
    if spec.dynamics is not None:
        figs["dynamics"] = dynamics_figure(spec, geometry, report)
    cs = getattr(report, "contact_stress", None)
    if spec.dynamics is not None and cs is not None and cs.max_mpa is not None:
        from .strength_plot import contact_stress_figure
        figs["contact_stress"] = contact_stress_figure(spec, geometry, report)
    return figs
