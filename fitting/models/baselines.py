"""
Baselines
=========

The approximations the coated-conductor model is compared against, all in
linear ACEScg and per RGB channel.

-   :func:`schlick`: Schlick (1994),
    :math:`F = F_0 + (1 - F_0)(1 - \\mu)^5`.
-   :func:`external_medium_F0`: Hoffman (2020) adjustment of F0 to a coating.
-   :func:`lazanyi_adjusted`: Hoffman's F82 form of Lazanyi's error term with
    the external-medium adjustment ("adjusted Lazanyi", Vernooij 2024).
-   :func:`baseline_inputs`: the metal's F0 and F82 in air from its n, k.
-   :func:`baseline_ACEScg`: a baseline on a grid, by name;
    :func:`baselines_ACEScg`: all of them at once.

References
----------
Schlick, C. (1994). An inexpensive BRDF model for physically-based
rendering. Computer Graphics Forum, 13(3), 233-246.
Lazanyi, I., & Szirmay-Kalos, L. (2005). Fresnel term approximations for metals. WSCG.
Hoffman, N. (2019). Fresnel Equations Considered Harmful. MAM workshop.
Hoffman, N. (2020). Some thoughts on the Fresnel term. SIGGRAPH PBS course.
"""

from __future__ import annotations

import numpy as np

from ..domain import DEFAULT_MIN_COVERAGE, as_float_array
from ..colour.reference import reference_ACEScg, reference_ACEScg_grid
from ..optics.nk import SpectralNK

__all__ = [
    "BASELINES",
    "MU_BAR",
    "schlick",
    "external_medium_F0",
    "lazanyi_a",
    "equivalent_index",
    "lazanyi_adjusted",
    "baseline_inputs",
    "baseline_ACEScg",
    "baselines_ACEScg",
]

MU_BAR = 1.0 / 7.0
"""cos(theta) of Hoffman's F82 sample (theta ~ 81.8 degrees)."""

BASELINES = ("schlick_air", "schlick_exact_F0", "lazanyi_adjusted", "lazanyi_exact_F0")

# sqrt(F0) -> 1 would send the equivalent real index to infinity.
_F0_MAX = 1.0 - 1.0e-6


def schlick(cos_theta, F0) -> np.ndarray:
    """
    Schlick (1994): :math:`F_0 + (1 - F_0)(1 - \\mu)^5`; ``F0`` broadcast
    against ``cos_theta[..., None]`` for RGB.

    Never raises on numeric input, never NaN for finite input: cos theta is
    clamped to [0, 1] (below the surface is grazing) and F0 to [0, 1] (it is
    a reflectance), so the result lies in [0, 1]. NaN in gives NaN.
    """
    mu = np.clip(as_float_array("cos_theta", cos_theta), 0.0, 1.0)[..., None]
    F0 = np.clip(as_float_array("F0", F0), 0.0, 1.0)
    return F0 + (1.0 - F0) * (1.0 - mu) ** 5


def equivalent_index(F0_air) -> np.ndarray:
    """
    Hoffman (2020): the real index :math:`n = (1 + \\sqrt{F_0})/(1 - \\sqrt{F_0})`
    whose normal reflectance in air is ``F0_air`` (F0 clipped to
    [0, 1 - 1e-6] so n stays finite): a per-material constant a renderer
    computes once for :func:`external_medium_F0` at any eta_i.
    """
    s = np.sqrt(np.clip(np.asarray(F0_air, dtype=np.float64), 0.0, _F0_MAX))
    return (1.0 + s) / (1.0 - s)


def external_medium_F0(F0_air, eta_i) -> np.ndarray:
    """
    Hoffman (2020): the F0 of a metal in air mapped to a coating of index
    eta_i through the equivalent real index
    :math:`n = (1 + \\sqrt{F_0})/(1 - \\sqrt{F_0})`, giving
    :math:`((n - \\eta_i)/(n + \\eta_i))^2`.
    """
    n = equivalent_index(F0_air)
    eta_i = np.asarray(eta_i, dtype=np.float64)[..., None]
    return ((n - eta_i) / (n + eta_i)) ** 2


def lazanyi_a(F0, F82) -> np.ndarray:
    """
    Hoffman (2019): coefficient of the error term so that the curve passes
    through F82 at :math:`\\bar\\mu = 1/7`:
    :math:`a = [F_0 + (1 - F_0)(1 - \\bar\\mu)^5 - F_{82}] / (\\bar\\mu(1 - \\bar\\mu)^6)`.
    """
    F0 = np.asarray(F0, dtype=np.float64)
    schlick_bar = F0 + (1.0 - F0) * (1.0 - MU_BAR) ** 5
    return (schlick_bar - np.asarray(F82, dtype=np.float64)) / (MU_BAR * (1.0 - MU_BAR) ** 6)


def lazanyi_adjusted(cos_theta, eta_i, F0_air, F82_air, exact_F0=None) -> np.ndarray:
    """
    Adjusted Lazanyi (Vernooij 2024, after Hoffman 2019, 2020):

    .. math::

        F = F_0' + (1 - F_0')(1 - \\mu)^5 - a\\,\\mu(1 - \\mu)^6

    with :math:`F_0'` the external-medium F0 (:func:`external_medium_F0`),
    or ``exact_F0`` (the exact F0 at each eta_i, shape eta_i.shape + (3,))
    when given, and *a* from the metal's F0 and F82 in air
    (:func:`lazanyi_a`).

    Returns
    -------
    numpy.ndarray
        ``broadcast(cos_theta, eta_i).shape + (3,)``, linear ACEScg.
    """
    mu, eta_i = np.broadcast_arrays(np.asarray(cos_theta, dtype=np.float64), np.asarray(eta_i, dtype=np.float64))
    F0 = external_medium_F0(F0_air, eta_i) if exact_F0 is None else np.asarray(exact_F0)
    a = lazanyi_a(F0_air, F82_air)
    m = np.clip(mu, 0.0, 1.0)[..., None]
    return F0 + (1.0 - F0) * (1.0 - m) ** 5 - a * m * (1.0 - m) ** 6


def baseline_inputs(nk: SpectralNK, step_nm: float = 1.0, min_coverage: float = DEFAULT_MIN_COVERAGE) -> dict:
    """
    F0 (mu = 1) and F82 (mu = 1/7) of the metal in air from the spectral
    reference, linear ACEScg, shape (3,) each.
    """
    values = reference_ACEScg(nk, np.array([1.0, MU_BAR]), 1.0, step_nm, min_coverage)
    return {"F0_air": values[0], "F82_air": values[1]}


def _exact_F0(nk: SpectralNK, eta: np.ndarray, step_nm: float, min_coverage: float) -> np.ndarray:
    """The exact F0 (mu = 1) at each eta_i of ``eta``, shape eta.shape + (3,)."""
    # F0 depends on eta_i alone: evaluated once per distinct eta_i.
    unique, inverse = np.unique(eta, return_inverse=True)
    F0 = reference_ACEScg_grid(nk, [1.0], unique, step_nm, min_coverage)[:, 0]
    return F0[inverse.reshape(eta.shape)]


def _baseline(name: str, mu: np.ndarray, eta: np.ndarray, inputs: dict, exact_F0) -> np.ndarray:
    if name.startswith("schlick"):
        F0 = inputs["F0_air"] if exact_F0 is None else exact_F0
        return np.broadcast_to(schlick(mu, F0), mu.shape + (3,)).copy()
    return lazanyi_adjusted(mu, eta, inputs["F0_air"], inputs["F82_air"], exact_F0)


def baseline_ACEScg(
    name: str,
    nk: SpectralNK,
    cos_theta,
    eta_i,
    step_nm: float = 1.0,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> np.ndarray:
    """
    A baseline by name on (cos_theta, eta_i), linear ACEScg, shape
    ``broadcast(cos_theta, eta_i).shape + (3,)``:

    -   ``schlick_air``: Schlick with the metal's F0 in air.
    -   ``schlick_exact_F0``: Schlick with the exact F0 at each eta_i.
    -   ``lazanyi_adjusted``: adjusted Lazanyi.
    -   ``lazanyi_exact_F0``: adjusted Lazanyi with the exact F0 at each eta_i.
    """
    if name not in BASELINES:
        raise ValueError(f"`name` must be one of {', '.join(BASELINES)}, got {name!r}")
    mu, eta = np.broadcast_arrays(np.asarray(cos_theta, dtype=np.float64), np.asarray(eta_i, dtype=np.float64))
    inputs = baseline_inputs(nk, step_nm, min_coverage)
    exact_F0 = _exact_F0(nk, eta, step_nm, min_coverage) if name.endswith("exact_F0") else None
    return _baseline(name, mu, eta, inputs, exact_F0)


def baselines_ACEScg(
    nk: SpectralNK,
    cos_theta,
    eta_i,
    step_nm: float = 1.0,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> dict[str, np.ndarray]:
    """
    Every baseline of :data:`BASELINES` on (cos_theta, eta_i), keyed by name:
    :func:`baseline_ACEScg` of each, with the metal's F0 and F82 in air and
    the exact F0 per eta_i computed once for all four.
    """
    mu, eta = np.broadcast_arrays(np.asarray(cos_theta, dtype=np.float64), np.asarray(eta_i, dtype=np.float64))
    inputs = baseline_inputs(nk, step_nm, min_coverage)
    exact_F0 = _exact_F0(nk, eta, step_nm, min_coverage)
    return {
        name: _baseline(name, mu, eta, inputs, exact_F0 if name.endswith("exact_F0") else None) for name in BASELINES
    }
