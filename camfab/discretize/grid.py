"""Exact nearest-site queries in the plane on uniform grids, numpy only.

The deviation measurement of every fit asked ``scipy.spatial.cKDTree`` for its candidates; importing
``scipy.spatial`` cost ~0.36 s of every ``camfab export`` (it pulls scipy.sparse, scipy.special and scipy.linalg).
Here the sites are bucketed in square cells, each query takes the sites of the 3×3 cells around it, and its
answer is certified exact when no site outside those cells can beat it (every such site is at least one cell
away); queries left uncertified retry on grids of 2×, 4×, … 32× coarser cells, and the last ones are compared
with every site — or, when many queries lie far from every site (a fit far off its curve), first settled on a k-d tree's
candidates, the only case that imports scipy.spatial (docs/decisions.md, "Start-up and export time").
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["grid_nearest"]

#: each level's cells are this many times the previous level's
_GROWTH = 2.0
#: (query, site) pairs compared at once when a query is compared with every site
_BRUTE_PAIRS = 2_000_000
#: grids tried (each ``_GROWTH`` times coarser); then a k-d tree for many queries left, else every site
_LEVELS = 6
#: candidates per query of the k-d tree pass
_KD_K = 32


def _column_min(a: np.ndarray) -> np.ndarray:
    """``a.min(axis=0)`` of an ``(N, 2)`` array: the same values, an order of magnitude faster for a few thousand
    rows (numpy's reduction over the leading axis of a two-column array is a slow strided loop)."""
    return np.array([a[:, 0].min(), a[:, 1].min()])


def _column_max(a: np.ndarray) -> np.ndarray:
    """``a.max(axis=0)`` of an ``(N, 2)`` array (as :func:`_column_min`)."""
    return np.array([a[:, 0].max(), a[:, 1].max()])


def _site_cells(sites: np.ndarray, cell: float) -> tuple | None:
    """The sites bucketed in cells of side ``cell``: ``(origin, nx, ny, order, sorted keys)``, or None when the grid
    would need more cells than int64 keys can number."""
    origin = _column_min(sites)
    cs = np.floor((sites - origin) / cell)
    nx, ny = _column_max(cs) + 1
    if nx * ny > 2.0 ** 60:
        return None
    ny_i = int(ny)
    keys = cs[:, 0].astype(np.int64) * ny_i + cs[:, 1].astype(np.int64)
    order = np.argsort(keys, kind="stable")
    return origin, nx, ny, order, keys[order]


def _candidates(sites: np.ndarray, q: np.ndarray, cell: float, cells: dict | None = None
                ) -> tuple[np.ndarray, np.ndarray] | None:
    """Every (query row, site index) pair whose site lies in the 3×3 cells around the query's cell, grouped by
    query row in increasing order, or None when the grid would need more cells than int64 keys can number.

    Keys number the cells column by column, so a query's 3×3 cells are three runs of consecutive keys (one
    ``searchsorted`` pair each).  ``cells``: the sites' buckets by cell side, kept for the next queries of the
    same sites (a caller's dictionary)."""
    if cells is None:
        grid = _site_cells(sites, cell)
    else:
        if cell not in cells:
            cells[cell] = _site_cells(sites, cell)
        grid = cells[cell]
    if grid is None:
        return None
    origin, nx, ny, order, skeys = grid
    ny_i = int(ny)
    qc = np.floor((q - origin) / cell)
    qc = np.clip(qc, -2.0, np.array([nx, ny]) + 1.0).astype(np.int64)  # far queries: no site near, no overflow
    col = qc[:, 0, None] + np.arange(-1, 2)  # (N, 3) the three columns
    y_lo = np.maximum(qc[:, 1] - 1, 0)[:, None]
    y_hi = np.minimum(qc[:, 1] + 1, ny_i - 1)[:, None]
    valid = (col >= 0) & (col < nx) & (y_lo <= y_hi)
    lo = np.searchsorted(skeys, col * ny_i + y_lo, side="left")
    hi = np.searchsorted(skeys, col * ny_i + y_hi, side="right")
    counts = np.where(valid, hi - lo, 0).ravel()
    total = int(counts.sum())
    rows = np.repeat(np.repeat(np.arange(q.shape[0]), 3), counts)
    first = np.repeat(lo.ravel(), counts)
    within = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    return rows, order[first + within]


def _row_minima(rows: np.ndarray, site: np.ndarray, d: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Per query row (``rows`` grouped in increasing order): the smallest ``d`` and its site (the lowest site
    index among equal distances); ``inf`` and 0 for a row without pairs."""
    best = np.full(n, np.inf)
    arg = np.zeros(n, dtype=np.int64)
    if rows.size:
        head = np.flatnonzero(np.concatenate([[True], rows[1:] != rows[:-1]]))
        r = rows[head]
        best[r] = np.minimum.reduceat(d, head)
        tied = np.where(d == best[rows], site, np.iinfo(np.int64).max)
        arg[r] = np.minimum.reduceat(tied, head)
    return best, arg


def grid_nearest(q: np.ndarray, sites: np.ndarray, cell: float,
                 distance: Callable[[np.ndarray, np.ndarray], np.ndarray], reach: float = 0.0,
                 cells: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The smallest ``distance(q_rows, site_indices)`` over every site, for each query point, exactly.

    Parameters
    ----------
    q : (N, 2) array
        Query points.
    sites : (M, 2) array
        The sites' positions; ``distance(q, j)`` must be at least ``|q − sites[j]| − reach`` (a site stands for
        an object within ``reach`` of it, e.g. a short piece of an arc).
    cell : float
        The finest cells' side (about the spacing of the sites).
    distance : callable
        ``distance(points (K, 2), site indices (K,)) -> (K,)`` distances.
    cells : dict, optional
        A dictionary kept by the caller for queries of the same ``sites``: their buckets per cell side are made
        once and reused (the same answers).

    Returns
    -------
    (distance (N,), site index (N,))
        The minimum over all sites and the site holding it (the lowest index among equal distances).
    """
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    n, m = q.shape[0], sites.shape[0]
    best = np.full(n, np.inf)
    arg = np.zeros(n, dtype=np.int64)
    # the largest side of the box around sites and queries (np.ptp of both stacked, without the copy and the slow
    # reductions; np.minimum / np.maximum propagate a NaN as those reductions do)
    extent = float((np.maximum(_column_max(sites), _column_max(q)) - np.minimum(_column_min(sites), _column_min(q))
                    ).max()) if n else 0.0
    todo = np.arange(n)
    cell = max(float(cell), 1e-12 * max(extent, 1.0))
    for _ in range(_LEVELS):
        if not todo.size or cell >= extent:
            break
        pairs = _candidates(sites, q[todo], cell, cells)
        if pairs is None:
            break
        rows, site = pairs
        d, j = _row_minima(rows, site, distance(q[todo][rows], site), todo.size)
        # a site outside the 3×3 cells is at least `cell` from the query: its object at least cell − reach
        done = d <= (cell - reach) * (1.0 - 1e-9)
        best[todo[done]], arg[todo[done]] = d[done], j[done]
        todo = todo[~done]
        cell *= _GROWTH
    if todo.size * m > _BRUTE_PAIRS:  # many queries far from every site: a k-d tree's candidates
        todo = _kdtree_pass(q, sites, distance, reach, todo, best, arg)
    step = max(1, _BRUTE_PAIRS // max(m, 1))
    every = np.arange(m)
    for c in range(0, todo.size, step):  # what no grid certified: against every site
        sel = todo[c:c + step]
        d = distance(np.repeat(q[sel], m, axis=0), np.tile(every, sel.size)).reshape(sel.size, m)
        arg[sel] = d.argmin(axis=1)
        best[sel] = d[np.arange(sel.size), arg[sel]]
    return best, arg


def _kdtree_pass(q: np.ndarray, sites: np.ndarray, distance: Callable[[np.ndarray, np.ndarray], np.ndarray],
                 reach: float, todo: np.ndarray, best: np.ndarray, arg: np.ndarray) -> np.ndarray:
    """Settle the queries ``todo`` on the ``_KD_K`` nearest sites of a k-d tree (filling ``best`` and ``arg``);
    returns those whose answer the tree's candidates do not prove (the k-th site within the best distance plus
    ``reach``).  Only queries far from every site come here (a fit far off its curve), so scipy.spatial is
    imported only then."""
    from scipy.spatial import cKDTree

    k = min(_KD_K, sites.shape[0])
    dm, idx = cKDTree(sites).query(q[todo], k=k)
    dm, idx = dm.reshape(todo.size, k), idx.reshape(todo.size, k)
    d = distance(np.repeat(q[todo], k, axis=0), idx.ravel()).reshape(todo.size, k)
    j = np.lexsort((idx, d))[:, 0]  # per row: the smallest distance, the lowest site among equal ones
    rows = np.arange(todo.size)
    best[todo], arg[todo] = d[rows, j], idx[rows, j]
    sure = (k == sites.shape[0]) | (dm[:, -1] - reach >= d[rows, j] * (1.0 + 1e-9))
    return todo[~sure]

