"""
Fits from edited reflectance curves
===================================

Artistic control over a material (Vernooij 2024, Section 6, "a curve editor,
allowing modifications to the RGB reflectance dataset, and subsequently
fitting coefficients to the adjusted data"): RGB reflectance curves against
cos theta, at one or more coating indices eta_i, in linear ACEScg, fitted by
the coated-conductor model (:mod:`fitting.models.coated_conductor`).

-   The curves: :mod:`fitting.fits.curves_input` (:class:`RGBCurve`,
    :func:`check_curves`).
-   The base and the blending of edits: :mod:`fitting.fits.curves_base`
    (:class:`CurveBase`, :func:`blend_weights`, :func:`edited_target`).
-   :func:`fit_curves`: the fit, its float16 pack and its Delta E 2000
    against the edited curves.
-   :class:`CurveFitSettings`: sampling and solver settings of
    :func:`fit_curves` (defaults measured by ``benchmarks/curves_fit.py``).

With a base, an edited curve replaces the base's reflectance at its eta_i and
the difference it makes fades smoothly across eta_i (:func:`blend_weights`);
the fit keeps the full quadratic dependence on eta_i. Without a base, the
curves are all there is, and the dependence on eta_i drops to what they
determine: constant for one eta_i, linear for two, quadratic for three or
more (the pack's degree records it).

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Section 6 (future work).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..domain import DEFAULT_ETA_I_RANGE, check_eta_i_range, check_int, check_number
from ..models.coated_conductor import coated_conductor_model
from ..models.pack import PackedMaterial
from .curves_base import CurveBase, edited_target
from .curves_input import RGBCurve, check_curves
from .metrics import curve_metrics, delta_E_summary
from .result import FitResult
from .settings import check_fit_options
from .solver import fit_coefficients

__all__ = ["CurveFitSettings", "fit_curves"]


@dataclass(frozen=True)
class CurveFitSettings:
    """
    Settings of :func:`fit_curves`.

    Attributes
    ----------
    mu_samples
        cos theta samples per eta_i row: each curve is resampled linearly to
        this many values evenly over its own span (without a base) or over
        [0, 1] (with a base).
    eta_samples
        Rows of the base evenly over the domain, besides the edited rows.
    objective, irls_rounds, max_nfev, quantise
        Passed to :func:`fitting.fits.solver.fit_coefficients`.
    blend_width
        Distance in eta_i over which an edit fades beyond the outermost
        edited indices (:func:`blend_weights`).
    edit_weight
        Least-squares weight of each sample of an edited row relative to a
        sample of a base row (with a base): the edited curves are what the
        artist looks at.
    """

    mu_samples: int = 8
    eta_samples: int = 4
    objective: str = "de2000"
    irls_rounds: int = 0
    max_nfev: int = 15
    quantise: bool = True
    blend_width: float = 1.0
    edit_weight: float = 3.0

    def __post_init__(self) -> None:
        check_int("mu_samples", self.mu_samples, 4, 256)
        check_int("eta_samples", self.eta_samples, 1, 64)
        check_fit_options(self.objective, self.max_nfev, self.irls_rounds)
        check_number("blend_width", self.blend_width, 0.0)
        check_number("edit_weight", self.edit_weight, 1.0, 1000.0)


def _describe(curves: Sequence[RGBCurve]) -> str:
    return ", ".join(f"{c.eta_i:g}" for c in sorted(curves, key=lambda c: c.eta_i))


def fit_curves(
    curves: Sequence[RGBCurve | Mapping[str, Any]],
    base: CurveBase | None = None,
    eta_i_range=None,
    name: str = "edited",
    settings: CurveFitSettings | None = None,
    **overrides,
) -> FitResult:
    """
    Fit the coated-conductor model to RGB reflectance curves.

    With a ``base``, the target is :func:`edited_target` on ``mu_samples``
    values of cos theta evenly over [0, 1] at ``eta_samples`` rows evenly over
    the base's domain plus one row per edited eta_i; the fit has degree 2 in
    eta_i over the base's domain. Without a base, the target is the curves
    themselves, each resampled to ``mu_samples`` values over its own span of
    cos theta; the degree is the number of distinct eta_i less one, at most 2,
    over ``eta_i_range`` (default [1, 2.5]), which must hold every curve.

    Parameters
    ----------
    curves
        :class:`RGBCurve` or mappings (see :func:`check_curves`), linear ACEScg.
    base
        The material being edited, or None.
    eta_i_range
        The domain of a fit without a base; with a base, None or the base's.
    name
        Name of the packed material.
    settings, overrides
        :class:`CurveFitSettings`, individual fields replaced by ``overrides``.

    Returns
    -------
    FitResult
        With ``packed`` (the float16 material), ``timings`` (``target``,
        ``fit``, ``quantise``, ``total`` in seconds), ``error`` (the
        :class:`~fitting.fits.metrics.ErrorMetrics` against the curves, one
        row per curve) and ``metrics``, its JSON:
        ``delta_E_mean`` and ``delta_E_max`` (CIE Delta E 2000 of the float16
        model against the curves at their own samples), ``by_curve`` (the same
        per curve, with its ``eta_i``), ``samples`` (the number of fitted
        samples), ``base`` (its name or None) and, with a base, ``target``
        (mean and max Delta E 2000 over the whole blended target).

    Raises
    ------
    ValueError
        For invalid curves, settings, name or domain, curves outside the
        domain, or a domain other than the base's.
    """
    t0 = time.perf_counter()
    settings = settings or CurveFitSettings()
    if overrides:
        settings = CurveFitSettings(**{**settings.__dict__, **overrides})
    curves = check_curves(curves)
    if not isinstance(name, str) or not name.strip():
        raise ValueError("`name` must be a non-empty string")
    if base is not None:
        if eta_i_range is not None and check_eta_i_range(eta_i_range) != base.eta_i_range:
            lo, hi = base.eta_i_range
            raise ValueError(
                f"`eta_i_range` must be the base's domain [{lo:g}, {hi:g}] or omitted, "
                f"got {list(eta_i_range)}"
            )
        eta_i_range = base.eta_i_range
    else:
        eta_i_range = check_eta_i_range(DEFAULT_ETA_I_RANGE if eta_i_range is None else eta_i_range)
    lo, hi = eta_i_range
    for i, curve in enumerate(curves):
        if not lo - 1e-9 <= curve.eta_i <= hi + 1e-9:
            raise ValueError(
                f"`curves[{i}].eta_i` must lie in the domain [{lo:g}, {hi:g}], got {curve.eta_i:g}"
            )
    if base is not None:
        mu_row = np.linspace(0.0, 1.0, settings.mu_samples)
        rows = np.linspace(lo, hi, settings.eta_samples) if hi > lo else np.array([lo])
        edited = np.array([c.eta_i for c in curves])
        rows = rows[np.all(np.abs(rows[:, None] - edited[None, :]) > 1e-6, axis=1)]
        rows = np.sort(np.concatenate([rows, edited]))
        E, M = np.meshgrid(rows, mu_row, indexing="ij")
        mu, eta = M.ravel(), E.ravel()
        target = edited_target(base, curves, mu, eta, settings.blend_width)
        is_edit = np.any(np.abs(eta[:, None] - edited[None, :]) <= 1e-6, axis=1)
        weights = np.where(is_edit, settings.edit_weight, 1.0)
        degree = 2
        source = f"{base.name} with RGB curves edited at eta_i {_describe(curves)}"
        if base.source:
            source += f"; base: {base.source}"
    else:
        mu = np.concatenate([np.linspace(c.cos_theta[0], c.cos_theta[-1], settings.mu_samples) for c in curves])
        eta = np.repeat([c.eta_i for c in curves], settings.mu_samples)
        target = np.concatenate([c.sampled(np.linspace(c.cos_theta[0], c.cos_theta[-1], settings.mu_samples)) for c in curves])
        degree = min(2, len(curves) - 1)
        weights = None
        source = f"RGB curves at eta_i {_describe(curves)}"
    t_target = time.perf_counter()
    result = fit_coefficients(
        target, mu, eta, eta_i_range, degree, settings.objective, settings.max_nfev,
        settings.quantise, weights=weights, irls_rounds=settings.irls_rounds,
    )
    C16 = result.coefficients_float16
    error = curve_metrics(
        curves, lambda c: coated_conductor_model(c.cos_theta, c.eta_i, C16, eta_i_range),
        "the edited curves at their samples",
    )
    metrics: dict[str, Any] = {
        **error.to_dict(),
        "samples": int(mu.size),
        "base": None if base is None else base.name,
    }
    if base is not None:
        metrics["target"] = delta_E_summary(
            target, coated_conductor_model(mu, eta, C16, eta_i_range),
            "the blended target", layout="grid",
        ).to_dict()
    result.error = error
    result.metrics = metrics
    result.packed = PackedMaterial(
        name=name, coefficients=C16, eta_i_range=eta_i_range, source=source[:4000], metrics=metrics
    )
    result.timings["target"] = t_target - t0
    result.timings["total"] = time.perf_counter() - t0
    return result
