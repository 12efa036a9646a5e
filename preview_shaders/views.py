"""
What a preview may show
=======================

The values :class:`preview_shaders.preview.PreviewRenderer` accepts and
their checks (a ``ValueError`` naming the argument and the rule), and the
preview sphere's geometry, in numpy alone (no GL): the module a caller
imports to check a request before it reaches a renderer.

-   :data:`COMPARISONS`, :data:`MODES`, :data:`ENVIRONMENTS`,
    :data:`SIZE_RANGE`, :data:`ETA_I_LIMITS`, :data:`SPHERE_RADIUS`.
-   :func:`check_size`, :func:`check_unit`, :func:`check_choice`: the checks.
-   :func:`sphere_cos_theta`: cos theta per pixel from the geometry (the
    geometry: :mod:`preview_shaders.preview`'s description).
"""

from __future__ import annotations

import numpy as np

from fitting.domain import ETA_I_MAX, ETA_I_MIN

__all__ = [
    "COMPARISONS",
    "MODES",
    "ENVIRONMENTS",
    "SIZE_RANGE",
    "ETA_I_LIMITS",
    "SPHERE_RADIUS",
    "check_choice",
    "check_size",
    "check_unit",
    "sphere_cos_theta",
]

COMPARISONS = ("none", "lazanyi", "reference")
MODES = ("immersed", "coated")
ENVIRONMENTS = ("white_sky", "studio", "outdoor")
"""The preview environments, by their index in ``cf_environment.glsl``
(CF_ENVIRONMENT_*); the rough preview prefilters each of them."""
SIZE_RANGE = (64, 2048)
ETA_I_LIMITS = (ETA_I_MIN, ETA_I_MAX)
SPHERE_RADIUS = 0.45
"""Sphere radius as a fraction of the image size."""


def check_size(size) -> int:
    """``size`` as an int, or a ValueError naming it and the range :data:`SIZE_RANGE`."""
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)):
        raise ValueError(f"`size` must be an integer in [64, 2048], got {size!r}")
    if not SIZE_RANGE[0] <= size <= SIZE_RANGE[1]:
        raise ValueError(f"`size` must lie in [64, 2048], got {size}")
    return int(size)


def check_unit(name: str, value) -> float:
    """``value`` as a float in [0, 1], or a ValueError naming ``name`` and the rule."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"`{name}` must be a number in [0, 1], got {value!r}")
    value = float(value)
    if not (np.isfinite(value) and 0.0 <= value <= 1.0):
        raise ValueError(f"`{name}` must lie in [0, 1], got {value}")
    return value


def check_choice(name: str, value, choices) -> str:
    """``value`` if it is one of ``choices``, or a ValueError naming ``name`` and the choices."""
    if value not in choices:
        raise ValueError(f"`{name}` must be one of {', '.join(choices)}, got {value!r}")
    return value


def sphere_cos_theta(size: int) -> tuple[np.ndarray, np.ndarray]:
    """
    cos theta per pixel (top row first) and the sphere mask, from the
    geometry in float64 (the module docstring gives the geometry).
    """
    size = check_size(size)
    centre = 0.5 * size
    radius = SPHERE_RADIUS * size
    x = (np.arange(size) + 0.5 - centre) / radius
    y = (size - np.arange(size) - 0.5 - centre) / radius
    r2 = x[None, :] ** 2 + y[:, None] ** 2
    mask = r2 < 1.0
    return np.where(mask, np.sqrt(np.clip(1.0 - r2, 0.0, 1.0)), 0.0), mask
