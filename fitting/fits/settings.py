"""
Fit settings and the fitting grid
=================================

-   :data:`OBJECTIVES`: ``rgb`` (the paper), ``lab`` and ``de2000``;
    :data:`DEFAULT_OBJECTIVE`.
-   :class:`FitSettings`: the settings of a material fit.
-   :func:`fit_grid`, :data:`GRIDS`: the (cos theta, eta_i) samples a fit is
    solved on, Gauss-Legendre or uniform.
-   :func:`check_fit_options`: the rules the settings of material and curve
    fits share (objective, solver budget, reweighting rounds).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..optics.quality import DEFAULT_MAX_GAP_NM, check_max_gap
from ..domain import DEFAULT_MIN_COVERAGE, check_choice, check_int, check_min_coverage, check_step_nm

__all__ = [
    "OBJECTIVES",
    "DEFAULT_OBJECTIVE",
    "DEGREES",
    "GRIDS",
    "FitSettings",
    "check_fit_options",
    "check_degree",
    "fit_grid",
]

OBJECTIVES = ("rgb", "lab", "de2000")
DEFAULT_OBJECTIVE = "de2000"
"""The objective with the lower Delta E 2000 on the library (docs/results.md)."""

GRIDS = ("gauss", "uniform")
"""Kinds of fitting grid (:func:`fit_grid`)."""

DEGREES = (0, 1, 2)
"""Polynomial degrees in t of F0, a and alpha."""


def check_degree(degree) -> int:
    """A polynomial degree of :data:`DEGREES`."""
    if degree not in DEGREES:
        raise ValueError(f"`degree` must be 0, 1 or 2, got {degree!r}")
    return degree


def check_fit_options(objective, max_nfev, irls_rounds) -> None:
    """The settings every fit shares: objective, evaluation budget, IRLS rounds."""
    check_choice("objective", objective, OBJECTIVES)
    check_int("max_nfev", max_nfev, 1)
    check_int("irls_rounds", irls_rounds, 0, 10)


@dataclass(frozen=True)
class FitSettings:
    """
    Settings of a material fit.

    Attributes
    ----------
    mu_samples, eta_samples, grid
        The fitting grid (:func:`fit_grid`): ``mu_samples`` values of cos
        theta over [0, 1] times ``eta_samples`` values of eta_i over the
        domain (1 when the domain is a single value), at Gauss-Legendre nodes
        with quadrature weights (``"gauss"``) or evenly (``"uniform"``).
    step_nm
        Spectral step of the reference used for fitting (nm).
    objective
        One of :data:`OBJECTIVES`.
    degree
        Polynomial degree in t of F0, a and alpha (0, 1 or 2); forced to 0
        for a single eta_i.
    quantise
        Choose float16 coefficients by :func:`fitting.fits.quantise.quantise_coefficients`
        (otherwise round the float32 fit).
    max_nfev
        Evaluation budget of the trust-region solver.
    min_coverage
        Smallest covered fraction of 360-830 nm accepted.
    irls_rounds
        Reweighting rounds of the ``de2000`` objective (mean Delta E).
    guard_max
        Guard the max (:mod:`fitting.fits.guarded`): keep the mean fit only
        when its mean and max are no worse than the paper method's on the
        guard points, else a constrained refit or the paper method's fit
        (not for the ``rgb`` objective: that is the paper's method).
    max_gap_nm
        Largest spacing of the data's samples inside 360-830 nm accepted
        (:mod:`fitting.optics.quality`); past the default the fit carries a
        warning.
    """

    mu_samples: int = 12
    eta_samples: int = 4
    grid: str = "gauss"
    step_nm: float = 5.0
    objective: str = DEFAULT_OBJECTIVE
    degree: int = 2
    quantise: bool = True
    max_nfev: int = 200
    min_coverage: float = DEFAULT_MIN_COVERAGE
    irls_rounds: int = 2
    guard_max: bool = True
    max_gap_nm: float = DEFAULT_MAX_GAP_NM

    def __post_init__(self) -> None:
        check_int("mu_samples", self.mu_samples, 4, 1000)
        check_int("eta_samples", self.eta_samples, 1, 1000)
        check_choice("grid", self.grid, GRIDS)
        check_degree(self.degree)
        check_fit_options(self.objective, self.max_nfev, self.irls_rounds)
        check_min_coverage(self.min_coverage)
        check_step_nm(self.step_nm)
        check_max_gap(self.max_gap_nm)
        if not isinstance(self.guard_max, bool):
            raise ValueError(f"`guard_max` must be true or false, got {self.guard_max!r}")


@functools.lru_cache(maxsize=64)
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights of ``n`` points on [-1, 1], read-only
    (numpy's ``leggauss`` solves an eigenproblem each call: half a
    millisecond, a twentieth of a material fit)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = w.flags.writeable = False
    return x, w


def fit_grid(
    eta_i_range: tuple[float, float],
    mu_samples: int = 12,
    eta_samples: int = 4,
    kind: str = "gauss",
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Flattened fitting grid over [0, 1] x ``eta_i_range`` with sample weights.

    The error the fit is judged by is the mean over a fine uniform grid, an
    approximation of the integral over (cos theta, eta_i). ``"gauss"`` places
    the samples at Gauss-Legendre nodes with their quadrature weights, which
    integrate smooth functions exactly to degree 2n - 1, so a small grid
    stands for the fine one; ``"uniform"`` spaces them evenly with equal
    weights. A single eta_i (lo = hi) gives one row.

    Returns
    -------
    tuple
        ``cos_theta``, ``eta_i`` and ``weights`` (mean 1), each flattened
        (samples indexed [eta_i, cos_theta]).
    """
    check_choice("kind", kind, GRIDS)
    lo, hi = eta_i_range

    def axis(n, a, b):
        if kind == "uniform":
            return np.linspace(a, b, n), np.ones(n)
        x, w = _gauss_legendre(n)
        return a + 0.5 * (x + 1.0) * (b - a), w

    mu, w_mu = axis(mu_samples, 0.0, 1.0)
    eta, w_eta = (np.array([lo]), np.ones(1)) if hi <= lo else axis(eta_samples, lo, hi)
    E, M = np.meshgrid(eta, mu, indexing="ij")
    W = np.outer(w_eta, w_mu)
    return M.ravel(), E.ravel(), (W / W.mean()).ravel()
