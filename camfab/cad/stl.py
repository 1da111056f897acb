"""STL export of the cam plate (trimesh): watertight, outward normals, chordal tolerance."""
from __future__ import annotations

from ..errors import GeometryError, MissingDependencyError
from ..geom2d import ArcChain
from ..textsafe import plain
from .plate import PlateSpec

__all__ = ["plate_mesh", "dumps"]


def _polygon(loop: ArcChain, tol: float):
    from shapely.geometry import Polygon

    return Polygon(loop.flatten(tol))


def plate_mesh(outline: ArcChain, plate: PlateSpec, *, tol: float):
    """A watertight ``trimesh.Trimesh`` of the plate (and hub), arcs flattened within ``tol``.

    The outline is flattened by chords inscribed in the exact curve, so the mesh
    is within ``tol`` of the exact solid everywhere (its volume is slightly
    below the exact one, by at most perimeter × tol × thickness).
    """
    try:
        import trimesh
    except ImportError as exc:  # pragma: no cover - exercised only without the extra
        raise MissingDependencyError("STL export needs trimesh and mapbox_earcut: "
                                     "pip install trimesh mapbox_earcut") from exc
    if plate.hub_diameter_mm and plate.hub_length_mm:
        raise GeometryError("STL export of a plate with a hub is not supported yet; "
                            "remove manufacturing.hub_diameter_mm for the STL or use STEP")
    poly = _polygon(outline, tol)
    hole = plate.hole()
    body = poly.difference(_polygon(hole, tol)) if hole is not None else poly
    mesh = trimesh.creation.extrude_polygon(body, plate.thickness_mm)
    mesh.merge_vertices()
    mesh.fix_normals()
    return mesh


def dumps(outline: ArcChain, plate: PlateSpec, *, tol: float, name: str = "cam") -> bytes:
    """Binary STL bytes of the plate, deterministic for the same input."""
    mesh = plate_mesh(outline, plate, tol=tol)
    data = mesh.export(file_type="stl")
    head = f"camfab {plain(name)} units=mm tol={tol:g}".encode("ascii", "replace")[:80].ljust(80, b" ")
    return head + data[80:]
