"""
Cubic interpolants through data
===============================

The three piecewise-cubic readings of sparse spectral data that
:func:`fitting.fits.fit_quality.data_uncertainty` compares, as
scipy.interpolate builds them, in numpy:

-   :func:`pchip`: :class:`scipy.interpolate.PchipInterpolator` (monotone
    cubic: Fritsch-Butland weighted harmonic means of the slopes, the
    one-sided three-point ends of Moler's ``pchiptx``);
-   :func:`akima`: :class:`scipy.interpolate.Akima1DInterpolator` with
    ``method="akima"`` (Akima's 1970 weights, two slopes extrapolated
    linearly past each end);
-   :func:`cubic_spline`: :class:`scipy.interpolate.CubicSpline` with its
    default ``bc_type="not-a-knot"``.

Each returns a callable that evaluates the cubic Hermite form on
``[x[0], x[-1]]`` (values outside are clamped to the end intervals'
cubics, as scipy extrapolates; callers here evaluate inside only). Why
not scipy itself: importing scipy.interpolate costs about 0.5 s of wall
time on the machines this project runs on (it pulls in scipy.special,
scipy.optimize and scipy.linalg), the whole budget of a command-line fit
of a sparse metal such as the library's gold; the tests hold these to
scipy's values to rounding (``tests/fitting/numerics/test_splines.py``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["pchip", "akima", "cubic_spline", "hermite"]


def _checked(x, y) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if x.ndim != 1 or y.shape != x.shape:
        raise ValueError(f"`x` and `y` must be 1-D of one length, got shapes {x.shape} and {y.shape}")
    if x.size < 2:
        raise ValueError(f"`x` must have at least 2 samples, got {x.size}")
    if not np.all(np.diff(x) > 0):
        raise ValueError("`x` must be strictly increasing")
    return x, y


def hermite(x: np.ndarray, y: np.ndarray, slopes: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """The piecewise cubic through ``(x, y)`` with ``slopes`` at the nodes (scipy's CubicHermiteSpline)."""
    h = np.diff(x)
    m = np.diff(y) / h
    c2 = (3.0 * m - 2.0 * slopes[:-1] - slopes[1:]) / h
    c3 = (slopes[:-1] + slopes[1:] - 2.0 * m) / h**2

    def evaluate(xi) -> np.ndarray:
        xi = np.asarray(xi, dtype=np.float64)
        i = np.clip(np.searchsorted(x, xi, side="right") - 1, 0, x.size - 2)
        t = xi - x[i]
        return ((c3[i] * t + c2[i]) * t + slopes[i]) * t + y[i]

    return evaluate


def _pchip_end(h0, h1, m0, m1) -> float:
    """The end slope of scipy's PchipInterpolator: three-point, then kept monotone."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > 3.0 * abs(m0):
        return 3.0 * m0
    return float(d)


def pchip(x, y) -> Callable[[np.ndarray], np.ndarray]:
    """The monotone piecewise cubic of :class:`scipy.interpolate.PchipInterpolator`."""
    x, y = _checked(x, y)
    h = np.diff(x)
    m = np.diff(y) / h
    if x.size == 2:
        return hermite(x, y, np.full(2, m[0]))
    d = np.zeros_like(y)
    flat = (np.sign(m[1:]) != np.sign(m[:-1])) | (m[1:] == 0) | (m[:-1] == 0)
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        harmonic = (w1 / m[:-1] + w2 / m[1:]) / (w1 + w2)
        d[1:-1] = np.where(flat, 0.0, 1.0 / harmonic)
    d[0] = _pchip_end(h[0], h[1], m[0], m[1])
    d[-1] = _pchip_end(h[-1], h[-2], m[-1], m[-2])
    return hermite(x, y, d)


def akima(x, y) -> Callable[[np.ndarray], np.ndarray]:
    """The piecewise cubic of :class:`scipy.interpolate.Akima1DInterpolator` (``method="akima"``)."""
    x, y = _checked(x, y)
    if x.size == 2:
        return hermite(x, y, np.full(2, (y[1] - y[0]) / (x[1] - x[0])))
    m = np.empty(x.size + 3)
    m[2:-2] = np.diff(y) / np.diff(x)
    m[1] = 2.0 * m[2] - m[3]
    m[0] = 2.0 * m[1] - m[2]
    m[-2] = 2.0 * m[-3] - m[-4]
    m[-1] = 2.0 * m[-2] - m[-3]
    t = 0.5 * (m[3:] + m[:-3])  # where both weights vanish (m1 == m2, m3 == m4)
    dm = np.abs(np.diff(m))
    f1, f2 = dm[2:], dm[:-2]
    f12 = f1 + f2
    defined = f12 > 1e-9 * np.max(f12, initial=-np.inf)
    i = np.flatnonzero(defined)
    t[i] = m[i + 1] + (f2[i] / f12[i]) * (m[i + 2] - m[i + 1])
    return hermite(x, y, t)


def _tridiagonal(lower: np.ndarray, diagonal: np.ndarray, upper: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Thomas's algorithm (no pivoting: for diagonally dominant systems)."""
    n = diagonal.size
    c, d = np.empty(n), np.empty(n)
    c[0], d[0] = upper[0] / diagonal[0], b[0] / diagonal[0]
    for i in range(1, n):
        denominator = diagonal[i] - lower[i] * c[i - 1]
        c[i] = upper[i] / denominator if i < n - 1 else 0.0
        d[i] = (b[i] - lower[i] * d[i - 1]) / denominator
    out = np.empty(n)
    out[-1] = d[-1]
    for i in range(n - 2, -1, -1):
        out[i] = d[i] - c[i] * out[i + 1]
    return out


def cubic_spline(x, y) -> Callable[[np.ndarray], np.ndarray]:
    """
    The not-a-knot cubic spline of :class:`scipy.interpolate.CubicSpline`.

    Its slopes solve scipy's tridiagonal system; the not-a-knot rows at each
    end are first taken off their neighbours (which leaves a diagonally
    dominant system, solved without pivoting), then give the end slopes.
    """
    x, y = _checked(x, y)
    n = x.size
    h = np.diff(x)
    m = np.diff(y) / h
    if n == 2:
        return hermite(x, y, np.full(2, m[0]))
    if n == 3:  # one parabola through the three points
        A = np.array([[1.0, 1.0, 0.0], [h[1], 2.0 * (h[0] + h[1]), h[0]], [0.0, 1.0, 1.0]])
        b = np.array([2.0 * m[0], 3.0 * (h[0] * m[1] + h[1] * m[0]), 2.0 * m[1]])
        return hermite(x, y, np.linalg.solve(A, b))
    # Rows 0..n-1 of scipy's system: row i (interior) is
    # h[i] s[i-1] + 2 (h[i-1] + h[i]) s[i] + h[i-1] s[i+1] = 3 (h[i] m[i-1] + h[i-1] m[i]).
    d0 = x[2] - x[0]
    first = (h[1], d0, ((h[0] + 2.0 * d0) * h[1] * m[0] + h[0] ** 2 * m[1]) / d0)  # s0, s1 coefficients, rhs
    dn = x[-1] - x[-3]
    last = (dn, h[-2], (h[-1] ** 2 * m[-2] + (2.0 * dn + h[-1]) * h[-2] * m[-1]) / dn)  # s[-2], s[-1], rhs
    lower = np.zeros(n)
    diagonal = np.zeros(n)
    upper = np.zeros(n)
    b = np.zeros(n)
    lower[1:-1] = h[1:]
    diagonal[1:-1] = 2.0 * (h[:-1] + h[1:])
    upper[1:-1] = h[:-1]
    b[1:-1] = 3.0 * (h[1:] * m[:-1] + h[:-1] * m[1:])
    # Row 1 minus row 0 scaled to cancel s0 (both rows carry h[1] s0): row 0 is
    # h[1] s0 + d0 s1 = r0, row 1 is h[1] s0 + 2 (h[0] + h[1]) s1 + h[0] s2 = b1.
    diagonal[1] -= first[1]
    b[1] -= first[2]
    lower[1] = 0.0
    # Likewise the last two rows, to cancel s[-1] (both carry h[-2] s[-1]).
    diagonal[-2] -= last[0]
    b[-2] -= last[2]
    upper[-2] = 0.0
    inner = _tridiagonal(lower[1:-1], diagonal[1:-1], upper[1:-1], b[1:-1])
    s = np.empty(n)
    s[1:-1] = inner
    s[0] = (first[2] - first[1] * s[1]) / first[0]
    s[-1] = (last[2] - last[0] * s[-2]) / last[1]
    return hermite(x, y, s)
