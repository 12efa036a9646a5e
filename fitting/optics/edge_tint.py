"""
Metals given by F0 and F82 tint
===============================

Artists, OpenPBR (``base_color``, ``specular_color``), Blender's Principled
BSDF (``Base Color``, ``Specular Tint``) and the Physically Based database
describe a metal by two colours in air: its reflectance at normal incidence
:math:`F_0` and the F82 tint :math:`t` of Hoffman's model, the ratio of its
reflectance at :math:`\\bar\\mu = \\cos 82^\\circ \\approx 1/7` to Schlick's
:math:`S(\\bar\\mu) = F_0 + (1 - F_0)(1 - \\bar\\mu)^5`. Per channel, this
module turns them into the complex index :math:`n + i k` of an exact
conductor in air whose Fresnel reflectance :math:`F(\\mu; n, k)` passes
through both anchors,

.. math::

    F(1; n, k) = F_0, \\qquad F(\\bar\\mu; n, k) = t\\, S(\\bar\\mu),

and, from that index, gives the :math:`F_0` and F82 tint an F82-tint
renderer must use for the metal under a clear coat of index
:math:`\\eta_i` (OpenPBR issue #225).

**The remap under a coat.** Renderers layer a coat over a base evaluated at
the view angle in air: :math:`L(\\mu) = R_c(\\mu) + (1 - R_c(\\mu))\\, B(\\mu)`
with :math:`R_c` the coat's dielectric Fresnel (Cycles' Principled coat,
MaterialX's ``layer`` of a ``dielectric_bsdf``). What is seen is the
physical stack :math:`S(\\mu)` (:func:`fitting.optics.coated_stack.coated_stack`:
the metal at the refracted angle, both polarisations, the bounces between
the interfaces), of the index found above. The remap makes :math:`L` equal
:math:`S` at normal incidence and at :math:`\\mu_a = \\cos 75^\\circ`
(:data:`UNDER_COAT_ANCHOR_COS`), in closed form given :math:`n, k`: with
:math:`B(\\mu) = (S(\\mu) - R_c(\\mu)) / (1 - R_c(\\mu))` the base that
makes them equal,

.. math::

    F_0' = B(1), \\qquad
    t' = 1 - \\frac{S_{F_0'}(\\mu_a) - B(\\mu_a)}{w(\\mu_a)\\, S_{F_0'}(\\bar\\mu)},
    \\quad w(\\mu) = \\frac{\\mu (1 - \\mu)^6}{\\bar\\mu (1 - \\bar\\mu)^6},

(the F82-tint curve is affine in :math:`t`), each clipped to [0, 1]. The
anchor 75 degrees was chosen by a coarse scan (50 to 82 degrees) of the
mean error over the library's 22 conductors at coat indices 1.33, 1.5 and
2.0 (82 degrees itself, the model's own anchor, is twice as far off: the
renderer's base falls towards grazing where the physical metal, seen at the
refracted angle, does not). Simply
taking the relative index :math:`(n + i k)/\\eta_i`'s own F0 and F82 tint
(:func:`F0_F82_from_nk` at :math:`\\eta_i`) ignores that the renderer
evaluates the base at the angle in air, not the refracted one, and is
measured beside it.

**The inversion.** Gulbrandsen (2014) parameterises :math:`k` by :math:`n` so
that the first anchor holds exactly,
:math:`k(n)^2 = \\frac{F_0 (n + 1)^2 - (n - 1)^2}{1 - F_0}`, on
:math:`n \\in [n_-, n_+] = [\\frac{1 - \\sqrt{F_0}}{1 + \\sqrt{F_0}},
\\frac{1 + \\sqrt{F_0}}{1 - \\sqrt{F_0}}]` (:math:`k = 0` at both ends), and
gives :math:`n` from an edge tint in closed form. Here :math:`n` is instead
the root of the second anchor, :math:`g(n) = F(\\bar\\mu; n, k(n)) - t\\,S(\\bar\\mu)`,
found by bracketing on 256 points of :math:`[n_-, n_+]` (geometric) and
Brent's method to :math:`10^{-12}`: both anchors then hold to rounding.
Where the tint is out of reach of any conductor (no root), the :math:`n`
nearest it is taken and the shortfall reported
(:attr:`EdgeTintIndex.F82_error`). Where several roots exist, the one whose
exact Fresnel is nearest the F82-tint curve over :math:`\\mu \\in [0, 1]`
(least squares, 101 samples) is taken. Between the anchors the exact
Fresnel and the F82-tint curve differ by the F82 model's own error; the
benchmark ``benchmarks/edge_tint.py`` records it over the library's
conductors (docs/edge_tint.md).

-   :func:`gulbrandsen_nk`: Gulbrandsen's closed form (reflectivity and edge tint).
-   :func:`nk_from_F0_F82`: the inversion above, per channel.
-   :func:`F0_F82_from_nk`: the forward map, :math:`F_0` and the F82 tint of
    an exact conductor of relative index :math:`(n + i k)/\\eta_i`.
-   :func:`F0_F82_under_coat`: the remap for an F82-tint renderer under a
    coat of index :math:`\\eta_i` (the two-anchor match above).

References
----------
Gulbrandsen, O. (2014). Artist Friendly Metallic Fresnel. Journal of
Computer Graphics Techniques 3(4).
Hoffman, N. (2023). Generalization of Adobe's Fresnel Model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..domain import check_eta_i
from .coated_stack import coated_stack
from .fresnel import fresnel_conductor, fresnel_dielectric

__all__ = [
    "F82_COS_THETA",
    "UNDER_COAT_ANCHOR_COS",
    "EdgeTintIndex",
    "gulbrandsen_nk",
    "nk_from_F0_F82",
    "F0_F82_from_nk",
    "F0_F82_under_coat",
]

F82_COS_THETA = 1.0 / 7.0
"""cos 82 degrees as Hoffman's model takes it."""
UNDER_COAT_ANCHOR_COS = float(np.cos(np.radians(75.0)))
"""The second anchor of :func:`F0_F82_under_coat` (see the module docstring)."""
_F0_MAX = 0.9999  # a perfect mirror (F0 1) has no finite index: the largest F0 taken
_GRID = 256


def _schlick82(F0):
    return F0 + (1.0 - F0) * (1.0 - F82_COS_THETA) ** 5


def _f82_curve(mu, F0, tint):
    m = F82_COS_THETA
    a = _schlick82(F0) * (1.0 - tint) / (m * (1.0 - m) ** 6)
    return F0 + (1.0 - F0) * (1.0 - mu) ** 5 - a * mu * (1.0 - mu) ** 6


def _channels(name: str, values) -> np.ndarray:
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 1 or array.size == 0:
        raise ValueError(f"`{name}` must be a list of numbers (one per channel), got shape {array.shape}")
    if not np.all(np.isfinite(array)) or np.any(array < 0.0) or np.any(array > 1.0):
        raise ValueError(f"`{name}` must lie in [0, 1] in every channel, got {array.tolist()}")
    return array


def gulbrandsen_nk(r, g) -> tuple[np.ndarray, np.ndarray]:
    """
    Gulbrandsen's (2014) closed form: reflectivity ``r`` (F0) and edge tint
    ``g``, each in [0, 1] per channel, to n and k (his Eq. for n(r, g) and
    k(r, n)). His edge tint is not the F82 tint; kept as the published
    reference and the start of comparisons.
    """
    r = np.clip(_channels("r", r), 0.0, _F0_MAX)
    g = _channels("g", g)
    sr = np.sqrt(r)
    n = g * (1.0 - r) / (1.0 + r) + (1.0 - g) * (1.0 + sr) / (1.0 - sr)
    k = np.sqrt(np.maximum(r * (n + 1.0) ** 2 - (n - 1.0) ** 2, 0.0) / (1.0 - r))
    return n, k


@dataclass(frozen=True)
class EdgeTintIndex:
    """
    Per-channel index of a metal given by F0 and F82 tint (:func:`nk_from_F0_F82`).

    Attributes
    ----------
    n, k
        Real and imaginary index per channel, in air.
    F82_error
        Per channel, the reachable F82 tint minus the one asked for (0 to
        rounding where a conductor reaches it).
    reachable
        Per channel, whether the F82 tint was reached (``|F82_error| < 1e-9``).
    """

    n: np.ndarray
    k: np.ndarray
    F82_error: np.ndarray
    reachable: np.ndarray


def _k_of(n, F0):
    return np.sqrt(np.maximum(F0 * (n + 1.0) ** 2 - (n - 1.0) ** 2, 0.0) / (1.0 - F0))


def _channel(F0: float, tint: float) -> tuple[float, float, float]:
    F0 = min(max(F0, 1e-6), _F0_MAX)  # F0 0: no conductor; the faintest one taken
    target = tint * _schlick82(F0)
    s = np.sqrt(F0)
    lo, hi = (1.0 - s) / (1.0 + s), (1.0 + s) / (1.0 - s)
    n_grid = np.geomspace(lo, hi, _GRID)

    def g(n):
        return float(fresnel_conductor(F82_COS_THETA, 1.0, n, _k_of(n, F0))) - target

    values = np.array([g(n) for n in n_grid])
    roots = [
        brentq(g, n_grid[i], n_grid[i + 1], xtol=1e-12, rtol=1e-14)
        for i in np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) <= 0.0)
    ]
    if not roots:
        best = float(n_grid[np.argmin(np.abs(values))])
        return best, float(_k_of(best, F0)), g(best) / _schlick82(F0)
    mu = np.linspace(0.0, 1.0, 101)
    curve = _f82_curve(mu, F0, tint)
    n = min(roots, key=lambda r: float(np.sum((fresnel_conductor(mu, 1.0, r, _k_of(r, F0)) - curve) ** 2)))
    return float(n), float(_k_of(n, F0)), g(n) / _schlick82(F0)


def nk_from_F0_F82(F0, F82_tint) -> EdgeTintIndex:
    """
    Per channel, the n, k in air of the exact conductor whose reflectance is
    ``F0`` at normal incidence and ``F82_tint`` times Schlick's at cos
    theta 1/7 (see the module docstring).

    Parameters
    ----------
    F0, F82_tint
        Linear colours, one value per channel in [0, 1], in any linear
        RGB space (the inversion is per channel; the index is that space's).

    Raises
    ------
    ValueError
        For lists of other lengths, values outside [0, 1], NaN or infinity.
    """
    F0, tint = _channels("F0", F0), _channels("F82_tint", F82_tint)
    if F0.shape != tint.shape:
        raise ValueError(f"`F82_tint` must have one value per channel of `F0` ({F0.size}), got {tint.size}")
    rows = np.array([_channel(float(a), float(b)) for a, b in zip(F0, tint)])
    error = rows[:, 2]
    return EdgeTintIndex(n=rows[:, 0], k=rows[:, 1], F82_error=error, reachable=np.abs(error) < 1e-9)


def F0_F82_from_nk(n, k, eta_i: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """
    F0 and F82 tint of the exact conductor of relative index (n + i k) /
    eta_i: its reflectance at normal incidence, and at cos theta 1/7
    divided by Schlick's there (tint above 1 possible: the caller clips
    where a renderer limits it).
    """
    eta = check_eta_i(eta_i)
    n, k = np.asarray(n, dtype=np.float64), np.asarray(k, dtype=np.float64)
    F0 = fresnel_conductor(1.0, eta, n, k)
    return F0, fresnel_conductor(F82_COS_THETA, eta, n, k) / _schlick82(F0)


def F0_F82_under_coat(F0, F82_tint, eta_i: float) -> tuple[np.ndarray, np.ndarray]:
    """
    The F0 and F82 tint an F82-tint renderer must give its base for a
    metal given in air by ``F0`` and ``F82_tint`` (linear, one value per
    channel in [0, 1]) when it layers a clear coat of index ``eta_i`` over
    it at the view angle (the coat's Fresnel reflection plus the base times
    what the coat lets through): the two-anchor match of the module
    docstring, each clipped to [0, 1]. At eta_i 1 (no coat) the inputs
    themselves. Its errors against the coated metal seen from air, beside
    today's conventions: docs/edge_tint.md.

    Raises
    ------
    ValueError
        For colours outside [0, 1] or of different lengths, or eta_i outside [1, 3].
    """
    eta = check_eta_i(eta_i)
    index = nk_from_F0_F82(F0, F82_tint)
    if eta == 1.0:
        return _channels("F0", F0), _channels("F82_tint", F82_tint)
    anchors = np.array([1.0, UNDER_COAT_ANCHOR_COS])
    seen = coated_stack(anchors[:, None], eta, index.n, index.k)
    coat = fresnel_dielectric(anchors, 1.0, eta)[:, None]
    base = np.clip((seen - coat) / (1.0 - coat), 0.0, 1.0)  # the base that makes L = S there
    F0_c, mu_a, m = base[0], UNDER_COAT_ANCHOR_COS, F82_COS_THETA
    schlick_a = F0_c + (1.0 - F0_c) * (1.0 - mu_a) ** 5
    weight = mu_a * (1.0 - mu_a) ** 6 / (m * (1.0 - m) ** 6) * _schlick82(F0_c)
    return F0_c, np.clip(1.0 - (schlick_a - base[1]) / weight, 0.0, 1.0)
