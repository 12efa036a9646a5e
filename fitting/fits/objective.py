"""
The objective of a fit
======================

-   :class:`Problem`: the residuals and analytic Jacobian of one fit of the
    coated-conductor model (:mod:`fitting.models.coated_conductor`) to RGB
    samples, in linear RGB (``rgb``), CIE Lab (``lab``) or the first-order
    CIEDE2000 metric (``de2000``, :func:`fitting.colour.delta_e.de2000_weights`).
-   :func:`coefficient_bounds`: the box the solver keeps the coefficients in.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
Sharma, G., Wu, W., & Dalal, E. N. (2005). The CIEDE2000 color-difference formula.
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab, ACEScg_to_Lab_deferred
from ..colour.delta_e import de2000_weights
from ..models.coated_conductor import ALPHA_MIN, ModelAt, model_jacobian

__all__ = ["COEFFICIENT_BOUND", "Problem", "coefficient_bounds", "delta_E_gradients"]


# Box bounds of the coefficients: F0, a, alpha. Generous for every measured
# conductor (on the 22 of the library |c| < 1 for F0, < 12 for a, < 9 for
# alpha), they keep parameters the data cannot identify (alpha where a ~ 0)
# from running away, and every coefficient far inside the float16 range.
# alpha's constant term stays at or above the model's clamp.
COEFFICIENT_BOUND = np.array([16.0, 64.0, 256.0])


def delta_E_gradients(r, J):
    """
    The gradient in the coefficients (S, n) of each sample's first-order
    Delta E, the norm of its ``de2000`` residual: from the residuals (S, 3)
    and Jacobian (S, 3, n) of :meth:`Problem.residuals_jacobian`.
    """
    dE = np.sqrt(np.sum(r**2, axis=1))
    return np.einsum("so,son->sn", r, J) / np.maximum(dE, 1e-12)[:, None]


class Problem:
    """Residuals and Jacobian of one fit (flattened samples S, 3 outputs each)."""

    def __init__(self, target_RGB, cos_theta, eta_i, eta_i_range, degree, objective, weights=None, range_check=None):
        # range_check: (mu, eta, weight) of points where the model must stay
        # in [0, 1]: one hinge residual weight * (min(F, 0) + max(F - 1, 0))
        # per point and channel, 0 while the model is inside.
        self.check = (
            None if range_check is None else (np.ravel(range_check[0]), np.ravel(range_check[1]), float(range_check[2]))
        )
        self.mu = np.ravel(cos_theta)
        self.eta = np.ravel(eta_i)
        self.range = eta_i_range
        self.shape = (3, 3, degree + 1)
        self.objective = objective
        self.target = np.asarray(target_RGB, dtype=np.float64).reshape(-1, 3)
        self.sqrt_w = None if weights is None else np.sqrt(np.ravel(weights))[:, None]
        if objective == "rgb":
            self.target_out = self.target
        else:
            self.target_out = ACEScg_to_Lab(self.target)
            self.A = de2000_weights(self.target_out) if objective == "de2000" else None

    def reweighted(self, weights) -> "Problem":
        """
        This problem with the sample ``weights`` (S,) instead: the target's
        Lab, its CIEDE2000 metric and the samples' geometry shared, not
        computed again (the rounds of :func:`fitting.fits.solver.reweighted`).
        """
        self._geometry()
        again = object.__new__(Problem)
        again.__dict__.update(self.__dict__)
        again.__dict__.pop("_last", None)
        again.sqrt_w = None if weights is None else np.sqrt(np.ravel(weights))[:, None]
        return again

    def _model(self) -> ModelAt:
        """The model at the samples (:class:`fitting.models.coated_conductor.ModelAt`), prepared once."""
        if getattr(self, "_at", None) is None:
            self._at = ModelAt(self.mu, self.eta, self.range)
        return self._at

    def _geometry(self):
        """What the samples fix of Eq. 1 and its derivative: mu, the powers of t, 1 - mu, (1 - mu)^5, log(1 - mu)."""
        if getattr(self, "_geo", None) is None:
            at = self._model()  # the same values the model is evaluated with
            x = at.x
            with np.errstate(divide="ignore", invalid="ignore"):
                log_x = np.where(x > 0.0, np.log(np.where(x > 0.0, x, 1.0)), 0.0)
            self._geo = (at.mu, at.powers_of(self.shape[2]), x, at.x5, log_x)
        return self._geo

    def residuals_jacobian(self, x):
        """
        The residuals (S, 3) and the Jacobian (S, 3, n) at ``x`` in one
        pass: :meth:`residuals` and :meth:`jacobian` of the samples (the
        model, Lab and its derivative once, the samples' geometry kept), for
        solvers that ask for both at every point (SLSQP). The range check's
        rows are not included.
        """
        d, jacobian = self.residuals_deferred(x)
        return d, jacobian()

    def residuals_deferred(self, x):
        """
        The residuals (S, 3) of :meth:`residuals_jacobian` at ``x`` and a
        function returning its Jacobian (S, 3, n), the same values: the
        Jacobian's part of the work is done only when asked for (SLSQP's
        line search evaluates points whose Jacobian it never uses).
        """
        if self.objective == "rgb":
            S = self.mu.size
            return self.residuals(x)[: 3 * S].reshape(S, 3), lambda: self.jacobian(x)[: 3 * S].reshape(S, 3, -1)
        mu, T, xx, x5, log_x = self._geometry()
        S, d1 = T.shape[0], self.shape[2]
        C = x.reshape(3, 3, d1)
        P = T[:, 0, None, None] * C[:, :, 0]  # [s, p, c], elementwise (no BLAS: the same on every CPU)
        for j in range(1, d1):
            P = P + T[:, j, None, None] * C[:, :, j]
        alpha_raw = P[:, 2, :]
        F0, a = P[:, 0, :], P[:, 1, :]
        mu_x_alpha = mu * xx ** np.maximum(alpha_raw, ALPHA_MIN)
        F = F0 + (1.0 - F0) * x5 - a * mu_x_alpha
        Lab, lab_jacobian = ACEScg_to_Lab_deferred(F)
        d = Lab - self.target_out
        if self.A is not None:
            d = np.einsum("sij,sj->si", self.A, d)
        if self.sqrt_w is not None:
            d = d * self.sqrt_w

        def jacobian():
            dP = np.empty((S, 3, 3))  # [s, p, c]
            dP[:, 0, :] = 1.0 - x5
            dP[:, 1, :] = -mu_x_alpha
            dP[:, 2, :] = np.where(alpha_raw > ALPHA_MIN, -a * mu_x_alpha * log_x, 0.0)
            G = lab_jacobian()
            if self.A is not None:
                G = self.A @ G
            if self.sqrt_w is not None:
                G = G * self.sqrt_w[:, :, None]
            # J[s, o, p, c, j] = G[s, o, c] * dP[s, p, c] * T[s, j], as jacobian()
            J = (G[:, :, None, :] * dP[:, None, :, :])[..., None] * T[:, None, None, None, :]
            return J.reshape(d.shape[0], 3, -1)

        return d, jacobian

    def _outputs(self, F):
        """The residuals of the model values ``F`` (S, 3), unweighted (the Jacobian: :meth:`residuals_jacobian`)."""
        if self.objective == "rgb":
            return F - self.target_out
        d = ACEScg_to_Lab(F) - self.target_out
        return d if self.A is None else np.einsum("sij,sj->si", self.A, d)

    def _range_residuals(self, x):
        mu, eta, weight = self.check
        if getattr(self, "_check_at", None) is None:
            self._check_at = ModelAt(mu, eta, self.range)
        F = self._check_at(x.reshape(self.shape))
        return weight * (np.minimum(F, 0.0) + np.maximum(F - 1.0, 0.0))

    def residuals(self, x):
        if self.objective == "rgb":
            r = self._outputs(self._model()(x.reshape(self.shape)))
            if self.sqrt_w is not None:
                r = r * self.sqrt_w
        else:
            # Lab and de2000: the one pass, its Jacobian kept for this x
            # (trf asks for the Jacobian at the point it has just evaluated).
            r, jacobian = self.residuals_deferred(x)
            self._last = (np.array(x, dtype=np.float64), jacobian)
        if self.check is not None:
            return np.concatenate([r.ravel(), self._range_residuals(x).ravel()])
        return r.ravel()

    def _range_jacobian(self, x):
        mu, eta, weight = self.check
        F, Jm = model_jacobian(mu, eta, x.reshape(self.shape), self.range)
        active = ((F < 0.0) | (F > 1.0)).astype(np.float64)  # (K, 3)
        K, d1 = Jm.shape[0], self.shape[2]
        J = np.zeros((K, 3, 3, 3, d1))
        idx = np.arange(3)
        J[:, idx, :, idx, :] = weight * active.T[:, :, None, None] * Jm.transpose(1, 0, 2, 3)
        return J.reshape(K * 3, -1)

    def jacobian(self, x):
        if self.objective != "rgb":  # Lab and de2000: the one pass, kept from residuals() at this x
            last = getattr(self, "_last", None)
            if last is not None and np.array_equal(last[0], x):
                J = last[1]()
            else:
                _, J = self.residuals_jacobian(x)
            J = J.reshape(J.shape[0] * 3, -1)
            return J if self.check is None else np.concatenate([J, self._range_jacobian(x)])
        # rgb: each output is its channel's model value, J[s, c, p, c, j] = Jm[s, c, p, j].
        _, Jm = model_jacobian(self.mu, self.eta, x.reshape(self.shape), self.range)
        S, d1 = Jm.shape[0], self.shape[2]
        J = np.zeros((S, 3, 3, 3, d1))
        idx = np.arange(3)
        J[:, idx, :, idx, :] = Jm.transpose(1, 0, 2, 3)
        if self.sqrt_w is not None:
            J = J * self.sqrt_w[:, :, None, None, None]
        if self.check is not None:
            return np.concatenate([J.reshape(S * 3, -1), self._range_jacobian(x)])
        return J.reshape(S * 3, -1)


def coefficient_bounds(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Box bounds (lower, upper) of the flattened coefficients, see ``COEFFICIENT_BOUND``."""
    upper = np.broadcast_to(COEFFICIENT_BOUND[:, None, None], (3, 3, degree + 1)).copy()
    lower = -upper
    lower[2, :, 0] = ALPHA_MIN
    return lower.ravel(), upper.ravel()
