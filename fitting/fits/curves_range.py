"""
The [0, 1] range of curve fits, and their evaluation budget
===========================================================

A curve fit is a reflectance: its float16 model must stay in [0, 1] over
its whole domain (:mod:`fitting.fits.curves`). The least squares hold it by
a penalty (:func:`fitting.fits.solver.fit_coefficients` ``range_check``),
made stiffer while the fit still leaves [0, 1]; that escalation has a
budget, and a fit the budget cannot bring into range is made so here.

-   :data:`RANGE_TOLERANCE`: how far past [0, 1] a float16 fit may read.
-   :func:`outside_range`: where on the scoring grid a float16 fit leaves [0, 1].
-   :func:`in_range_fallback`: the closest in-range variant of a fit found by
    shrinking its shape term (always exists: the Schlick limit).
-   :class:`EvaluationBudget`: model evaluations left to one refit.
"""

from __future__ import annotations

import functools

import numpy as np

from ..models.coated_conductor import coated_conductor_model, model_parameters
from ..models.range_bound import certify_range
from ..models.pack import to_float16
from .curves_score import SCORE_GRID, check_grid
from ..numerics.plain import unique

__all__ = [
    "RANGE_TOLERANCE",
    "PROOF_CELLS",
    "outside_range",
    "proven_in_range",
    "range_report",
    "escape_points",
    "in_range_fallback",
    "EvaluationBudget",
]

RANGE_TOLERANCE = 1e-4
"""float16 rounding of a fit on the boundary."""

_SHAPE_SCALES = (0.9, 0.75, 0.5, 0.25, 0.0)  # shrink factors of the a term tried, largest first


def outside_range(C16, eta_i_range) -> np.ndarray:
    """
    (M * E, 3) mask of the points of :data:`SCORE_GRID` (angles x eta_i
    over ``eta_i_range``) and channels where the model of coefficients
    ``C16`` leaves [0, 1] by more than :data:`RANGE_TOLERANCE`.
    """
    M, E = check_grid(eta_i_range, *SCORE_GRID)
    values = coated_conductor_model(M.ravel(), E.ravel(), C16, eta_i_range)
    return (values < -RANGE_TOLERANCE) | (values > 1.0 + RANGE_TOLERANCE)


def _channel_only(C, channel: int) -> np.ndarray:
    """``C`` with every channel but ``channel`` replaced by the constant 0.5 (in range)."""
    out = np.zeros_like(np.asarray(C, dtype=np.float64))
    out[0, :, 0] = 0.5
    out[:, channel, :] = np.asarray(C, dtype=np.float64)[:, channel, :]
    return out


PROOF_CELLS = 400_000
"""Cells a proof of [0, 1] examines at most by default (:func:`fitting.models.range_bound.certify_range`)."""


@functools.lru_cache(maxsize=256)
def _certificate(key: bytes, shape: tuple[int, ...], eta_i_range: tuple[float, float], max_cells: int):
    """:func:`certify_range` at :data:`RANGE_TOLERANCE`, once per coefficients (a refit asks again and again)."""
    C = np.frombuffer(key, dtype=np.float64).reshape(shape)
    return certify_range(C, eta_i_range, RANGE_TOLERANCE, max_cells=max_cells)


def _certified(C, eta_i_range, max_cells: int = PROOF_CELLS):
    C = np.ascontiguousarray(C, dtype=np.float64)
    return _certificate(C.tobytes(), C.shape, tuple(float(v) for v in eta_i_range), int(max_cells))


def proven_in_range(C16, eta_i_range, channel: int | None = None, max_cells: int = PROOF_CELLS) -> bool:
    """
    Whether the model of ``C16`` is proven inside [0, 1] (by
    :data:`RANGE_TOLERANCE`) over the whole domain, every channel or one
    (:func:`fitting.models.range_bound.certify_range` examining at most
    ``max_cells`` cells; unproven counts as outside).
    """
    C = C16 if channel is None else _channel_only(C16, channel)
    return _certified(C, eta_i_range, max_cells).in_range is True


def range_report(C16, eta_i_range, max_cells: int = PROOF_CELLS) -> dict:
    """The JSON of :func:`fitting.models.range_bound.certify_range` at :data:`RANGE_TOLERANCE`."""
    return _certified(C16, eta_i_range, max_cells).to_dict()


def escape_points(C16, eta_i_range, mask, range_M, range_E, check_rows: int, max_cells: int = PROOF_CELLS):
    """
    Extra check points of a refit leaving [0, 1]: the scoring-grid points
    of ``mask`` (over ``range_M``, ``range_E``) and, unless proven in
    range, the certificate's counterexample with its neighbours in cos
    theta (x 0.5, 1.5, 2) at every check row and its own eta_i.
    """
    pm, pe = range_M[mask], range_E[mask]
    certificate = _certified(C16, eta_i_range, max_cells)
    if certificate.in_range is not True:
        mu_w, eta_w = certificate.worst[0], certificate.worst[1]
        rows = unique(np.concatenate([check_grid(eta_i_range, 2, check_rows)[1][:, 0], [eta_w]]))
        near = np.clip(mu_w * np.array([0.5, 1.0, 1.5, 2.0]), 0.0, 1.0)
        NM, NE = np.meshgrid(near, rows)
        pm, pe = np.concatenate([pm, NM.ravel()]), np.concatenate([pe, NE.ravel()])
    return pm, pe


def in_range_fallback(C16, eta_i_range, max_cells: int = PROOF_CELLS) -> np.ndarray:
    """
    Float16 coefficients in [0, 1] over the whole domain (on the scoring
    grid and proven by :func:`proven_in_range`), as close to
    ``C16`` as a shrink of each out-of-range channel's shape term allows.

    Per channel of Eq. 1, :math:`F = F_0 + (1 - F_0)(1 - \\mu)^5 - s\\,a\\,
    \\mu(1 - \\mu)^\\alpha`: the largest :math:`s` of 1, 0.9, 0.75, 0.5, 0.25,
    0 that keeps the channel in range is kept. At :math:`s = 0` the channel
    is Schlick's, in [0, 1] whenever :math:`F_0` is; a channel whose
    :math:`F_0` polynomial itself leaves [0, 1] gets its mean over the
    domain, clipped to [0, 1], as a constant. Coefficients already in range
    are returned unchanged.
    """
    C = np.asarray(C16, dtype=np.float64).copy()
    bad = outside_range(to_float16(C), eta_i_range).any(axis=0)
    # The whole domain, not the grid only (no proof asked of a channel the grid already refutes).
    bad |= np.array([not bad[c] and not proven_in_range(to_float16(C), eta_i_range, c, max_cells) for c in range(3)])
    if not bad.any():
        return to_float16(C)
    rows = check_grid(eta_i_range, 2, SCORE_GRID[1])[1][:, 0]
    F0 = model_parameters(C, rows, eta_i_range)[:, 0, :]  # (E, channel)
    for c in np.flatnonzero(bad):
        if F0[:, c].min() < 0.0 or F0[:, c].max() > 1.0:
            C[0, c, :] = 0.0
            C[0, c, 0] = float(np.clip(F0[:, c].mean(), 0.0, 1.0))
        a = C[1, c, :].copy()
        for scale in _SHAPE_SCALES:
            C[1, c, :] = scale * a
            if not outside_range(to_float16(C), eta_i_range)[:, c].any() and proven_in_range(
                to_float16(C), eta_i_range, c, max_cells
            ):
                break
    return to_float16(C)


class EvaluationBudget:
    """
    Model evaluations (residuals and Jacobian each count one) left to one
    refit, over all its solves, escalation rounds and candidates. A refit's
    samples are bounded by its settings, so evaluations bound its CPU time.
    """

    def __init__(self, evaluations: int) -> None:
        self.left = int(evaluations)
        self.cut = False  # a solve was shortened, or an escalation skipped, by the budget

    def per_solve(self, wanted: int, solves: int) -> int:
        """The ``max_nfev`` of each of up to ``solves`` solves wanting ``wanted`` each."""
        return min(wanted, max(1, self.left // max(1, solves)))

    def spend(self, result, max_nfev: int, wanted: int) -> None:
        """Charge a fit's evaluations; marked cut when its solve stopped at a budget-shortened ``max_nfev``."""
        self.left -= int(result.nfev + result.njev)
        if max_nfev < wanted and result.status == 0:
            self.cut = True

    def allows(self, minimum: int) -> bool:
        """Whether ``minimum`` more evaluations are left (else the budget is marked cut)."""
        if self.left < minimum:
            self.cut = True
            return False
        return True
