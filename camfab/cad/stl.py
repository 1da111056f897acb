"""STL export of the cam plate: watertight, outward normals, chordal tolerance.

The plate is a prism, so its mesh is written directly: the face (outline minus bore, shapely) triangulated by
earcut (``mapbox_earcut``) for the top and, reversed, the bottom, and two triangles per boundary chord for the
walls; the binary STL is one numpy structured array.  trimesh (which imports scipy.spatial, ~0.8 s) only reads
the files back in the tests (docs/decisions.md, "STL written with numpy").
"""
from __future__ import annotations

import numpy as np

from ..errors import GeometryError, MissingDependencyError
from ..geom2d import ArcChain
from ..textsafe import plain
from .plate import PlateSpec

__all__ = ["plate_triangles", "prism_triangles", "cap_triangles", "wall_triangles", "is_closed_surface",
           "stl_bytes", "dumps"]

#: one binary STL facet: unit normal, three vertices, the (unused) attribute byte count
FACET = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])


def _polygon(loop: ArcChain, tol: float):
    from shapely.geometry import Polygon

    return Polygon(loop.flatten(tol))


def _rings(body) -> list[np.ndarray]:
    """The rings of a shapely polygon, exterior counter-clockwise and holes clockwise, without the closing
    vertex or repeated consecutive vertices."""
    from shapely.geometry.polygon import orient

    body = orient(body, 1.0)
    out = []
    for ring in (body.exterior, *body.interiors):
        xy = np.asarray(ring.coords, dtype=np.float64)[:-1]
        keep = np.any(xy != np.roll(xy, 1, axis=0), axis=1)
        out.append(xy[keep])
    return out


def cap_triangles(rings: list[np.ndarray], z: float, *, up: bool) -> np.ndarray:
    """Triangles ``(k, 3, 3)`` of the flat face bounded by ``rings`` (the exterior first, then the holes) at
    height ``z`` (earcut: no new vertices), counter-clockwise seen from +z when ``up``, else from −z."""
    try:
        import mapbox_earcut as earcut
    except ImportError as exc:  # pragma: no cover - exercised only without the dependency
        raise MissingDependencyError("STL export needs mapbox_earcut: pip install mapbox_earcut") from exc
    xy = np.concatenate(rings)
    ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
    tri = np.asarray(earcut.triangulate_float64(xy, ends), dtype=np.int64).reshape(-1, 3)
    a, b, c = xy[tri[:, 0]], xy[tri[:, 1]], xy[tri[:, 2]]
    cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
    tri[cw] = tri[cw][:, ::-1]  # counter-clockwise seen from +z
    xyz = np.column_stack([xy, np.full(len(xy), float(z))])
    return xyz[tri if up else tri[:, ::-1]]


def wall_triangles(ring: np.ndarray, z0: float, z1: float) -> np.ndarray:
    """Triangles ``(2n, 3, 3)`` of the wall from z0 to z1 (> z0) along the closed ring ``(n, 2)``, facing the
    right of its direction: outward for a counter-clockwise exterior or a clockwise hole of the material."""
    p, q = ring, np.roll(ring, -1, axis=0)
    lo, hi = np.full((len(ring), 1), float(z0)), np.full((len(ring), 1), float(z1))
    p0, q0, p1, q1 = np.hstack([p, lo]), np.hstack([q, lo]), np.hstack([p, hi]), np.hstack([q, hi])
    return np.concatenate([np.stack([p0, q0, q1], axis=1), np.stack([p0, q1, p1], axis=1)])


def prism_triangles(rings: list[np.ndarray], height: float) -> np.ndarray:
    """Triangles ``(m, 3, 3)`` of the prism over a face (exterior ring counter-clockwise, holes clockwise)
    from z = 0 to z = ``height``, every triangle counter-clockwise seen from outside."""
    caps = [cap_triangles(rings, height, up=True), cap_triangles(rings, 0.0, up=False)]
    return np.concatenate(caps + [wall_triangles(r, 0.0, height) for r in rings])


def is_closed_surface(triangles: np.ndarray) -> bool:
    """True when the triangles, their vertices identified by exact coordinates, form closed surfaces with a
    consistent winding: every directed edge appears once and its reverse once (what trimesh calls watertight
    and winding-consistent)."""
    tri = np.ascontiguousarray(triangles, dtype=np.float64)
    _, ids = np.unique(tri.reshape(-1, 3), axis=0, return_inverse=True)
    ids = ids.reshape(-1, 3).astype(np.int64)
    n = int(ids.max()) + 1 if ids.size else 0
    heads, tails = ids, np.roll(ids, -1, axis=1)
    edges = (heads * n + tails).ravel()
    reverse = (tails * n + heads).ravel()
    uniq = np.unique(edges)
    return bool(ids.size) and len(uniq) == len(edges) and bool(np.isin(reverse, uniq).all())


def plate_triangles(outline: ArcChain, plate: PlateSpec, *, tol: float) -> np.ndarray:
    """The triangles ``(m, 3, 3)`` of a watertight mesh of the plate, arcs flattened within ``tol``.

    The outline is flattened by chords inscribed in the exact curve, so the mesh
    is within ``tol`` of the exact solid everywhere (its volume is slightly
    below the exact one, by at most perimeter × tol × thickness).
    """
    if plate.hub_diameter_mm and plate.hub_length_mm:
        raise GeometryError("STL export of a plate with a hub is not supported yet; "
                            "remove manufacturing.hub_diameter_mm for the STL or use STEP")
    poly = _polygon(outline, tol)
    hole = plate.hole()
    body = poly.difference(_polygon(hole, tol)) if hole is not None else poly
    if body.geom_type != "Polygon" or body.is_empty:
        raise GeometryError(f"the bore (manufacturing.bore_mm = {plate.bore_mm:g}) leaves "
                            f"{'nothing' if body.is_empty else 'several pieces'} of the plate: it must lie inside "
                            "the profile; make it smaller")
    return prism_triangles(_rings(body), plate.thickness_mm)


def stl_bytes(triangles: np.ndarray, header: str) -> bytes:
    """Binary STL of ``triangles`` ``(m, 3, 3)``: an 80-byte ASCII header, the count, one facet each (the
    unit normal from the float64 vertices, by the right-hand rule)."""
    tri = np.asarray(triangles, dtype=np.float64)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
    facets = np.zeros(len(tri), dtype=FACET)
    facets["normal"], facets["vertices"] = n, tri
    head = header.encode("ascii", "replace")[:80].ljust(80, b" ")
    return head + np.uint32(len(tri)).astype("<u4").tobytes() + facets.tobytes()


def dumps(outline: ArcChain, plate: PlateSpec, *, tol: float, name: str = "cam") -> bytes:
    """Binary STL bytes of the plate, deterministic for the same input."""
    return stl_bytes(plate_triangles(outline, plate, tol=tol), f"camfab {plain(name)} units=mm tol={tol:g}")
