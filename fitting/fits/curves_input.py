"""
Edited reflectance curves
=========================

The input of a curve fit (:mod:`fitting.fits.curves`): RGB reflectance
curves against cos theta at one coating index eta_i each, in linear ACEScg.

-   :class:`RGBCurve`: one validated curve at one eta_i.
-   :func:`check_curves`: curves from plain mappings (a request body), each
    refusal naming the place (``curves[1].rgb[12][0]``).
-   :data:`CURVE_MIN_SAMPLES`, :data:`CURVE_MAX_SAMPLES`,
    :data:`CURVE_MAX_COUNT`: the limits of one request.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..domain import ANGLE_LIMITS_DEG, check_eta_i, cos_theta_from_angle

__all__ = [
    "CURVE_MIN_SAMPLES",
    "CURVE_MAX_SAMPLES",
    "CURVE_MAX_COUNT",
    "RGBCurve",
    "check_curves",
]

CURVE_MIN_SAMPLES = 5
"""Fewest samples per curve: the model has three parameters per channel."""


CURVE_MAX_SAMPLES = 1024
"""Most samples per curve (bounds the work of one request)."""


CURVE_MAX_COUNT = 16
"""Most curves (edited eta_i values) in one fit."""


_CHANNELS = "RGB"


_RGB_TOLERANCE = 1e-6  # the spectral reference of a perfect mirror reads 1 + 2e-10


def _where(curve: str, field_name: str) -> str:
    return f"{curve}.{field_name}" if curve else field_name


@dataclass(frozen=True)
class RGBCurve:
    """
    A reflectance curve at one coating index.

    Attributes
    ----------
    eta_i
        Index of the coating, [1, 3] (:func:`fitting.domain.check_eta_i`).
    cos_theta
        :math:`\\mu = \\cos\\theta` in the coating, [0, 1], strictly
        increasing (sorted on construction), at least
        :data:`CURVE_MIN_SAMPLES` values.
    rgb
        Reflectance, linear ACEScg, [0, 1], shape (N, 3); values within 1e-6
        outside the interval (rounding in the colour conversion) are clipped.
    label
        The curve's place in a request (``curves[2]``), used in messages.

    Raises
    ------
    ValueError
        Naming the field, the rule and the value, e.g. "`curves[0].rgb[3][0]`
        (R at cos_theta 0.5) must lie in [0, 1], got 1.2".
    """

    eta_i: float
    cos_theta: np.ndarray
    rgb: np.ndarray
    label: str = field(default="curve", compare=False)

    def __post_init__(self) -> None:
        label = self.label
        eta_i = check_eta_i(self.eta_i, _where(label, "eta_i"))
        try:
            mu = np.asarray(self.cos_theta, dtype=np.float64)
            rgb = np.asarray(self.rgb, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"`{_where(label, 'cos_theta')}` and `{_where(label, 'rgb')}` must be numbers") from None
        if mu.ndim != 1:
            raise ValueError(f"`{_where(label, 'cos_theta')}` must be a list of numbers")
        if not CURVE_MIN_SAMPLES <= mu.size <= CURVE_MAX_SAMPLES:
            raise ValueError(
                f"`{_where(label, 'cos_theta')}` must hold {CURVE_MIN_SAMPLES} to "
                f"{CURVE_MAX_SAMPLES} samples, got {mu.size}"
            )
        if rgb.shape != (mu.size, 3):
            raise ValueError(
                f"`{_where(label, 'rgb')}` must hold one [R, G, B] per cos_theta sample "
                f"({mu.size} x 3), got shape {rgb.shape}"
            )
        bad = np.flatnonzero(~np.isfinite(mu))
        if bad.size:
            raise ValueError(f"`{_where(label, 'cos_theta')}[{bad[0]}]` must be finite, got {mu[bad[0]]}")
        bad = np.flatnonzero((mu < 0.0) | (mu > 1.0))
        if bad.size:
            i = bad[0]
            raise ValueError(f"`{_where(label, 'cos_theta')}[{i}]` must lie in [0, 1], got {mu[i]:g}")
        outside = (rgb < -_RGB_TOLERANCE) | (rgb > 1.0 + _RGB_TOLERANCE)
        for check, rule in ((~np.isfinite(rgb), "must be finite"), (outside, "must lie in [0, 1]")):
            bad = np.argwhere(check)
            if bad.size:
                i, c = bad[0]
                angle = np.degrees(np.arccos(mu[i]))
                raise ValueError(
                    f"`{_where(label, 'rgb')}[{i}][{c}]` ({_CHANNELS[c]} at cos_theta "
                    f"{mu[i]:.4g}, {angle:.1f} degrees) {rule}, got {rgb[i, c]:g}"
                )
        order = np.argsort(mu, kind="stable")
        mu, rgb = mu[order], np.clip(rgb[order], 0.0, 1.0)
        repeated = np.flatnonzero(np.diff(mu) <= 0.0)
        if repeated.size:
            raise ValueError(f"`{_where(label, 'cos_theta')}` must not repeat a value, got {mu[repeated[0]]:g} twice")
        for array in (mu, rgb):
            array.setflags(write=False)
        object.__setattr__(self, "eta_i", eta_i)
        object.__setattr__(self, "cos_theta", mu)
        object.__setattr__(self, "rgb", rgb)

    @classmethod
    def from_angles(cls, eta_i: float, angle_deg, rgb, label: str = "curve") -> RGBCurve:
        """A curve sampled at angles theta in degrees, [0, 90], in the coating."""
        try:
            angle = np.asarray(angle_deg, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"`{_where(label, 'angle_deg')}` must be numbers") from None
        if angle.ndim != 1:
            raise ValueError(f"`{_where(label, 'angle_deg')}` must be a list of numbers")
        lo, hi = ANGLE_LIMITS_DEG
        bad = np.flatnonzero(~np.isfinite(angle) | (angle < lo) | (angle > hi))
        if bad.size:
            i = bad[0]
            raise ValueError(f"`{_where(label, 'angle_deg')}[{i}]` must lie in [{lo:g}, {hi:g}], got {angle[i]:g}")
        return cls(eta_i, cos_theta_from_angle(angle), rgb, label)

    def sampled(self, cos_theta) -> np.ndarray:
        """The curve interpolated linearly at ``cos_theta`` (held flat past its ends), (..., 3)."""
        mu = np.asarray(cos_theta, dtype=np.float64)
        return np.stack([np.interp(mu, self.cos_theta, self.rgb[:, c]) for c in range(3)], axis=-1)


def check_curves(curves: Sequence[RGBCurve | Mapping[str, Any]]) -> list[RGBCurve]:
    """
    Validate curves given as :class:`RGBCurve` or as mappings with ``eta_i``,
    ``rgb`` and one of ``cos_theta`` or ``angle_deg`` (degrees).

    Raises
    ------
    ValueError
        If there are no curves or more than :data:`CURVE_MAX_COUNT`, if two
        share an eta_i, or if a curve is invalid (the message names it as
        ``curves[i]``).
    """
    if isinstance(curves, (str, bytes, Mapping)) or not isinstance(curves, Sequence):
        raise ValueError("`curves` must be a list of curves")
    if not 1 <= len(curves) <= CURVE_MAX_COUNT:
        raise ValueError(f"`curves` must hold 1 to {CURVE_MAX_COUNT} curves, got {len(curves)}")
    out: list[RGBCurve] = []
    for i, curve in enumerate(curves):
        label = f"curves[{i}]"
        if isinstance(curve, RGBCurve):
            curve = RGBCurve(curve.eta_i, curve.cos_theta, curve.rgb, label)
        elif isinstance(curve, Mapping):
            has_mu, has_angle = curve.get("cos_theta") is not None, curve.get("angle_deg") is not None
            if has_mu == has_angle:
                raise ValueError(f"`{label}` must give exactly one of `cos_theta` or `angle_deg`")
            if "eta_i" not in curve or "rgb" not in curve:
                raise ValueError(f"`{label}` must give `eta_i` and `rgb`")
            if has_mu:
                curve = RGBCurve(curve["eta_i"], curve["cos_theta"], curve["rgb"], label)
            else:
                curve = RGBCurve.from_angles(curve["eta_i"], curve["angle_deg"], curve["rgb"], label)
        else:
            raise ValueError(f"`{label}` must be a curve, got {type(curve).__name__}")
        for j, other in enumerate(out):
            if abs(other.eta_i - curve.eta_i) < 1e-6:
                raise ValueError(f"`{label}.eta_i` must differ from `curves[{j}].eta_i`, both are {curve.eta_i:g}")
        out.append(curve)
    return out
