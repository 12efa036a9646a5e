"""
What a curve refit fits
=======================

The first step of :func:`fitting.fits.curves.fit_curves`: its arguments
checked and turned into the samples the least squares fit.

-   :class:`CurveProblem`: the checked curves, base, domain, settings and
    model kind of one refit, with its target samples, weights and degree.
-   :func:`refit_settings`: the settings with a call's overrides.
-   :func:`curve_problem`: the arguments checked (in a fixed order, so that
    the first broken rule is the one reported), the domain chosen and the
    target sampled (:func:`base_samples` with a base, :func:`curve_samples`
    without).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..domain import DEFAULT_ETA_I_RANGE, check_eta_i_range
from ..models.kinds import model_kind
from .curves_base import CurveBase, edited_target
from .curves_input import RGBCurve, check_curves
from .curves_score import angle_mu
from .curves_settings import CurveFitSettings
from .kinds import fit_kind
from .pipeline import FitKind

__all__ = ["CurveProblem", "refit_settings", "curve_problem", "base_samples", "curve_samples"]


@dataclass(frozen=True)
class CurveProblem:
    """
    One curve refit's problem, checked.

    Attributes
    ----------
    curves
        The :class:`RGBCurve` (:func:`check_curves`).
    base
        The material being edited, or None.
    eta_i_range
        The domain: the base's, or the one given (default
        :data:`fitting.domain.DEFAULT_ETA_I_RANGE`) holding every curve.
    name
        Name of the packed material.
    settings
        The :class:`CurveFitSettings` of the refit.
    model, solver
        The model kind's name and its :class:`~fitting.fits.pipeline.FitKind`
        (``solver.solve``, ``solver.bounded``).
    target, mu, eta, weights
        The fitted samples: (S, 3) linear ACEScg at (S,) cos theta and
        (S,) eta_i, with (S,) least-squares weights or None (all 1).
    degree
        The degree of the fit in eta_i.
    source
        The pack's provenance text (what was edited, at which eta_i).
    """

    curves: list[RGBCurve]
    base: CurveBase | None
    eta_i_range: tuple[float, float]
    name: str
    settings: CurveFitSettings
    model: str
    solver: FitKind
    target: np.ndarray
    mu: np.ndarray
    eta: np.ndarray
    weights: np.ndarray | None
    degree: int
    source: str


def refit_settings(settings: CurveFitSettings | None, overrides: dict[str, Any]) -> CurveFitSettings:
    """``settings`` (default :class:`CurveFitSettings`) with the fields of ``overrides`` replaced (checked)."""
    settings = settings or CurveFitSettings()
    if overrides:
        settings = CurveFitSettings(**{**settings.__dict__, **overrides})
    return settings


def _describe(curves: Sequence[RGBCurve]) -> str:
    return ", ".join(f"{c.eta_i:g}" for c in sorted(curves, key=lambda c: c.eta_i))


def _domain(curves: list[RGBCurve], base: CurveBase | None, eta_i_range) -> tuple[float, float]:
    """The refit's domain (the base's, else ``eta_i_range`` or the default), every curve's eta_i inside it."""
    if base is not None:
        if eta_i_range is not None and check_eta_i_range(eta_i_range) != base.eta_i_range:
            lo, hi = base.eta_i_range
            raise ValueError(
                f"`eta_i_range` must be the base's domain [{lo:g}, {hi:g}] or omitted, got {list(eta_i_range)}"
            )
        eta_i_range = base.eta_i_range
    else:
        eta_i_range = check_eta_i_range(DEFAULT_ETA_I_RANGE if eta_i_range is None else eta_i_range)
    lo, hi = eta_i_range
    for i, curve in enumerate(curves):
        if not lo - 1e-9 <= curve.eta_i <= hi + 1e-9:
            raise ValueError(f"`curves[{i}].eta_i` must lie in the domain [{lo:g}, {hi:g}], got {curve.eta_i:g}")
    return eta_i_range


def base_samples(curves: list[RGBCurve], base: CurveBase, settings: CurveFitSettings, max_degree: int):
    """
    The samples of a refit with a base: :func:`edited_target` at
    ``mu_samples`` angles evenly over [0, 90] degrees on ``eta_samples`` rows
    evenly over the base's domain plus one row per edited eta_i (a row
    within 1e-6 of an edit is the edit's), the edited rows weighted
    ``edit_weight``. Gives (target, mu, eta, weights, degree, source), the
    degree ``max_degree`` (the kind's).
    """
    lo, hi = base.eta_i_range
    mu_row = angle_mu(np.linspace(0.0, 90.0, settings.mu_samples))
    rows = np.linspace(lo, hi, settings.eta_samples) if hi > lo else np.array([lo])
    edited = np.array([c.eta_i for c in curves])
    rows = rows[np.all(np.abs(rows[:, None] - edited[None, :]) > 1e-6, axis=1)]
    rows = np.sort(np.concatenate([rows, edited]))
    E, M = np.meshgrid(rows, mu_row, indexing="ij")
    mu, eta = M.ravel(), E.ravel()
    target = edited_target(base, curves, mu, eta, settings.blend_width)
    is_edit = np.any(np.abs(eta[:, None] - edited[None, :]) <= 1e-6, axis=1)
    weights = np.where(is_edit, settings.edit_weight, 1.0)
    source = f"{base.name} with RGB curves edited at eta_i {_describe(curves)}"
    if base.source:
        source += f"; base: {base.source}"
    return target, mu, eta, weights, max_degree, source


def curve_samples(curves: list[RGBCurve], settings: CurveFitSettings, max_degree: int):
    """
    The samples of a refit without a base: each curve resampled to
    ``mu_samples`` values of cos theta evenly over its own span, unweighted.
    Gives (target, mu, eta, None, degree, source), the degree the number of
    curves less one, at most ``max_degree``.
    """
    spans = [np.linspace(c.cos_theta[0], c.cos_theta[-1], settings.mu_samples) for c in curves]
    mu = np.concatenate(spans)
    eta = np.repeat([c.eta_i for c in curves], settings.mu_samples)
    target = np.concatenate([c.sampled(span) for c, span in zip(curves, spans)])
    degree = min(max_degree, len(curves) - 1)
    return target, mu, eta, None, degree, f"RGB curves at eta_i {_describe(curves)}"


def curve_problem(
    curves: Sequence[RGBCurve | Mapping[str, Any]],
    base: CurveBase | None,
    eta_i_range,
    name: str,
    settings: CurveFitSettings,
    model: str,
) -> CurveProblem:
    """
    The :class:`CurveProblem` of :func:`fitting.fits.curves.fit_curves`'
    arguments: the curves checked, then the model kind, the name, the
    domain and the curves inside it (``ValueError`` naming the first rule
    broken), and the samples (:func:`base_samples` or :func:`curve_samples`).
    """
    curves = check_curves(curves)
    kind, solver = model_kind(model), fit_kind(model)
    if not isinstance(name, str) or not name.strip():
        raise ValueError("`name` must be a non-empty string")
    eta_i_range = _domain(curves, base, eta_i_range)
    if base is not None:
        samples = base_samples(curves, base, settings, kind.max_degree)
    else:
        samples = curve_samples(curves, settings, kind.max_degree)
    return CurveProblem(curves, base, eta_i_range, name, settings, kind.name, solver, *samples)
