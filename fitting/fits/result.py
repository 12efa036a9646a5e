"""
The result of a fit
===================

-   :class:`FitResult`: coefficients (float64 and the shipped float16), the
    solver's convergence report, timings, and, filled by the pipeline that
    made it, the pack and the metrics; :meth:`FitResult.from_solve`, the one
    constructor of a fit's result from the solver's.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..models.kinds import DEFAULT_MODEL
from ..models.pack import PackedMaterial
from .metrics import ErrorMetrics

__all__ = ["FitResult"]


@dataclass
class FitResult:
    """
    Result of a fit.

    Attributes
    ----------
    coefficients
        Float64 least-squares optimum, (3, 3, degree + 1).
    coefficients_float16
        The shipped float16 coefficients (same shape).
    eta_i_range, degree, objective
        The fitted domain, polynomial degree and objective.
    success, status, message, nfev, njev
        Convergence report of the last solve (:func:`fitting.numerics.trf_least_squares`,
        or scipy's ``least_squares`` for a bounded one)
        (``status`` > 0 is convergence, 0 is the evaluation budget).
    cost
        Half the sum of squared (weighted) residuals of the last solve at the
        float64 optimum.
    cost_float16
        The same for the float16 coefficients.
    timings
        Seconds: ``reference``, ``fit``, ``quantise``, ``total``.
    coverage
        Fraction of 360-830 nm covered by the data (n, k fits).
    packed
        The :class:`fitting.models.pack.PackedMaterial` (n, k fits).
    metrics
        Filled by :func:`evaluate_material` or the caller.
    model
        The model kind (:data:`fitting.models.kinds.MODEL_KINDS`); an
        ``rgb-conductor`` fit has coefficients of shape (2, 3) and degree 0.
        Filled by :func:`fitting.fits.evaluate.evaluate_material` or the
        caller: the JSON of the errors (and, for curve fits, the counts).
    error
        The float16 model's error as :class:`fitting.fits.metrics.ErrorMetrics`,
        where it was measured (``metrics`` holds its JSON).
    settings
        The settings that ran (:class:`fitting.fits.settings.FitSettings` of a
        material fit; None where the caller set the samples itself): the
        provenance a stored fit records.
    best_effort
        True when the fit's evaluation budget ran out before it met its
        constraints, and ``coefficients_float16`` were then made to meet
        them (curve fits: :func:`fitting.fits.curves_range.in_range_fallback`).
    guard
        The max's guard (:func:`fitting.fits.guarded.guard_report`): the
        candidate kept and every candidate's mean, max and where the max is.
    quality
        ``range`` (the proof that the float16 model stays in [0, 1] over the
        whole domain, :func:`fitting.models.range_bound.certify_range`) and
        ``warnings`` (sparse data fitted with the gap limit relaxed, a model
        that leaves [0, 1]): :func:`fitting.fits.fit_quality.fit_quality`.
    """

    coefficients: np.ndarray
    coefficients_float16: np.ndarray
    eta_i_range: tuple[float, float]
    degree: int
    objective: str
    success: bool
    status: int
    message: str
    nfev: int
    njev: int
    cost: float
    cost_float16: float
    timings: dict[str, float] = field(default_factory=dict)
    coverage: float = 1.0
    packed: PackedMaterial | None = None
    metrics: dict[str, Any] = field(default_factory=dict)
    model: str = DEFAULT_MODEL
    error: ErrorMetrics | None = None
    best_effort: bool = False
    settings: Any = None

    @classmethod
    def from_solve(
        cls,
        solution,
        coefficients,
        coefficients_float16,
        eta_i_range,
        degree: int,
        objective: str,
        nfev: int,
        njev: int,
        cost_float16: float,
        timings: dict[str, float],
        model: str = DEFAULT_MODEL,
    ) -> "FitResult":
        """
        The result of a least-squares fit of any kind: ``solution`` is the
        last solve's result (:func:`fitting.numerics.trf_least_squares` or
        :func:`scipy.optimize.least_squares`: its success,
        status, message and cost), ``nfev`` / ``njev`` the totals over every
        solve (reweighting rounds included).
        """
        return cls(
            coefficients=coefficients,
            coefficients_float16=coefficients_float16,
            eta_i_range=eta_i_range,
            degree=int(degree),
            objective=objective,
            success=bool(solution.success),
            status=int(solution.status),
            message=str(solution.message),
            nfev=int(nfev),
            njev=int(njev),
            cost=float(solution.cost),
            cost_float16=float(cost_float16),
            timings=dict(timings),
            model=model,
        )

    guard: dict[str, Any] | None = None  # The worst-case guard's candidates (fitting.fits.guarded)
    quality: dict[str, Any] = field(default_factory=dict)  # Range proof and data warnings (fitting.fits.fit_quality)

    def with_coefficients(self, coefficients, coefficients_float16) -> "FitResult":
        """
        This result with other coefficients (a candidate of the same solve:
        its report and timings kept), e.g. the worst-case guard's
        (:mod:`fitting.fits.guarded`, :mod:`fitting.fits.curves_guard`).
        """
        return dataclasses.replace(
            self,
            coefficients=np.asarray(coefficients, dtype=np.float64),
            coefficients_float16=coefficients_float16,
            timings=dict(self.timings),
            metrics={},
            packed=None,
            error=None,
        )

    @property
    def iterations(self) -> int:
        """Jacobian evaluations, one per accepted trust-region step."""
        return self.njev

    def summary(self) -> dict[str, Any]:
        """JSON-friendly report of the convergence and timings."""
        return {
            "model": self.model,
            "success": self.success,
            "status": self.status,
            "message": self.message,
            "iterations": self.iterations,
            "nfev": self.nfev,
            "cost": self.cost,
            "cost_float16": self.cost_float16,
            "objective": self.objective,
            "degree": self.degree,
            "coverage": self.coverage,
            "timings": dict(self.timings),
            **({"quality": self.quality} if self.quality else {}),
            **({"guard": self.guard} if self.guard is not None else {}),
        }
