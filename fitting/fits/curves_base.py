"""
Bases of curve fits
===================

The material an edit starts from, and how edits blend into it
(:mod:`fitting.fits.curves`).

-   :class:`CurveBase`: the reflectance of a base material on a fine
    (cos theta, eta_i) grid, computed once per material and interpolated.
-   :func:`curve_base_from_nk`, :func:`curve_base_from_coefficients`: bases
    from measured *n*, *k* or from a fitted model, cached.
-   :func:`blend_weights`: how an edit at some eta_i spreads across eta_i.
-   :func:`edited_target`: the base with the edits blended in.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..colour.reference import reference_ACEScg_grid
from ..domain import DEFAULT_ETA_I_RANGE, BoundedCache, check_eta_i_range, check_number
from ..models.kinds import DEFAULT_MODEL, check_model_coefficients, model_ACEScg
from ..optics.nk import SpectralNK
from .curves_input import RGBCurve

__all__ = [
    "CurveBase",
    "curve_base_from_nk",
    "curve_base_from_coefficients",
    "blend_weights",
    "edited_target",
]

_BASE_MU_SAMPLES = 257  # linear interpolation error ~ h^2/8 * 20 < 5e-5 near grazing


_BASE_ETA_STEP = 0.05  # reflectance is smooth in eta_i: 0.05 keeps the error < 1e-5


_BASE_STEP_NM = 5.0  # the spectral step of the material fits (fitting.fits.settings.FitSettings)


_BASE_CACHE_SIZE = 32


@dataclass(frozen=True)
class CurveBase:
    """
    The reflectance of a base material on a fine grid, in linear ACEScg.

    Attributes
    ----------
    name, source
        The material and where its data come from.
    eta_i_range
        The domain [lo, hi] of eta_i covered by the grid.
    cos_theta
        (M,) evenly over [0, 1].
    eta_i
        (E,) evenly over ``eta_i_range`` (one value when lo = hi).
    RGB
        (E, M, 3) reflectance, linear ACEScg.
    kind
        ``"nk"`` (exact spectral reference) or ``"model"`` (a fitted model).
    """

    name: str
    source: str
    eta_i_range: tuple[float, float]
    cos_theta: np.ndarray
    eta_i: np.ndarray
    RGB: np.ndarray
    kind: str

    def rgb(self, cos_theta, eta_i) -> np.ndarray:
        """
        Reflectance at (cos theta, eta_i) broadcast together, (..., 3), by
        bilinear interpolation of the grid; eta_i is clamped to the domain.
        """
        mu, eta = np.broadcast_arrays(
            np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0),
            np.asarray(eta_i, dtype=np.float64),
        )
        M, E = self.cos_theta.size, self.eta_i.size
        u = mu * (M - 1)
        i0 = np.minimum(np.floor(u).astype(np.intp), M - 2)
        fu = (u - i0)[..., None]
        if E == 1:
            row = self.RGB[0]
            return row[i0] * (1.0 - fu) + row[i0 + 1] * fu
        lo, hi = self.eta_i_range
        v = np.clip((eta - lo) / (hi - lo), 0.0, 1.0) * (E - 1)
        j0 = np.minimum(np.floor(v).astype(np.intp), E - 2)
        fv = (v - j0)[..., None]
        G = self.RGB
        top = G[j0, i0] * (1.0 - fu) + G[j0, i0 + 1] * fu
        bottom = G[j0 + 1, i0] * (1.0 - fu) + G[j0 + 1, i0 + 1] * fu
        return top * (1.0 - fv) + bottom * fv


_BASES = BoundedCache(_BASE_CACHE_SIZE)


def _base_grid(eta_i_range: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = eta_i_range
    mu = np.linspace(0.0, 1.0, _BASE_MU_SAMPLES)
    rows = 1 if hi <= lo else max(2, int(np.ceil((hi - lo) / _BASE_ETA_STEP)) + 1)
    eta = np.linspace(lo, hi, rows)
    for array in (mu, eta):
        array.setflags(write=False)
    return mu, eta


def curve_base_from_nk(nk: SpectralNK, eta_i_range=DEFAULT_ETA_I_RANGE) -> CurveBase:
    """
    The exact spectral reference of ``nk`` (5 nm, as the material fits) on the
    base grid over ``eta_i_range``; computed once per material and domain.

    Raises
    ------
    ValueError
        For an invalid domain or data covering too little of the visible range.
    """
    eta_i_range = check_eta_i_range(eta_i_range)

    def build() -> CurveBase:
        mu, eta = _base_grid(eta_i_range)
        # The product-grid form: reference_ACEScg's numbers (to rounding), faster.
        RGB = reference_ACEScg_grid(nk, mu, eta, _BASE_STEP_NM)
        RGB.setflags(write=False)
        return CurveBase(nk.name, nk.source, eta_i_range, mu, eta, RGB, "nk")

    return _BASES.get(("nk", nk.content_key(), eta_i_range), build)


def curve_base_from_coefficients(
    coefficients,
    eta_i_range=DEFAULT_ETA_I_RANGE,
    name: str = "fit",
    source: str = "",
    model: str = DEFAULT_MODEL,
) -> CurveBase:
    """
    The model of fitted ``coefficients`` of kind ``model`` ((3, 3, d + 1)
    for the coated-conductor, (2, 3) n, k for the rgb-conductor) over its
    domain ``eta_i_range`` on the base grid (for a stored fit without *n*, *k*).

    Raises
    ------
    ValueError
        For invalid coefficients or domain.
    """
    C = check_model_coefficients(model, coefficients)
    eta_i_range = check_eta_i_range(eta_i_range)

    def build() -> CurveBase:
        mu, eta = _base_grid(eta_i_range)
        RGB = model_ACEScg(model, mu[None, :], eta[:, None], C, eta_i_range)
        RGB.setflags(write=False)
        return CurveBase(name, source, eta_i_range, mu, eta, RGB, "model")

    key = ("model", model, np.ascontiguousarray(C, dtype="<f8").tobytes(), C.shape, eta_i_range, name, source)
    return _BASES.get(key, build)


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def blend_weights(eta_i, edit_eta_i, width: float) -> np.ndarray:
    """
    Weight of each edit at each eta_i, (..., K) for K edits.

    Between two neighbouring edited indices :math:`e_a < e_b` the weights are
    :math:`1 - s` and :math:`s` with :math:`s` the smoothstep of
    :math:`(\\eta_i - e_a)/(e_b - e_a)`; below the lowest and above the
    highest edit the weight of that edit falls smoothly to 0 over ``width``.
    Each edit has weight 1 at its own eta_i (the edited curve replaces the
    base there) and the weights are continuous with continuous derivative.
    """
    width = check_number("blend_width", float(width), 0.0)
    eta = np.asarray(eta_i, dtype=np.float64)
    edits = np.asarray(edit_eta_i, dtype=np.float64)
    order = np.argsort(edits)
    e = edits[order]
    W = np.zeros(eta.shape + (e.size,))
    below, above = eta <= e[0], eta >= e[-1]
    W[..., 0] = np.where(below, _smoothstep(1.0 - (e[0] - eta) / width), 0.0)
    W[..., -1] = np.where(above, _smoothstep(1.0 - (eta - e[-1]) / width), W[..., -1])
    for k in range(e.size - 1):
        inside = (eta >= e[k]) & (eta < e[k + 1])
        s = _smoothstep((eta - e[k]) / (e[k + 1] - e[k]))
        W[..., k] = np.where(inside, 1.0 - s, W[..., k])
        W[..., k + 1] = np.where(inside, s, W[..., k + 1])
    out = np.empty_like(W)
    out[..., order] = W
    return out


def edited_target(
    base: CurveBase, curves: Sequence[RGBCurve], cos_theta, eta_i, blend_width: float = 1.0
) -> np.ndarray:
    """
    The base with the edits blended in, at (cos theta, eta_i), (..., 3),
    linear ACEScg clipped to [0, 1]:

    .. math::

        T(\\mu, \\eta_i) = B(\\mu, \\eta_i) + \\sum_k w_k(\\eta_i)
        \\,[C_k(\\mu) - B(\\mu, e_k)]

    with :math:`B` the base, :math:`C_k` the k-th curve (piecewise linear
    through its samples, held flat past its ends), :math:`e_k` its eta_i and
    :math:`w_k` from :func:`blend_weights`. At :math:`\\eta_i = e_k`,
    :math:`T` is the curve itself.
    """
    mu, eta = np.broadcast_arrays(np.asarray(cos_theta, dtype=np.float64), np.asarray(eta_i, dtype=np.float64))
    T = base.rgb(mu, eta)
    W = blend_weights(eta, [c.eta_i for c in curves], blend_width)
    for k, curve in enumerate(curves):
        delta = curve.sampled(mu) - base.rgb(mu, curve.eta_i)
        T = T + W[..., k, None] * delta
    return np.clip(T, 0.0, 1.0)
