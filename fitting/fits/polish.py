"""
Float16 polish of a kept fit
============================

Where the guard keeps a twin of the paper's method (a curve refit whose own
fit could not get its max under the paper's), the shipped coefficients are
that least-squares optimum rounded to float16, and an outside auditor's
paper fit is the same optimum rounded by its own solver: the two tie up to
one float16 step in a coefficient or two, and which one is ahead on the mean
(by about 1e-6) is a coin toss. :func:`polish_float16` settles it: one-ulp
moves of single float16 coefficients that lower one figure (mean or max
Delta E 2000 on the scoring points) without raising the other, best first,
so the result is ahead of the rounded optimum on both figures by what
float16 allows, not by chance.

Each step predicts every move (two per coefficient) to first order: the
gradient of each point's Delta E in the coefficients, from the residuals
and Jacobian of the ``de2000`` objective
(:meth:`fitting.fits.objective.Problem.residuals_jacobian`, the CIEDE2000
metric at the target colour, as the guard's SLSQP objective takes it); the :data:`SCREEN` most
promising are scored exactly (scoring all 54 exactly, measured by hand once, took about 65 ms a
step, Delta E 2000 on 77,000 points), the best exact one taken. A step
whose exact scores help neither figure ends the polish, so it never cycles
(each accepted move strictly lowers one figure and does not raise the
other).
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab
from ..colour.delta_e import delta_E_2000
from ..models.coated_conductor import coated_conductor_model
from .objective import Problem, delta_E_gradients
from .worst_case import score_of
from ..numerics.plain import unique

__all__ = ["POLISH_STEPS", "SCREEN", "polish_float16"]

POLISH_STEPS = 8
"""Most one-ulp moves taken. Measured on the curve edits of
``benchmarks/curve_edits_vs_paper.py`` whose kept fit is the paper
method's twin: see docs/fitting.md."""

SCREEN = (4, 2)
"""Moves scored exactly each step: the most promising by the predicted
mean (among those predicted not to raise the max), and by the predicted
max (among those predicted not to raise the mean)."""


def _neighbours(C16: np.ndarray) -> np.ndarray:
    """Every float16 array one ulp away from ``C16`` in one coefficient, (2 n, *C16.shape)."""
    flat = C16.ravel()
    n = flat.size
    moves = np.repeat(flat[None], 2 * n, axis=0)
    index = np.arange(n)
    with np.errstate(over="ignore"):
        moves[index, index] = np.nextafter(flat, np.float16(np.inf))
        moves[n + index, index] = np.nextafter(flat, np.float16(-np.inf))
    keep = np.all(np.isfinite(moves), axis=1)
    return moves[keep].reshape(-1, *C16.shape)


def _figures(target_Lab, cos_theta, eta_i, eta_i_range, stack: np.ndarray):
    """Mean and max Delta E 2000 of each coefficient array of ``stack`` (K, ...): (K,), (K,), (K, S)."""
    models = np.stack([coated_conductor_model(cos_theta, eta_i, C, eta_i_range) for C in stack])
    dE = delta_E_2000(np.broadcast_to(target_Lab, models.shape), ACEScg_to_Lab(models))
    return dE.mean(axis=1), dE.max(axis=1), dE


def _predicted(problem: Problem, C16, moves, dE):
    """First-order Delta E of each move (K, S): the exact ``dE`` of ``C16`` plus the gradient times the step."""
    G = delta_E_gradients(*problem.residuals_jacobian(C16.ravel().astype(np.float64)))
    steps = moves.reshape(len(moves), -1).astype(np.float64) - C16.ravel().astype(np.float64)
    return dE[None] + steps @ G.T


def polish_float16(C16, target_RGB, cos_theta, eta_i, eta_i_range, steps: int = POLISH_STEPS):
    """
    ``C16`` moved one float16 ulp at a time while a move lowers the mean
    Delta E 2000 against ``target_RGB`` (S, 3, linear ACEScg) at
    (``cos_theta``, ``eta_i``) (S,) without raising the max (else lowers
    the max without raising the mean), at most ``steps`` moves. Returns
    ``(C16, score)`` (:class:`fitting.fits.worst_case.GuardScore`) of the
    result, ``C16`` itself when no move helped. The caller proves the
    result's range.
    """
    C16 = np.asarray(C16, dtype=np.float16)
    mu, eta = np.ravel(cos_theta), np.ravel(eta_i)
    problem = Problem(target_RGB, mu, eta, eta_i_range, C16.shape[2] - 1, "de2000")
    target_Lab = problem.target_out
    means, maxes, dE = _figures(target_Lab, mu, eta, eta_i_range, C16[None])
    mean, peak, where = float(means[0]), float(maxes[0]), dE[0]
    by_mean, by_max = SCREEN
    for _ in range(steps):
        moves = _neighbours(C16)
        predicted = _predicted(problem, C16, moves, where)
        p_mean, p_max = predicted.mean(axis=1), predicted.max(axis=1)
        picks = unique(
            np.concatenate(
                [
                    np.argsort(np.where(p_max <= peak, p_mean, np.inf))[:by_mean],
                    np.argsort(np.where(p_mean <= mean, p_max, np.inf))[:by_max],
                ]
            )
        )
        means, maxes, dE = _figures(target_Lab, mu, eta, eta_i_range, moves[picks])
        lower_mean = (means < mean) & (maxes <= peak)
        lower_max = (maxes < peak) & (means <= mean)
        if lower_mean.any():
            k = int(np.argmin(np.where(lower_mean, means, np.inf)))
        elif lower_max.any():
            k = int(np.argmin(np.where(lower_max, maxes, np.inf)))
        else:
            break
        C16, mean, peak, where = moves[picks[k]], float(means[k]), float(maxes[k]), dE[k]
    return C16, score_of(where, mu, eta)
