"""
The auditors of a curve refit
=============================

What the max guard of a curve refit (:mod:`fitting.fits.curves_guard`)
holds the refit against: the paper's method as an auditor runs it, plain rgb
least squares of the whole blended target on a dense grid, fitted from
several starts.

-   :func:`audit_grid`, :class:`AuditGrid`: an auditor's grid (one of
    :data:`AUDIT_GRIDS`), the whole target there, and scores on it.
-   :func:`auditor_fits`: the paper's method on one grid from each start;
    every distinct optimum the starts reach, the lowest residual first. An
    auditor's own starts may land in any of them (the local optima of the
    rgb residual differ in Delta E, and the one of lowest residual is not
    always the one of lowest Delta E), so the guard holds the refit no
    worse than each one that is a reflectance (:func:`audit_floor`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab
from ..colour.delta_e import delta_E_2000
from ..colour.reference import evaluation_grid
from ..models.coated_conductor import coated_conductor_model
from ..models.pack import to_float16
from .curves_base import edited_target
from .curves_score import score_grid
from .objective import coefficient_bounds
from .paper_method import paper_fit as paper_method_fit
from .result import FitResult
from .solver import fit_coefficients
from .worst_case import GuardScore, guard_score

__all__ = [
    "AUDIT_SAMPLES",
    "AUDIT_GRIDS",
    "AUDIT_STARTS",
    "AuditGrid",
    "AuditorFit",
    "audit_grid",
    "auditor_fits",
    "audit_floor",
]

AUDIT_SAMPLES = 100
"""The auditor's grids are :data:`AUDIT_SAMPLES` x :data:`AUDIT_SAMPLES`
points of the whole blended target, :data:`AUDIT_GRIDS`: where the guard
scores and caps a curve refit."""

AUDIT_GRIDS = ("angle", "cos_theta")
"""The two measures an auditor may sample the target by: angles evenly over
[0, 90] degrees (the editor's error map,
:data:`fitting.fits.curves_score.SCORE_GRID`, five times as dense) and cos
theta evenly over [0, 1] (the paper's grid,
:func:`fitting.colour.reference.evaluation_grid`), each times
:data:`AUDIT_SAMPLES` eta_i evenly over the domain. The paper's method fitted
on one measure is not the paper's method fitted on the other (their rgb
residuals weigh grazing angles differently): the refit is held no worse
than each auditor's fit on that auditor's own grid."""

AUDIT_STARTS = ("paper", "own", "guess")
"""The starts of the auditor's paper-method fits: the refit's paper-method
candidate, its own fit, and the variable-projection initial guess on the
audit grid (:func:`fitting.fits.start.initial_guess`)."""

_FREE_MAX_NFEV = 200  # the unconstrained paper fit's evaluations per channel
_POLISH_MAX_NFEV = 20  # its joint polish from the channels' optimum
_DISTINCT = 1e-6  # optima whose residuals differ by less than this, relatively, are one


def audit_grid(eta_i_range, by: str, samples: int = AUDIT_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """(cos_theta, eta_i), flattened, of the auditor's grid sampled ``by`` one of :data:`AUDIT_GRIDS`."""
    if by == "angle":
        _, _, M, E = score_grid(eta_i_range, (samples, samples))
    elif by == "cos_theta":
        M, E = evaluation_grid(samples, eta_i_range)
    else:
        raise ValueError(f"`by` must be one of {', '.join(AUDIT_GRIDS)}, got {by!r}")
    return M.ravel(), E.ravel()


class AuditGrid:
    """One auditor's grid: its points, the whole blended target there, and the scores of fits on it."""

    def __init__(self, base, curves, blend_width, by, samples=AUDIT_SAMPLES):
        self.by = by
        self.M, self.E = audit_grid(base.eta_i_range, by, samples)
        self.T = edited_target(base, curves, self.M, self.E, blend_width).reshape(-1, 3)
        self.Lab = ACEScg_to_Lab(self.T)
        self.range = base.eta_i_range

    def score(self, C16) -> GuardScore:
        return guard_score(self.Lab, coated_conductor_model(self.M, self.E, C16, self.range), self.M, self.E)

    def delta_E(self, C16) -> np.ndarray:
        """The Delta E 2000 of float16 coefficients ``C16`` at each point here."""
        return delta_E_2000(self.Lab, ACEScg_to_Lab(coated_conductor_model(self.M, self.E, C16, self.range)))

    def cost(self, C) -> float:
        """Half the sum of squared rgb residuals of coefficients ``C`` here."""
        r = coated_conductor_model(self.M, self.E, C, self.range).reshape(-1, 3) - self.T
        return 0.5 * float(np.sum(r * r))


@dataclass
class AuditorFit:
    """One optimum of an auditor's paper-method fit: the fit, its starts, its score, whether a reflectance."""

    fit: FitResult
    starts: list[str]
    score: GuardScore
    reflectance: bool


def auditor_fits(grid: AuditGrid, starts: dict, like: FitResult, degree: int, in_range) -> tuple[list, dict]:
    """
    The paper's method as an auditor runs it on ``grid``: rgb least squares
    of the whole target, no [0, 1] constraint, from each of ``starts``
    (coefficients by label), solved channel by channel
    (:func:`fitting.fits.paper_method.paper_fit`). Gives every distinct
    optimum (:class:`AuditorFit`), the lowest residual first (polished and
    quantised jointly from its optimum, as the fits are, where inside the
    coefficients' box; the others rounded to nearest, as the paper ships
    them), and every start's residual.
    ``in_range(C16)`` says whether float16 coefficients are a reflectance.
    """
    optima, costs = {}, {}
    for label, C in starts.items():
        start = like.with_coefficients(C, to_float16(C))
        optima[label] = paper_method_fit(
            grid.T, grid.M, grid.E, grid.range, degree, _FREE_MAX_NFEV, start, boxed=True
        ).coefficients
        costs[label] = grid.cost(optima[label])
    groups: list[list[str]] = []
    for label in sorted(costs, key=costs.__getitem__):
        if groups and costs[label] - costs[groups[-1][0]] <= _DISTINCT * costs[groups[-1][0]]:
            groups[-1].append(label)
        else:
            groups.append([label])
    out = []
    for i, group in enumerate(groups):
        C = optima[group[0]]
        lower, upper = (b.reshape(C.shape) for b in coefficient_bounds(degree))
        if i == 0 and np.all((C > lower) & (C < upper)):
            # The starts' polish is a joint solve from a converged optimum: the best one's only, and
            # only inside the box (one on its edge would leave it for the bounded solve, whose SVD of
            # the whole grid's Jacobian each step costs more than the audit).
            fit = fit_coefficients(grid.T, grid.M, grid.E, grid.range, degree, "rgb", _POLISH_MAX_NFEV, start=C)
        else:
            fit = like.with_coefficients(C, to_float16(C))
        out.append(
            AuditorFit(fit, group, grid.score(fit.coefficients_float16), bool(in_range(fit.coefficients_float16)))
        )
    return out, costs


def audit_floor(audits: list[AuditorFit]) -> GuardScore | None:
    """
    What the refit must not be worse than on an auditor's grid: the lowest
    mean and the lowest max of the auditor's optima that are reflectances
    (an auditor may ship any of them), None when none is.
    """
    kept = [a.score for a in audits if a.reflectance]
    if not kept:
        return None
    worst = min(kept, key=lambda s: s.max)
    return GuardScore(min(s.mean for s in kept), worst.max, worst.eta_i, worst.angle_deg)
