"""
Fits of both auditors' measures at once
=======================================

When no candidate of a curve refit holds both auditors
(:mod:`fitting.fits.curves_audit`: the paper's method fitted with angles
evenly and with cos theta evenly), the guard
(:mod:`fitting.fits.curves_guard`) tries the fits of least Delta E on both
measures at once:

-   :func:`both_measures_fit`: de2000 fits of both measures' samples,
    reweighted round by round toward a measure whose mean is above the bar
    and toward the samples near a max above it.
-   :func:`blends`: coefficients between two successive rounds (one round's
    max over the bar, the next one's mean: a fit between may hold both).
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab
from ..colour.delta_e import delta_E_2000
from ..models.coated_conductor import coated_conductor_model
from ..models.pack import to_float16
from .curves_audit import AUDIT_GRIDS, AuditGrid
from .curves_score import check_grid
from .result import FitResult
from .solver import fit_coefficients

__all__ = ["CHECK_SAMPLES", "UNION_SAMPLES", "both_measures_fit", "blends"]

CHECK_SAMPLES = (19, 7)
"""Where the constrained refits keep the model in [0, 1]: the refit's default check grid."""

UNION_SAMPLES = 40
"""The both-measures fit's samples (:func:`both_measures_fit`): this many
angles evenly times as many eta_i, and as many cos theta evenly times as
many eta_i: the mean Delta E of both auditors' grids, four times coarser."""

_BOTH_MAX_NFEV = 100  # the both-measures fit's evaluations per round
_BOTH_ROUNDS = 4  # its reweightings toward a measure whose mean, or the points whose Delta E, is above the bar
_BOTH_NFEV = 200  # a round starts only while the rounds before used fewer evaluations than this, together
_BOTH_POWER = 4  # a sample's weight grows by 1 + (Delta E / the auditors' max) ** this a round
_BLEND_STEPS = 3  # coefficients tried evenly between two successive rounds of the both-measures fit


def both_measures_fit(
    base, curves, blend_width, start: FitResult, aim: dict, floor: dict, score, in_range, degree: int
):
    """
    The de2000 fits (least mean Delta E, :func:`fitting.fits.solver.fit_coefficients`)
    of the whole target on both auditors' measures at once
    (:data:`UNION_SAMPLES`), held in [0, 1] by the check grid's hinge, from
    ``start`` then each from the last, at most :data:`_BOTH_ROUNDS`: while a
    measure's mean stays above ``aim``'s, that measure is weighted up
    (doubled); while the max (``score(C16)`` by grid) is above ``floor``'s
    on a grid, every sample by 1 + (Delta E / that max) **
    :data:`_BOTH_POWER` (the max pulled down where it is, as Lawson's
    reweighting toward the least max); while a fit is not ``in_range(C16)``,
    the hinge ten times stiffer; no round started once the rounds before
    used :data:`_BOTH_NFEV` evaluations (a hard target's solves fall back
    to the bounded solver, several times dearer). Returns ``(fit, samples)`` of each round,
    ``samples`` = ``(target, mu, eta, weights)``.
    """
    grids = [AuditGrid(base, curves, blend_width, by, UNION_SAMPLES) for by in AUDIT_GRIDS]
    sizes = [g.M.size for g in grids]
    T = np.concatenate([g.T for g in grids])
    M, E = np.concatenate([g.M for g in grids]), np.concatenate([g.E for g in grids])
    Lab = np.concatenate([g.Lab for g in grids])
    CM, CE = check_grid(base.eta_i_range, *CHECK_SAMPLES)
    scale, boost, stiff = np.ones(len(grids)), np.ones(M.size), 1.0
    C, rounds, spent = start.coefficients, [], 0
    cap = min(ref.max for ref in floor.values())
    for _ in range(_BOTH_ROUNDS):
        if spent >= _BOTH_NFEV:
            break
        weights = np.repeat(scale, sizes) * boost
        fit = fit_coefficients(
            T,
            M,
            E,
            base.eta_i_range,
            degree,
            "de2000",
            _BOTH_MAX_NFEV,
            True,
            weights=weights,
            irls_rounds=0,
            range_check=(CM.ravel(), CE.ravel(), stiff),
            start=C,
        )
        C, spent = fit.coefficients, spent + fit.nfev
        rounds.append((fit, (T, M, E, weights)))
        scores = score(fit.coefficients_float16)
        over = [scores[grid.by].mean > aim[grid.by].mean for grid in grids]
        too_high = any(scores[by].max > floor[by].max for by in floor)
        outside = not in_range(fit.coefficients_float16)
        if not (any(over) and not all(over)) and not too_high and not outside:
            break
        if any(over) and not all(over):
            scale = np.where(over, 2.0 * scale, scale)
        if too_high:
            model = coated_conductor_model(M, E, fit.coefficients_float16, base.eta_i_range)
            boost = boost * (1.0 + (delta_E_2000(Lab, ACEScg_to_Lab(model)) / cap) ** _BOTH_POWER)
            boost /= boost.mean()
        if outside:
            stiff *= 10.0
    return rounds


def blends(rounds, steps=_BLEND_STEPS):
    """Float16 coefficients between each two successive rounds' fits (``(fit, samples)``), ``steps`` evenly inside."""
    for (a, _), (b, _) in zip(rounds, rounds[1:]):
        for t in np.linspace(0.0, 1.0, steps + 2)[1:-1]:
            C = (1.0 - t) * a.coefficients + t * b.coefficients
            yield a.with_coefficients(C, to_float16(C))
