"""
Model kinds
===========

The one notion of a model kind shared by the pack, the fits, the shaders,
the command line and the service.

-   :data:`MODEL_KINDS`: ``coated-conductor`` (Vernooij 2024, Eq. 1 and 2;
    coefficients (3, 3, d + 1), d in 0-2) and ``rgb-conductor`` (the exact
    Fresnel equations per channel of the relative index (n + i k)/eta_i;
    coefficients (2, 3)).
-   :data:`DEFAULT_MODEL`: ``coated-conductor``.
-   :func:`check_model`: a kind name, or a ``ValueError`` naming the rule.
-   :func:`check_model_coefficients`: coefficients valid for a kind.
-   :func:`model_ACEScg`: a kind's reflectance, linear ACEScg.
-   :func:`coefficient_count`: float16 numbers per material.
"""

from __future__ import annotations

import numpy as np

from .coated_conductor import check_coefficients, coated_conductor_model
from .rgb_conductor import check_rgb_conductor_coefficients, rgb_conductor_model

__all__ = [
    "MODEL_KINDS",
    "DEFAULT_MODEL",
    "check_model",
    "check_model_coefficients",
    "model_ACEScg",
    "coefficient_count",
]

MODEL_KINDS = ("coated-conductor", "rgb-conductor")
DEFAULT_MODEL = "coated-conductor"


def check_model(model) -> str:
    """``model`` if it is one of :data:`MODEL_KINDS`; otherwise ``ValueError``."""
    if model not in MODEL_KINDS:
        raise ValueError(f"`model` must be one of {', '.join(MODEL_KINDS)}, got {model!r}")
    return model


def check_model_coefficients(model: str, coefficients) -> np.ndarray:
    """The coefficients of kind ``model`` as float64, validated (shape, finiteness, signs)."""
    if check_model(model) == "rgb-conductor":
        return check_rgb_conductor_coefficients(coefficients)
    return check_coefficients(coefficients)


def model_ACEScg(model: str, cos_theta, eta_i, coefficients, eta_i_range) -> np.ndarray:
    """
    Reflectance of kind ``model`` at (cos theta, eta_i), linear ACEScg,
    shape ``broadcast(cos_theta, eta_i).shape + (3,)``. ``eta_i_range`` is
    the fitted domain (the coated-conductor model's t; the rgb-conductor
    does not depend on it).
    """
    if check_model(model) == "rgb-conductor":
        return rgb_conductor_model(cos_theta, eta_i, coefficients)
    return coated_conductor_model(cos_theta, eta_i, coefficients, eta_i_range)


def coefficient_count(model: str, degree: int = 2) -> int:
    """Float16 numbers per material of kind ``model`` (and polynomial degree)."""
    return 6 if check_model(model) == "rgb-conductor" else 9 * (degree + 1)
