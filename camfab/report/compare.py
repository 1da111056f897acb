"""Comparison of several designs (``camfab compare A B …``): overlaid plots and a
side-by-side table of the key numbers (the CAM-DAS "Pizarra").

:func:`render_comparison` returns ``{relative path: bytes}``: ``compare.html`` and
``plots/{svaj,curvature,pressure_angle}.svg`` (and ``.png`` with ``png=True``).  Each design keeps its own
units (mm or degrees of lift; degrees of cam angle or mm of travel).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import InputError
from ..results import Severity
from ..textsafe import mpl_text
from ._common import VERDICT_CLASS, VERDICT_TEXT, axis_of, fmt, mechanism_text, sample_grid
from .plots import SVAJ_UNITS, new_figure, off_view, plot_style

__all__ = ["render_comparison", "comparison_rows", "compare_svaj_figure", "compare_curvature_figure",
           "compare_pressure_angle_figure", "design_labels"]


def design_labels(items) -> list[str]:
    """Design names, made unique ("Cam", "Cam (2)") for legends and column heads."""
    out: list[str] = []
    seen: dict[str, int] = {}
    for spec, _, _ in items:
        n = seen.get(spec.name, 0) + 1
        seen[spec.name] = n
        out.append(spec.name if n == 1 else f"{spec.name} ({n})")
    return out


def _x_setup(ax, items) -> None:
    axes = [axis_of(spec.program()) for spec, _, _ in items]
    if all(a.closed for a in axes):
        ax.set_xlim(0, 360)
        ax.set_xticks(np.arange(0, 361, 30))
        ax.set_xlabel("cam angle (°)")
    else:
        ax.set_xlim(0, max(a.user_period for a in axes))
        ax.set_xlabel("cam angle (°) / cam travel (mm)")


def compare_svaj_figure(items, labels: Sequence[str] | None = None):
    """S, V, A, J of every design overlaid (time units at each design's speed).

    Parameters
    ----------
    items : sequence of (DesignSpec, CamGeometry, Report)
    labels : sequence of str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    labels = [mpl_text(t) for t in (labels or design_labels(items))]  # no mathtext from a name
    units = sorted({spec.follower.lift_unit for spec, _, _ in items})
    with plot_style():
        fig = new_figure(9.0, 8.6)
        axes = fig.subplots(4, 1, sharex=True)
        for i, (spec, _, _) in enumerate(items):
            prog = spec.program()
            axis = axis_of(prog)
            x = sample_grid(prog.period, prog.breakpoints)
            vals = prog.evaluate(x) * (spec.speed ** np.arange(4))[:, None]
            for k, ax in enumerate(axes):
                ax.plot(x * axis.scale, vals[k], color=f"C{i}", lw=1.3, label=labels[i] if k == 0 else None)
        for q, ax in zip("SVAJ", axes, strict=True):
            ax.axhline(0.0, color="0.2", lw=0.6)
            ax.set_ylabel(f"{q} ({' | '.join(SVAJ_UNITS[q].format(u=u) for u in units)})")
            ax.margins(y=0.1)
        _x_setup(axes[-1], items)
        axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        fig.suptitle("Motion diagrams S, V, A, J", fontsize=11)
    return fig


def compare_curvature_figure(items, labels: Sequence[str] | None = None):
    """Radius of curvature of every design's profile(s), overlaid (view clipped at ±3·Rmax)."""
    labels = [mpl_text(t) for t in (labels or design_labels(items))]  # no mathtext from a name
    rmax = max((r.max_radius_mm or 50.0) for _, _, r in items)
    lim = 3.0 * rmax
    with plot_style():
        fig = new_figure(9.0, 4.4)
        ax = fig.subplots()
        lo, hi = 0.0, 0.0
        for i, (spec, geom, _) in enumerate(items):
            axis = axis_of(spec.program())
            for k, c in enumerate(geom.profiles):
                x = sample_grid(c.period, c.breakpoints)
                rho = off_view(c.evaluate(x).rho, lim)
                ax.plot(x * axis.scale, rho, color=f"C{i}", ls="-" if k == 0 else "--",
                        label=labels[i] + (f" cam {k + 1}" if len(geom.profiles) > 1 else ""))
                lo, hi = min(lo, np.nanmin(rho, initial=0.0)), max(hi, np.nanmax(rho, initial=0.0))
        ax.axhline(0.0, color="0.1", lw=0.9, label="ρ = 0 (cusp limit)")
        ax.set_ylim(max(lo, -lim) - 0.08 * lim, min(hi, lim) + 0.08 * lim)
        _x_setup(ax, items)
        ax.set_ylabel("radius of curvature ρ (mm)")
        ax.set_title(f"Radius of curvature (+ convex, − concave; view clipped at ±{lim:.0f} mm)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig


def compare_pressure_angle_figure(items, labels: Sequence[str] | None = None):
    """Pressure angle of every design with its limit (dashed, in the design's colour)."""
    labels = [mpl_text(t) for t in (labels or design_labels(items))]  # no mathtext from a name
    with plot_style():
        fig = new_figure(9.0, 4.2)
        ax = fig.subplots()
        for i, (spec, geom, rep) in enumerate(items):
            axis = axis_of(spec.program())
            for k, c in enumerate(geom.profiles):
                x = sample_grid(c.period, c.breakpoints)
                pa = c.evaluate(x).pressure_angle
                if pa is None or (c.kind == "flat" and not c.oscillating):
                    continue
                ax.plot(x * axis.scale, np.degrees(pa), color=f"C{i}", ls="-" if k == 0 else "--",
                        label=labels[i] + (f" cam {k + 1}" if len(geom.profiles) > 1 else ""))
            lim = rep.pressure_angle.limit if rep.pressure_angle is not None else None
            if lim is not None:
                for sgn in (1, -1):
                    ax.axhline(sgn * lim, color=f"C{i}", lw=0.9, ls=(0, (5, 3)),
                               label=f"{labels[i]} limit ±{lim:g}°" if sgn > 0 else None)
        ax.axhline(0.0, color="0.2", lw=0.6)
        _x_setup(ax, items)
        ax.margins(y=0.15)
        ax.set_ylabel("pressure angle δ (°)")
        ax.set_title("Pressure angle against the limits")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig


def _c(value, unit: str = "", digits: int = 2) -> dict[str, Any]:
    if value is None:
        return {"text": "--", "value": None, "cls": ""}
    return {"text": fmt(value, digits) + (f" {unit}" if unit else ""), "value": float(value), "cls": ""}


def _t(text: str, cls: str = "") -> dict[str, Any]:
    return {"text": text, "value": None, "cls": cls}


def _min_contact_force(rep):
    """The smallest contact force of a spring-loaded follower (None without dynamics, or form-closed)."""
    dyn = rep.dynamics
    return None if dyn is None or dyn.form_closed else dyn.contact_force.min


def _max_contact_force(rep):
    dyn = rep.dynamics
    if dyn is None:
        return None
    return max(e.max for e in (dyn.contact_force, dyn.second_contact_force) if e is not None)


def _peak_torque(rep):
    dyn = rep.dynamics
    return None if dyn is None or not dyn.torque else max(abs(dyn.drive.max), abs(dyn.drive.min))


def _jump_cell(rep) -> dict[str, Any]:
    dyn = rep.dynamics
    if dyn is None or dyn.form_closed:
        return _c(None)
    v = dyn.jump_speed.value
    return _t("never") if v is None else _c(v, digits=1)


def _part(obj, attr: str):
    """``obj.attr``, or None when the summary ``obj`` is None."""
    return None if obj is None else getattr(obj, attr)


def _vertex_face_length(rep):
    """How far from its vertex the contact runs on an oscillating face, flat or curved (None otherwise)."""
    face = rep.face_length
    return None if face is None or face.left is not None else face.max


def comparison_rows(items) -> list[dict[str, Any]]:
    """The side-by-side table: ``[{"label": str, "cells": [{"text", "value", "cls"}, ...]}, ...]``,
    one cell per design (``value`` is the exact report number, or None)."""
    ds = [(spec, rep) for spec, _, rep in items]
    rows: list[dict[str, Any]] = []

    def add(label, fn):
        rows.append({"label": label, "cells": [fn(spec, rep) for spec, rep in ds]})

    add("Mechanism", lambda s, r: _t(mechanism_text(s)))
    add("Verdict", lambda s, r: _t(VERDICT_TEXT[r.verdict], "verdict-cell " + VERDICT_CLASS[r.verdict]))
    add("Errors / warnings", lambda s, r: _t(f"{sum(f.severity == Severity.ERROR for f in r.findings)} / "
                                            f"{sum(f.severity == Severity.WARNING for f in r.findings)}"))
    add("Speed", lambda s, r: _t(f"{s.speed:.4g} mm/s" if s.is_translating_cam else
                                 f"{s.speed * 30 / math.pi:.4g} rpm"))
    add("Base radius Rb (mm)", lambda s, r: _c(s.follower.base_radius_mm))
    add("Roller radius (mm)", lambda s, r: _c(s.follower.roller_radius_mm if s.follower.type == "roller" else None))
    add("Face radius (mm)", lambda s, r: _c(s.follower.face_radius_mm))
    add("Ø min = 2·R min (mm)", lambda s, r: _c(None if r.base_radius_mm is None else 2 * r.base_radius_mm))
    add("Ø max = 2·R max, blank (mm)", lambda s, r: _c(None if r.max_radius_mm is None else 2 * r.max_radius_mm))
    add("Profile area (mm²)", lambda s, r: _c(r.area_mm2))
    for q, unit in (("S", "{u}"), ("V", "{u}/s"), ("A", "{u}/s²"), ("J", "{u}/s³")):
        for key in ("max", "min"):
            add(f"{q} {key}", lambda s, r, q=q, key=key, unit=unit:
                _c(_part(_part(_part(r.motion, "peaks"), q), key), unit.format(u=s.follower.lift_unit)))
    add("Min convex ρ (mm)", lambda s, r: _c(_part(r.curvature, "min_convex")))
    add("Min concave ρ (mm)", lambda s, r: _c(_part(r.curvature, "min_concave")))
    for key in ("max", "min"):
        add(f"Pressure angle {key} (°)", lambda s, r, key=key: _c(_part(r.pressure_angle, key)))
    add("Pressure-angle limit (°)", lambda s, r: _c(_part(r.pressure_angle, "limit"), digits=1))
    add("Face length left (mm)", lambda s, r: _c(_part(r.face_length, "left")))
    add("Face length right (mm)", lambda s, r: _c(_part(r.face_length, "right")))
    add("Contact from the face vertex, max (mm)", lambda s, r: _c(_vertex_face_length(r)))
    add("Min contact force (N)", lambda s, r: _c(_min_contact_force(r)))
    add("Max contact force (N)", lambda s, r: _c(_max_contact_force(r)))
    add("Peak drive torque (N·m)", lambda s, r: _c(_peak_torque(r)))
    add("Jump speed (rpm)", lambda s, r: _jump_cell(r))
    return [r for r in rows if any(c["text"] != "--" for c in r["cells"])]


def render_comparison(items, *, standalone: bool = False, png: bool = False) -> dict[str, bytes]:
    """The files of a comparison page.

    Parameters
    ----------
    items : sequence of (DesignSpec, CamGeometry, Report)
        Two or more designs (one is accepted).
    standalone : bool
        Embed the SVG plots in ``compare.html`` as ``data:`` URIs.
    png : bool
        Also write each plot as PNG.

    Returns
    -------
    dict[str, bytes]
        ``{"compare.html": ..., "plots/svaj.svg": ..., ...}`` (and ``"plots/svaj.png"``… with ``png``).
    """
    from .html import common_context, plot_files, template_environment

    items = list(items)
    if not items:
        raise InputError("items is empty: render_comparison needs at least one (spec, geometry, report) item")
    labels = design_labels(items)
    figs = {"svaj": compare_svaj_figure(items, labels), "curvature": compare_curvature_figure(items, labels)}
    if any(c.kind == "roller" or c.oscillating for _, g, _ in items for c in g.profiles):
        figs["pressure_angle"] = compare_pressure_angle_figure(items, labels)
    files, plots = plot_files(figs, standalone=standalone, png=png)
    ctx = common_context(None)
    ctx.update({"labels": labels, "rows": comparison_rows(items), "plots": plots,
                "sources": [s.source and s.source.rsplit("/", 1)[-1] for s, _, _ in items],
                "verdicts": [(VERDICT_CLASS[r.verdict], VERDICT_TEXT[r.verdict]) for _, _, r in items]})
    html = template_environment().get_template("compare.html.j2").render(ctx)
    return {"compare.html": html.encode("utf-8"), **files}
