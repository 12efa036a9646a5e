"""
Float16 n, k of the rgb-conductor kind
======================================

-   :class:`RGBConductorObjective`: residuals of an rgb-conductor fit in
    linear RGB, CIE Lab or the first-order CIEDE2000 metric, and the
    objective itself for many candidates at once.
-   :func:`quantise_rgb_conductor`: the float16 n, k that minimise it.
-   :func:`nk_bounds`, :data:`N_BOUNDS`, :data:`K_BOUNDS`.

References
----------
Sharma, G., Wu, W., & Dalal, E. N. (2005). The CIEDE2000 color-difference formula.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab, ACEScg_to_Lab_jacobian
from ..colour.delta_e import de2000_weights, delta_E_2000
from ..models.pack import to_float16
from ..models.rgb_conductor import rgb_conductor_model
from ..optics.fresnel import fresnel_conductor, fresnel_conductor_derivatives
from ..numerics.plain import unique

__all__ = ["N_BOUNDS", "K_BOUNDS", "nk_bounds", "RGBConductorObjective", "quantise_rgb_conductor"]

N_BOUNDS = (1.0e-3, 20.0)
"""Bounds of n per channel: n > 0 as for any SpectralNK; every conductor of
the library has n < 5 in 360-830 nm."""
K_BOUNDS = (0.0, 50.0)
"""Bounds of k per channel; the library's conductors have k < 12."""


class RGBConductorObjective:
    """Residuals of one fit: samples S, 3 outputs each (rgb, Lab or first-order CIEDE2000)."""

    def __init__(self, target, mu, eta, objective, weights):
        self.mu, self.eta, self.objective = mu, eta, objective
        self.target = target
        self.w = np.ones(mu.size) if weights is None else weights
        if objective == "rgb":
            self.target_out = target
        else:
            self.target_out = ACEScg_to_Lab(target)
            self.A = de2000_weights(self.target_out) if objective == "de2000" else None

    def outputs(self, F):
        if self.objective == "rgb":
            return F - self.target_out
        d = ACEScg_to_Lab(F) - self.target_out
        if self.A is not None:
            d = np.einsum("sij,sj->si", self.A, d)
        return d

    def residuals(self, x):
        F = rgb_conductor_model(self.mu, self.eta, x.reshape(2, 3))
        return (self.outputs(F) * np.sqrt(self.w)[:, None]).ravel()

    def jacobian(self, x):
        """
        The exact Jacobian (3 S, 6) of :meth:`residuals` in the flattened
        (n_R, n_G, n_B, k_R, k_G, k_B): each channel's Fresnel derivatives
        (:func:`fitting.optics.fresnel.fresnel_conductor_derivatives`)
        through Lab and the CIEDE2000 metric.
        """
        C = x.reshape(2, 3)
        F, dn, dk = fresnel_conductor_derivatives(self.mu[:, None], self.eta[:, None], C[0], C[1])
        dF = np.stack([dn, dk], axis=1)  # [s, p, c]
        if self.objective == "rgb":
            G = np.broadcast_to(np.eye(3), (F.shape[0], 3, 3))
        else:
            G = ACEScg_to_Lab_jacobian(F)
            if self.A is not None:
                G = self.A @ G
        J = G[:, :, None, :] * dF[:, None, :, :] * np.sqrt(self.w)[:, None, None, None]  # [s, o, p, c]
        return J.reshape(3 * F.shape[0], 6)

    def score(self, F):
        """
        The objective itself for reflectances ``F`` of shape (..., S, 3):
        the weighted sum of squared residuals (``rgb``, ``lab``), or the
        weighted sum of CIEDE2000 differences (``de2000``, which the
        reweighted least squares approaches).
        """
        if self.objective == "de2000":
            dE = delta_E_2000(np.broadcast_to(ACEScg_to_Lab(self.target), F.shape), ACEScg_to_Lab(F))
            return np.sum(dE * self.w, axis=-1)
        if self.objective == "rgb":
            d = F - self.target_out
        else:
            d = ACEScg_to_Lab(F) - self.target_out
        return np.sum(np.sum(d * d, axis=-1) * self.w, axis=-1)


def nk_bounds() -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of the flattened (n_R, n_G, n_B, k_R, k_G, k_B)."""
    lower = np.array([N_BOUNDS[0]] * 3 + [K_BOUNDS[0]] * 3)
    upper = np.array([N_BOUNDS[1]] * 3 + [K_BOUNDS[1]] * 3)
    return lower, upper


def _lattice(value: float, radius: int, lo: float, hi: float) -> np.ndarray:
    """The float16 values nearest ``value``, ``radius`` on either side, clipped to [lo, hi]."""
    h = np.float16(value)
    below = h if float(h) <= value else np.nextafter(h, np.float16(-np.inf))
    values = [below]
    for _ in range(radius - 1):
        values.insert(0, np.nextafter(values[0], np.float16(-np.inf)))
    above = np.nextafter(below, np.float16(np.inf))
    values.append(above)
    for _ in range(radius - 1):
        values.append(np.nextafter(values[-1], np.float16(np.inf)))
    out = np.array(values, dtype=np.float64)
    out = unique(np.clip(out, lo, hi))
    return out[np.isfinite(out)]


def quantise_rgb_conductor(
    objective: RGBConductorObjective, x: np.ndarray, radius: int = 8, keep: int = 8, passes: int = 8
) -> np.ndarray:
    """
    Float16 n, k that minimise the fit's objective near the float64 optimum.

    The objective is the fit's own (:meth:`RGBConductorObjective.score`: the weighted
    CIEDE2000 sum for ``de2000``, not its quadratic model). n and k of a
    channel are strongly correlated (the error has a long valley), so the
    best lattice point can lie several ulps from the optimum:

    1.  per channel, every pair of the ``radius`` float16 values either side
        of n and of k is scored with the other channels at the optimum,
        and the ``keep`` best pairs are kept;
    2.  every combination of the kept pairs of the three channels
        (``keep``^3) is scored; the best is taken;
    3.  one-ulp moves of single values are taken while they lower the
        objective.

    Plain rounding is among the candidates of step 1 but may be screened
    out; the result is compared with it and the better kept, so it is never
    worse than plain rounding on the fitting grid.
    """
    x = np.asarray(x, dtype=np.float64).reshape(2, 3)
    lower, upper = nk_bounds()
    mu, eta = objective.mu, objective.eta
    F_opt = rgb_conductor_model(mu, eta, x)
    kept = []  # per channel: (keep, 2) pairs of (n, k) and their (keep, S) reflectance
    for c in range(3):
        ns = _lattice(x[0, c], radius, lower[c], upper[c])
        ks = _lattice(x[1, c], radius, lower[3 + c], upper[3 + c])
        pairs = np.array(list(itertools.product(ns, ks)))
        C = np.zeros((2, 3, pairs.shape[0]))
        C[0] = 1.0
        C[:, c, :] = pairs.T
        # One evaluation for all pairs: channel c of each, the others at the optimum.
        F_c = fresnel_conductor(mu[None, :], eta[None, :], pairs[:, :1], pairs[:, 1:])
        F = np.broadcast_to(F_opt, (pairs.shape[0],) + F_opt.shape).copy()
        F[:, :, c] = F_c
        best = np.argsort(objective.score(F), kind="stable")[:keep]
        kept.append((pairs[best], F_c[best]))
    combos = np.array(list(itertools.product(*(range(len(k[0])) for k in kept))))
    F = np.stack([kept[c][1][combos[:, c]] for c in range(3)], axis=-1)
    scores = objective.score(F)
    i = int(np.argmin(scores))
    h = np.array([kept[c][0][combos[i, c]] for c in range(3)]).T.astype(np.float16)
    current = float(scores[i])
    # One-ulp moves from the best (the screening may have left the optimum at an edge).
    for _ in range(passes * 6):
        moves = []
        for p, c in itertools.product(range(2), range(3)):
            for direction in (np.float16(-np.inf), np.float16(np.inf)):
                trial = h.copy()
                trial[p, c] = np.nextafter(h[p, c], direction)
                value = float(trial[p, c])
                if np.isfinite(value) and lower[3 * p + c] <= value <= upper[3 * p + c]:
                    moves.append(trial)
        F = np.stack([rgb_conductor_model(mu, eta, t.astype(np.float64)) for t in moves])
        trial_scores = objective.score(F)
        j = int(np.argmin(trial_scores))
        if not trial_scores[j] < current:
            break
        h, current = moves[j], float(trial_scores[j])
    nearest = to_float16(x)
    nearest_score = float(objective.score(rgb_conductor_model(mu, eta, nearest.astype(np.float64))))
    return h if current <= nearest_score else nearest
