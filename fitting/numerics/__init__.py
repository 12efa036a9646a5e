"""
Numerics
========

Small dense solvers sized for the fits of this package (tens of unknowns,
hundreds of residuals), below every layer that fits something:

-   :func:`trf_least_squares`: the trust-region reflective method of
    :func:`scipy.optimize.least_squares` for small problems, without its
    per-iteration SVD (:mod:`fitting.numerics.trf`).
-   :func:`scipy_optimize`: scipy.optimize on first use, with a thread-pool
    controller that covers its BLAS (:mod:`fitting.numerics.optimize`).
-   :func:`unique`, :func:`union`, :func:`median`: numpy's of plain arrays
    without its import of numpy.ma (:mod:`fitting.numerics.plain`).
-   :func:`pchip`, :func:`akima`, :func:`cubic_spline`: scipy.interpolate's
    PCHIP, Akima and not-a-knot interpolants in numpy, without its import
    (:mod:`fitting.numerics.splines`).
"""

from .optimize import scipy_optimize
from .plain import median, union, unique
from .splines import akima, cubic_spline, pchip
from .trf import TRFResult, trf_least_squares

__all__ = [
    "TRFResult",
    "akima",
    "cubic_spline",
    "median",
    "pchip",
    "scipy_optimize",
    "trf_least_squares",
    "union",
    "unique",
]
