"""The package overview: what ``camfab package`` records of each built cam (:func:`cam_summary`: key figures,
the reasons for its verdict, an outline thumbnail) and its ``index.html`` (:func:`index_html`, from
``templates/package/index.html.j2`` with autoescape): counts by verdict, the drawing set linked at the top, one row
per cam with its thumbnail (inline SVG), key figures, reasons and files grouped by kind, sortable columns (a small
inline script, no network), an error row that wraps.  See docs/decisions.md, "The package index"."""
from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from ..assets import read_template
from ..discretize.curve import points_at
from ..offset import profile_curve
from ..results import Severity
from ..textsafe import bounded, excerpt, plain

__all__ = ["cam_summary", "index_html"]

log = logging.getLogger(__name__)


def cam_summary(spec, geometry, report, deviations: Iterable[float | None] = ()) -> dict:
    """What the index shows of a built cam, recorded in its manifest entry: ``drawing_number`` (the design's
    ``[drawing] number``, when it has one), ``figures`` (largest |pressure angle| and its limit, smallest convex
    radius of curvature, largest radius ``r_max_mm`` and — a disc cam — largest diameter ``d_max_mm`` named
    apart, speed, achieved deviation), ``reasons`` (the findings behind the verdict, one per code, errors
    first) and ``outline`` (the profile thumbnail: SVG path data, y up, mm)."""
    rep = report
    pa, cv = rep.pressure_angle, rep.curvature
    rmax = rep.max_radius_mm if rep.max_radius_mm is not None else geometry.max_radius
    devs = [d for d in deviations if d is not None]
    if spec.is_translating_cam:
        speed = {"value": spec.cam.speed_mm_s, "unit": "mm/s", "given": spec.cam.speed_mm_s is not None}
    else:
        rpm = float(f"{spec.cam.omega_rad_s * 30.0 / math.pi:.10g}")  # 60 rpm, not 59.99999999999999
        speed = {"value": rpm, "unit": "rpm", "given": spec.cam.speed_given}
    figures = {
        "pressure_angle_max_deg": None if pa is None else max(abs(pa.max), abs(pa.min)),
        "pressure_angle_limit_deg": None if pa is None else pa.limit,
        "min_radius_of_curvature_mm": None if cv is None else cv.min_convex,
        "r_max_mm": rmax, "d_max_mm": None if spec.is_translating_cam or rmax is None else 2.0 * rmax,
        "speed": speed, "deviation_mm": max(devs) if devs else None,
    }
    order = {Severity.ERROR: 0, Severity.WARNING: 1, Severity.INFO: 2}
    reasons, seen = [], set()
    for f in sorted(rep.findings, key=lambda f: order.get(f.severity, 3)):
        if f.code in seen or f.severity == Severity.INFO:
            continue
        seen.add(f.code)
        reasons.append({"code": str(f.code), "severity": str(f.severity), "message": bounded(f.message)})
    number = spec.drawing.number or None
    return {"drawing_number": plain(str(number)) if number else None, "figures": figures, "reasons": reasons[:6],
            "outline": _outline(spec, geometry)}


def _outline(spec, geometry, n: int = 241) -> dict | None:
    """The cam's outline for a thumbnail: each profile sampled at ``n`` points (a translating cam's plate closed
    down to its bottom edge), the bore as a circle; coordinates in mm, y up, rounded to 1/400 of the size.
    None when the profile cannot be sampled."""
    try:
        loops = []
        for c in geometry.profiles:
            curve = profile_curve(c)
            pts = points_at(curve, np.linspace(0.0, curve.period, n))
            if not geometry.closed:
                pts = np.vstack([pts, [[pts[-1, 0], 0.0], [pts[0, 0], 0.0]]])
            loops.append(pts)
    except Exception as exc:  # noqa: BLE001 - a thumbnail is never worth a failed build
        log.info("%s: no outline thumbnail (%s: %s)", spec.name, type(exc).__name__, exc)
        return None
    allp = np.vstack(loops)
    if not np.all(np.isfinite(allp)):
        return None
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    size = float(max(hi - lo)) or 1.0
    q = size / 400.0
    digits = max(0, -math.floor(math.log10(q)))

    def num(v: float) -> str:
        s = f"{round(v / q) * q:.{digits}f}"
        return "0" if float(s) == 0 else s

    paths = ["M" + "L".join(f"{num(x)},{num(-y)}" for x, y in p) + "Z" for p in loops]
    bore = spec.manufacturing.bore_mm / 2 if geometry.closed else 0.0
    pad = 0.04 * size
    box = [lo[0] - pad, -hi[1] - pad, hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad]
    return {"viewbox": " ".join(num(v) for v in box), "paths": paths, "bore_r": float(bore) if bore > 0 else None,
            "stroke": num(size / 120.0)}


_ERROR_LABEL = {"io": "I/O error", "dependency": "missing dependency", "internal": "internal error",
                "worker": "worker lost"}
_VERDICTS = (("acceptable", "acceptable"), ("not_for_high_speed", "not for high speed"),
             ("unacceptable", "unacceptable"), ("error", "failed"))
#: file groups of the index, in order: (label, test on the file's path relative to the cam folder)
_KINDS: tuple[tuple[str, Callable[[str], bool]], ...] = (
    ("drawings", lambda n: n.endswith(("_drawing.pdf", "_drawing.dxf"))),
    ("CAD", lambda n: n.endswith((".dxf", ".step", ".stl"))),
    ("G-code", lambda n: n.endswith(".nc")),
    ("report", lambda n: n in ("report.html", "check.json")),
    ("plots", lambda n: n.startswith("plots/")),
    ("tables", lambda n: n.endswith((".xlsx", ".csv"))),
)
_GROUP_MAX = 6  # links shown per group (the rest counted)


def _num(v: float | None, digits: int = 2) -> str:
    return "–" if v is None else f"{v:.{digits}f}"


def _cells(e: dict) -> list[dict]:
    """The key-figure cells of a built cam: text, sort value, and whether it breaks its limit."""
    f = e.get("figures") or {}
    pa, lim = f.get("pressure_angle_max_deg"), f.get("pressure_angle_limit_deg")
    sp = f.get("speed") or {}
    star = "" if sp.get("given") else "*"
    speed = None if sp.get("value") is None else f"{sp['value']:.4g} {sp.get('unit', '')}{star}"
    dev, tol = f.get("deviation_mm"), e.get("tolerance_mm")
    return [
        {"text": _num(pa, 1) + ("" if lim is None else f" ({lim:g})"), "sort": "" if pa is None else pa,
         "over": pa is not None and lim is not None and pa > lim},
        {"text": _num(f.get("min_radius_of_curvature_mm")), "sort": f.get("min_radius_of_curvature_mm") or ""},
        {"text": _num(f.get("r_max_mm")), "sort": f.get("r_max_mm") or ""},
        {"text": _num(f.get("d_max_mm")), "sort": f.get("d_max_mm") or ""},
        {"text": speed or "–", "sort": "" if sp.get("value") is None else sp["value"]},
        {"text": "–" if dev is None else f"{dev:.2g}", "sort": "" if dev is None else dev,
         "title": None if tol is None else f"tolerance {tol:g} mm", "over": dev is not None and tol is not None
         and dev > tol},
    ]


def _groups(e: dict) -> list[dict]:
    """A cam's files grouped by kind (:data:`_KINDS`): at most :data:`_GROUP_MAX` links each."""
    folder = e.get("folder") or ""
    groups: dict[str, list[dict]] = {}
    for f in e.get("files", []):
        rel = Path(f["path"]).relative_to(folder).as_posix() if folder else f["path"]
        kind = next((k for k, test in _KINDS if test(rel)), "other")
        name = Path(rel).name  # shown without the cam's stem: "drawing.pdf", "dxf", "cam1.step", "lift.csv"
        label = name[len(folder):].lstrip("_.") if folder and name.startswith(folder) else name
        groups.setdefault(kind, []).append({"path": Path(f["path"]).as_posix(), "label": label or name})
    if "plots" in groups:  # the report's figures: one link to their folder
        plots = groups["plots"]
        groups["plots"] = [{"path": plots[0]["path"].rsplit("/", 1)[0] + "/", "label": f"{len(plots)} files"}]
    order = [k for k, _ in _KINDS] + ["other"]
    return [{"kind": k, "files": groups[k][:_GROUP_MAX], "more": max(0, len(groups[k]) - _GROUP_MAX)}
            for k in order if k in groups]


def index_html(manifest: dict) -> str:
    """The package's ``index.html`` (``templates/package/index.html.j2``, autoescaped): counts by verdict, the
    drawing set, one row per cam with its outline, key figures, reasons and files grouped by kind."""
    from jinja2 import Environment, select_autoescape

    env = Environment(autoescape=select_autoescape(default=True))
    tpl = env.from_string(read_template("package", "index.html.j2"))
    rank = {k: i for i, (k, _) in enumerate(_VERDICTS)}
    counts = dict.fromkeys(rank, 0)
    rows = []
    for e in manifest["cams"]:
        verdict = e.get("verdict") if e.get("status") != "error" else "error"
        counts[verdict if verdict in counts else "error"] += 1
        reasons = [{"code": r.get("code"), "message": r.get("message", ""),
                    "short": excerpt(str(r.get("message", "")).split("\n", 1)[0], 140)}
                   for r in e.get("reasons") or []]
        rows.append({"name": e.get("name"), "source": e.get("source"), "status": e.get("status"),
                     "error_label": _ERROR_LABEL.get(e.get("error_kind", ""), "error"),
                     "verdict": e.get("verdict"), "verdict_rank": rank.get(str(verdict), 9), "error": e.get("error"),
                     "drawing_number": e.get("drawing_number"), "reasons": reasons,
                     "cells": _cells(e), "groups": _groups(e), "outline": e.get("outline"),
                     "withheld": e.get("withheld", [])})
    return tpl.render(rows=rows, version=manifest["camfab_version"], counts=counts, verdicts=_VERDICTS,
                      drawing_set=manifest.get("drawing_set"))
