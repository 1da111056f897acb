"""cos and sin of arrays of angles, the same bits on every CPU.

The profile evaluates cos/sin of the cam angle (and of an arm angle) at every sample.  numpy's float64
``sin``/``cos`` are not one function: numpy picks an implementation by build and CPU at run time (SIMD kernels
such as SVML on AVX-512 machines, the C library elsewhere), and these differ in the last bits — so a profile,
and every exported file's bytes, would depend on the machine.  These kernels are fdlibm's (``k_sin.c``,
``k_cos.c``: Cody–Waite reduction by π/2, minimax polynomials on [−π/4, π/4], quadrant selection), written as
~40 elementwise IEEE operations on numpy arrays: accurate to ~1 ulp (tested against the library),
deterministic everywhere, and on a CPU without AVX-512 twice as fast as numpy's scalar library calls
(``benchmarks/bench_profile.py``).  The decision and its measurement are recorded in ``docs/decisions.md``
("cos/sin kernels").
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["cos_sin", "SINCOS_MAX"]

# fdlibm's kernel polynomials for sin and cos on [−π/4, π/4] and its two-part π/2
_PIO2_1, _PIO2_1T = 1.57079632673412561417e+00, 6.07710050650619224932e-11
_SIN_C = (1.58969099521155010221e-10, -2.50507602534068634195e-08, 2.75573137070700676789e-06,
          -1.98412698298579493134e-04, 8.33333333332248946124e-03, -1.66666666666666324348e-01)
_COS_C = (-1.13596475577881948265e-11, 2.08757232129817482790e-09, -2.75573143513906633035e-07,
          2.48015872894767294178e-05, -1.38888888888741095749e-03, 4.16666666666666019037e-02)
#: |x| below which the reduction x − k·π/2 is exact enough (k·_PIO2_1 exact for |k| < 2²⁰)
SINCOS_MAX = 1.0e5
#: cos and sin of q·π/2 for the quadrant q = 0…3
_QUAD_COS, _QUAD_SIN = np.array([1.0, 0.0, -1.0, 0.0]), np.array([0.0, 1.0, 0.0, -1.0])


def _kernels(r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """fdlibm's cos and sin of the reduced argument r ∈ [−π/4, π/4]."""
    z = r * r
    ps = _SIN_C[0] * z
    for cf in _SIN_C[1:]:
        ps += cf
        ps *= z
    ps *= r
    sin_r = r + ps
    pc = _COS_C[0] * z
    for cf in _COS_C[1:]:
        pc += cf
        pc *= z
    pc *= z
    cos_r = 1.0 - 0.5 * z
    cos_r += pc
    return cos_r, sin_r


def cos_sin(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(cos x, sin x)`` to ~1 ulp, vectorised, the same bits on every CPU.

    Parameters
    ----------
    x : (n,) float array
        Angles in radians.  Beyond :data:`SINCOS_MAX` (never a cam angle), NaN or inf, a complex exponential
        is used.
    """
    x = np.asarray(x, dtype=float)
    if x.size == 0 or not np.abs(x).max() < SINCOS_MAX:  # also NaN / inf
        e = np.exp(x * 1j)
        return e.real, e.imag
    k = np.rint(x * (2.0 / math.pi))
    r = x - k * _PIO2_1
    r -= k * _PIO2_1T
    cos_r, sin_r = _kernels(r)
    # quadrant q = k mod 4: cos x = a·cos r − b·sin r, sin x = b·cos r + a·sin r with (a, b) the
    # quadrant's (cos, sin) of q·π/2 (0 or ±1, so the result is exactly ±cos r or ±sin r)
    q = k.astype(np.intp) & 3
    a, b = _QUAD_COS.take(q), _QUAD_SIN.take(q)
    c = cos_r * a
    c -= sin_r * b
    s = cos_r * b
    s += sin_r * a
    return c, s
