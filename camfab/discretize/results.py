"""What a discretisation returns: the measured :class:`Deviation`, the polyline :class:`Discretisation`
and the arc chain :class:`ArcDiscretisation` (an :class:`~camfab.geom2d.ArcChain` with its fit data)."""
from __future__ import annotations

import numpy as np

from ..geom2d import ArcChain, J, rotate
from ..records import dataclass
from .chain import Chain

__all__ = ["Deviation", "Discretisation", "ArcDiscretisation"]


@dataclass(frozen=True)
class Deviation:
    """Measured two-way deviation between entities and an exact curve (mm).

    Attributes
    ----------
    max : float
        The Hausdorff-type maximum of the two directions.
    curve_to_entities : float
        Largest distance from a point of the exact curve to the entities.
    entities_to_curve : float
        Largest distance from a point of the entities to the exact curve.
    at_param : float
        Curve parameter where the maximum occurs (for the entity direction: the
        parameter of the closest curve point).
    at_point : (2,) ndarray
        The curve point at ``at_param``.
    """

    max: float
    curve_to_entities: float
    entities_to_curve: float
    at_param: float
    at_point: np.ndarray

    def __float__(self) -> float:
        return float(self.max)


@dataclass(frozen=True)
class Discretisation:
    """A polyline within ``tol`` of an exact curve.

    Attributes
    ----------
    params : (n,) ndarray
        Curve parameters of the vertices, from 0 to ``period`` inclusive; every
        breakpoint is among them.
    points : (n, 2) ndarray
        The vertices ``P(params)`` (mm); ``points[-1] == points[0]`` when closed.
    max_deviation : float
        Measured two-way maximum distance between the segments and the curve (mm).
    tol : float
        The requested tolerance; ``max_deviation <= tol``.
    closed : bool
        Whether the curve (and the polyline) is closed.
    """

    params: np.ndarray
    points: np.ndarray
    max_deviation: float
    tol: float
    closed: bool = True

    @property
    def n_entities(self) -> int:
        """Number of line segments."""
        return int(self.params.size - 1)

    def chain(self) -> Chain:
        """The segments as a :class:`Chain`."""
        return Chain.from_polyline(self.points, self.closed)

    def arc_chain(self) -> ArcChain:
        """The segments as an :class:`~camfab.geom2d.ArcChain` of lines with the measured deviation."""
        return ArcChain.from_polyline(self.points, closed=self.closed, max_deviation=self.max_deviation)


@dataclass(frozen=True, eq=False, kw_only=True)
class ArcDiscretisation(ArcChain):
    """A chain of arcs (and lines) within ``tol`` of a curve, tangent-continuous except at its kinks.

    An :class:`~camfab.geom2d.ArcChain` (``starts``, ``ends``, ``centres``, ``sweeps``, ``bulges``,
    ``closed``; ``ends[i] == starts[i + 1]`` exactly; ``max_deviation`` measured, ``<= tol``) with the
    data of its fit.

    Attributes
    ----------
    params : (m,) ndarray
        Curve parameters (0 … ``period``) where the chain passes through
        ``P(params)`` with the curve's tangent (exactly at breakpoints, to the
        surrogate's accuracy elsewhere).  For a free arc spline (see
        :func:`~camfab.discretize.fit.arcs`) they are its span ends (every kink among them; G1
        breakpoints may be crossed by arcs); for interpolating biarcs every
        fitting node (every breakpoint).
    tangents : (n, 2) ndarray
        Unit tangents at the entity starts.
    tol : float
        The requested tolerance (mm).
    """

    max_deviation: float  # always measured
    params: np.ndarray
    tangents: np.ndarray
    tol: float

    @classmethod
    def from_chain(cls, chain: Chain, params: np.ndarray, measured: float, tol: float,
                   closed: bool = True) -> ArcDiscretisation:
        """The chain ``chain`` as arcs with centres, sweeps and bulges (``tan(sweep/4)``)."""
        line = chain.curvature == 0
        ksafe = np.where(line, 1.0, chain.curvature)
        centres = np.where(line[:, None], np.nan, chain.start + J(chain.tangent) / ksafe[:, None])
        sweeps = chain.sweep
        return cls(chain.start, chain.end, centres, sweeps, np.tan(sweeps / 4.0), closed,
                   max_deviation=float(measured), params=params, tangents=chain.tangent, tol=tol)

    @property
    def end_tangents(self) -> np.ndarray:
        """Unit tangents at the entity ends."""
        return rotate(self.tangents, self.sweeps)

    def chain(self) -> Chain:
        """The entities as a :class:`Chain`."""
        line = self.is_line
        radii = np.where(line, 1.0, self.radii)  # a line's infinite radius never enters a product (inf·0)
        k = np.where(line, 0.0, np.sign(self.sweeps) / radii)
        length = np.where(line, np.hypot(*(self.ends - self.starts).T), np.abs(self.sweeps) * radii)
        return Chain(self.starts, self.tangents, k, length, self.ends)
