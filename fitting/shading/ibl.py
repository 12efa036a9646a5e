"""
Split-sum pre-integration for image-based lighting
==================================================

The specular directional albedo of the GGX BRDF
(:mod:`fitting.shading.microfacet`) with the model's Fresnel, pre-integrated
so that a renderer multiplies it with a prefiltered environment (Karis 2013,
the split-sum approximation). The model,

.. math::

    F(\\mu) = F_0 (1 - (1 - \\mu)^5) + (1 - \\mu)^5 - a\\,\\mu(1 - \\mu)^{\\alpha},

is linear in :math:`F_0` and *a*, so its directional albedo is

.. math::

    E(\\mu_v, r) = F_0 A(\\mu_v, r) + B(\\mu_v, r) - a\\,G(\\mu_v, r, \\alpha)

with, over the GGX lobe of roughness *r* (:math:`h` the microfacet normal,
:math:`x = 1 - \\mathbf{v}\\cdot\\mathbf{h}`),
:math:`A = \\int (1 - x^5)\\,w`, :math:`B = \\int x^5\\,w` (the usual
split-sum terms) and :math:`G = \\int (\\mathbf{v}\\cdot\\mathbf{h})\\,x^{\\alpha}\\,w`,
where :math:`w\\,d\\omega = f_s/F \\cdot \\cos\\theta_l\\,d\\omega_l`. *G* needs
:math:`\\alpha` as a third axis, as Blender EEVEE's F82 channel
(``brdf_f82_tint_lut``, :math:`\\alpha = 6` fixed) does not: here alpha
varies per channel and with eta_i. The slices are spaced evenly in
:math:`\\log(\\alpha + 1)`, where *G* is close to linear.

-   :class:`SplitSumLUT`: the table, its lookup and its binary form.
-   :func:`generate_lut`: deterministic pre-integration (Hammersley points
    through Heitz's visible-normal sampling).
-   :func:`split_sum_model`, :func:`split_sum_schlick`,
    :func:`split_sum_lazanyi`: the albedo of the model and the baselines.
-   :func:`split_sum_coated`: an approximate pre-integrated albedo of the
    ``coated`` mode from the same LUT.
-   :func:`average_fresnel`: the closed-form hemispherical average
    :math:`2\\int_0^1 F\\mu\\,d\\mu` of the model.
-   :func:`energy_compensation`: the multiple-scattering factor from it.
-   :func:`encode_lut`, :func:`decode_lut`: the file format (docs/shading.md).

References
----------
Karis, B. (2013). Real shading in Unreal Engine 4. SIGGRAPH course.
Heitz, E. (2018). Sampling the GGX distribution of visible normals. JCGT 7(4).
Kulla, C., & Conty, A. (2017). Revisiting physically based shading at
Imageworks. SIGGRAPH course (average Fresnel, energy compensation).
Fdez-Aguera, C. J. (2019). A multiple-scattering microfacet model for
real-time image-based lighting. JCGT 8(1).
Hoffman, N. (2019). Fresnel equations considered harmful (F82).
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

import functools
import struct
import zlib
from dataclasses import dataclass

import numpy as np

from ..domain import as_finite_array
from ..models.baselines import external_medium_F0, lazanyi_a
from ..models.coated_conductor import ALPHA_MIN
from ..optics.fresnel import fresnel_dielectric
from .microfacet import alpha_g_from_roughness, sample_visible_normal, smith_G1, smith_G2

__all__ = [
    "LUT_SHAPE",
    "ALPHA_RANGE",
    "LUT_SAMPLES",
    "SplitSumLUT",
    "generate_lut",
    "default_lut",
    "encode_lut",
    "decode_lut",
    "split_sum_model",
    "split_sum_schlick",
    "split_sum_lazanyi",
    "split_sum_coated",
    "average_fresnel",
    "energy_compensation",
]

LUT_SHAPE = (16, 64, 64)
"""(alpha slices, roughness nodes, NdotV nodes)."""

ALPHA_RANGE = (0.5, 12.0)
"""The alpha axis: the library's alphas lie in 0.9 .. 8 over eta_i 1 .. 2.5;
the range leaves room on both sides. Outside it, alpha is clamped (G varies
slowly there and is multiplied by a, which is small where alpha is extreme)."""

LUT_SAMPLES = 4096
"""Hammersley points per (NdotV, roughness) node of the pre-integration."""

MAGIC = b"CFIBLUT1"
_HEADER = struct.Struct("<8s4I2f")


@dataclass(frozen=True)
class SplitSumLUT:
    """
    The pre-integrated terms on a regular grid.

    ``data[k, j, i] = (A, B, G)`` at NdotV node i, roughness node j and
    alpha slice k: NdotV :math:`\\mu_i = (i/(n_\\mu - 1))^2` (nodes crowd
    towards grazing, where the albedo bends), roughness :math:`r_j = j/(n_r - 1)`,
    :math:`\\log(\\alpha_k + 1)` evenly from :math:`\\log(\\alpha_{lo} + 1)` to
    :math:`\\log(\\alpha_{hi} + 1)`. Stored float32 (the texture a renderer
    uploads); *A* and *B* repeat across the slices so that one trilinear
    fetch returns all three.
    """

    data: np.ndarray
    alpha_range: tuple[float, float] = ALPHA_RANGE

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.data.shape[:3]

    def coordinates(self, NdotV, roughness, alpha):
        """Continuous texel coordinates (i, j, k) of the inputs, clamped to the grid."""
        n_alpha, n_r, n_mu = self.shape
        mu = np.clip(np.asarray(NdotV, dtype=np.float64), 0.0, 1.0)
        r = np.clip(np.asarray(roughness, dtype=np.float64), 0.0, 1.0)
        lo, hi = (np.log1p(v) for v in self.alpha_range)
        s = np.log1p(np.clip(np.asarray(alpha, dtype=np.float64), *self.alpha_range))
        return np.sqrt(mu) * (n_mu - 1), r * (n_r - 1), (s - lo) / (hi - lo) * (n_alpha - 1)

    def alpha_nodes(self) -> np.ndarray:
        """The alpha of each slice."""
        lo, hi = (np.log1p(v) for v in self.alpha_range)
        return np.expm1(np.linspace(lo, hi, self.shape[0]))

    def lookup(self, NdotV, roughness, alpha) -> np.ndarray:
        """
        (A, B, G), shape ``broadcast + (3,)``; inputs outside the grid are
        clamped (NdotV, roughness to [0, 1], alpha to :attr:`alpha_range`).

        Bilinear in (NdotV, roughness) on the two slices around alpha, then
        geometric between them, :math:`G = G_k^{1-t} G_{k+1}^t` with *t*
        linear in alpha: for a mirror lobe :math:`G = \\mu x^\\alpha` is
        exactly exponential in alpha, and a rough lobe's G, a mixture of such
        exponentials, stays close to one (linear interpolation of G in
        log(alpha + 1) errs by ~1 % of the albedo near alpha = 1, this by
        < 0.1 %). *A* and *B* do not depend on alpha.
        """
        x, y, z = np.broadcast_arrays(*self.coordinates(NdotV, roughness, alpha))
        n_alpha, n_r, n_mu = self.shape
        data = self.data.astype(np.float64)
        i0 = np.clip(np.floor(x).astype(np.int64), 0, n_mu - 2)
        j0 = np.clip(np.floor(y).astype(np.int64), 0, n_r - 2)
        k0 = np.clip(np.floor(z).astype(np.int64), 0, n_alpha - 2)
        fx, fy = (x - i0)[..., None], (y - j0)[..., None]

        def bilinear(k):
            return (
                (1.0 - fy) * ((1.0 - fx) * data[k, j0, i0] + fx * data[k, j0, i0 + 1])
                + fy * ((1.0 - fx) * data[k, j0 + 1, i0] + fx * data[k, j0 + 1, i0 + 1])
            )

        low, high = bilinear(k0), bilinear(k0 + 1)
        nodes = self.alpha_nodes()
        alpha = np.clip(np.broadcast_to(np.asarray(alpha, dtype=np.float64), x.shape), *self.alpha_range)
        t = np.clip((alpha - nodes[k0]) / (nodes[k0 + 1] - nodes[k0]), 0.0, 1.0)
        # G > 0 wherever the lobe has weight; the floor keeps log2 finite
        # at NdotV = 0, where every term is 0.
        G = np.exp2(
            (1.0 - t) * np.log2(np.maximum(low[..., 2], _G_FLOOR))
            + t * np.log2(np.maximum(high[..., 2], _G_FLOOR))
        )
        return np.concatenate([low[..., :2], G[..., None]], axis=-1)


_G_FLOOR = 1.0e-30
"""Floor of G before its logarithm (float32-safe: above FLT_MIN)."""


def _hammersley(count: int) -> tuple[np.ndarray, np.ndarray]:
    """The Hammersley point set: (i + 1/2)/N and the base-2 radical inverse of i."""
    i = np.arange(count, dtype=np.uint64)
    bits = i.copy()
    reversed_bits = np.zeros_like(bits)
    for _ in range(32):
        reversed_bits = (reversed_bits << np.uint64(1)) | (bits & np.uint64(1))
        bits >>= np.uint64(1)
    return (i.astype(np.float64) + 0.5) / count, reversed_bits.astype(np.float64) / 2.0**32


def _node_terms(mu: np.ndarray, roughness: float, alphas: np.ndarray, u1, u2) -> np.ndarray:
    """(n_mu, n_alpha, 3) of (A, B, G) at one roughness, by the point set."""
    alpha_g = alpha_g_from_roughness(roughness)
    mu = np.maximum(mu, 1.0e-6)  # NdotV = 0: the limit from above (G1 -> 0 cancels)
    v = np.stack([np.sqrt(1.0 - mu * mu), np.zeros_like(mu), mu], axis=-1)[:, None, :]
    h = sample_visible_normal(v, alpha_g, u1[None, :], u2[None, :])
    VdotH = np.clip(np.sum(v * h, axis=-1), 0.0, 1.0)
    NdotL = 2.0 * VdotH * h[..., 2] - v[..., 2]
    w = np.where(
        NdotL > 0.0, smith_G2(mu[:, None], NdotL, alpha_g) / smith_G1(mu[:, None], alpha_g), 0.0
    )
    x = 1.0 - VdotH
    x5 = x**5
    A = np.mean(w * (1.0 - x5), axis=1)
    B = np.mean(w * x5, axis=1)
    G = np.stack([np.mean(w * VdotH * x**alpha, axis=1) for alpha in alphas], axis=-1)
    return np.stack(np.broadcast_arrays(A[:, None], B[:, None], G), axis=-1)


def generate_lut(
    shape: tuple[int, int, int] = LUT_SHAPE,
    alpha_range: tuple[float, float] = ALPHA_RANGE,
    samples: int = LUT_SAMPLES,
) -> SplitSumLUT:
    """
    Pre-integrate (A, B, G) on the grid of :class:`SplitSumLUT`.

    Each node is the mean of the estimator :math:`F\\,G_2/G_1(\\mathbf{v})` of
    Heitz's visible-normal sampling over ``samples`` Hammersley points (a
    deterministic quadrature: the same table on every run). Roughness 0 is
    evaluated at :data:`fitting.shading.microfacet.ROUGHNESS_MIN`, as the
    BRDF is.
    """
    n_alpha, n_r, n_mu = (int(v) for v in shape)
    if min(n_alpha, n_r, n_mu) < 2 or max(n_alpha, n_r, n_mu) > 1024:
        raise ValueError(f"`shape` must hold 2 .. 1024 nodes per axis, got {shape}")
    if not 16 <= int(samples) <= 1 << 20:
        raise ValueError(f"`samples` must lie in [16, 1048576], got {samples}")
    lo, hi = (float(v) for v in alpha_range)
    if not (np.isfinite(lo) and np.isfinite(hi) and 0.0 < lo < hi):
        raise ValueError(f"`alpha_range` must satisfy 0 < lo < hi, got {alpha_range}")
    mu = (np.arange(n_mu) / (n_mu - 1)) ** 2
    alphas = np.expm1(np.linspace(np.log1p(lo), np.log1p(hi), n_alpha))
    u1, u2 = _hammersley(int(samples))
    data = np.empty((n_alpha, n_r, n_mu, 3))
    for j, r in enumerate(np.arange(n_r) / (n_r - 1)):
        data[:, j] = _node_terms(mu, r, alphas, u1, u2).transpose(1, 0, 2)
    return SplitSumLUT(data.astype(np.float32), (lo, hi))


def encode_lut(lut: SplitSumLUT) -> bytes:
    """The binary file of docs/shading.md: header, float32 texels, CRC-32."""
    n_alpha, n_r, n_mu = lut.shape
    header = _HEADER.pack(MAGIC, n_mu, n_r, n_alpha, 3, *lut.alpha_range)
    body = header + np.ascontiguousarray(lut.data, dtype="<f4").tobytes()
    return body + struct.pack("<I", zlib.crc32(body))


def decode_lut(blob: bytes) -> SplitSumLUT:
    """
    Read :func:`encode_lut`'s bytes.

    Raises
    ------
    ValueError
        If the file is truncated, not a LUT, damaged (CRC) or inconsistent.
    """
    blob = bytes(blob)
    if len(blob) < _HEADER.size + 4:
        raise ValueError(f"`lut` is truncated: {len(blob)} bytes, need at least {_HEADER.size + 4}")
    magic, n_mu, n_r, n_alpha, channels, lo, hi = _HEADER.unpack_from(blob)
    if magic != MAGIC:
        raise ValueError(f"`lut` is not a split-sum LUT (magic {magic!r}, expected {MAGIC!r})")
    if channels != 3 or min(n_mu, n_r, n_alpha) < 2 or max(n_mu, n_r, n_alpha) > 1024:
        raise ValueError(f"`lut` header is inconsistent: {n_mu} x {n_r} x {n_alpha} x {channels}")
    size = _HEADER.size + 4 * 3 * n_mu * n_r * n_alpha
    if len(blob) != size + 4:
        raise ValueError(f"`lut` must be {size + 4} bytes for its header, got {len(blob)}")
    (crc,) = struct.unpack_from("<I", blob, size)
    if zlib.crc32(blob[:size]) != crc:
        raise ValueError("`lut` is damaged: CRC-32 mismatch")
    if not (np.isfinite(lo) and np.isfinite(hi) and 0.0 < lo < hi):
        raise ValueError(f"`lut` alpha range must satisfy 0 < lo < hi, got [{lo}, {hi}]")
    data = np.frombuffer(blob, dtype="<f4", count=3 * n_mu * n_r * n_alpha, offset=_HEADER.size)
    data = data.reshape(n_alpha, n_r, n_mu, 3).astype(np.float32)
    if not np.all(np.isfinite(data)):
        raise ValueError("`lut` texels must be finite")
    return SplitSumLUT(data, (float(lo), float(hi)))


@functools.cache
def default_lut() -> SplitSumLUT:
    """The LUT at the default shape and sample count, generated once per process."""
    return generate_lut()


def _inputs(NdotV, roughness):
    return as_finite_array("NdotV", NdotV), as_finite_array("roughness", roughness)


def split_sum_model(NdotV, roughness, F0, a, alpha, lut: SplitSumLUT | None = None) -> np.ndarray:
    """
    Directional albedo of the GGX BRDF with the model's Fresnel:
    :math:`F_0 A + B - a\\,G(\\alpha)` per channel, linear ACEScg.

    Parameters
    ----------
    NdotV, roughness
        Broadcast against each other; clamped to [0, 1].
    F0, a, alpha
        Per-channel parameters (3,) of the model at one eta_i
        (:func:`fitting.models.coated_conductor.collapse_to_eta_i`).

    Returns
    -------
    numpy.ndarray
        ``broadcast(NdotV, roughness).shape + (3,)``.
    """
    lut = lut or default_lut()
    mu, r = _inputs(NdotV, roughness)
    F0, a, alpha = (np.asarray(p, dtype=np.float64) for p in (F0, a, alpha))
    terms = lut.lookup(mu[..., None], r[..., None], alpha)
    return F0 * terms[..., 0] + terms[..., 1] - a * terms[..., 2]


def split_sum_schlick(NdotV, roughness, F0, lut: SplitSumLUT | None = None) -> np.ndarray:
    """Directional albedo with Schlick's Fresnel: :math:`F_0 A + B`."""
    lut = lut or default_lut()
    mu, r = _inputs(NdotV, roughness)
    terms = lut.lookup(mu, r, lut.alpha_range[0])
    return np.asarray(F0, dtype=np.float64) * terms[..., 0:1] + terms[..., 1:2]


def split_sum_lazanyi(
    NdotV, roughness, eta_i, F0_air, F82_air, lut: SplitSumLUT | None = None
) -> np.ndarray:
    """
    Directional albedo with adjusted Lazanyi (:func:`fitting.models.baselines.lazanyi_adjusted`):
    the model's form with :math:`F_0'` at ``eta_i`` (scalar), *a* from F0 and
    F82 in air and :math:`\\alpha = 6`.
    """
    F0 = external_medium_F0(F0_air, float(eta_i))
    a = lazanyi_a(F0_air, F82_air)
    return split_sum_model(NdotV, roughness, F0, a, np.full(3, 6.0), lut)


def split_sum_coated(
    NdotV, roughness, F0, a, alpha, eta_i, coat_roughness=0.0, lut: SplitSumLUT | None = None
) -> np.ndarray:
    """
    Approximate directional albedo of the ``coated`` BRDF from the LUT:

    .. math::

        E \\approx F_{0c} A_c + B_c + [1 - F_c(\\mu_v)]^2\\,E_s(\\mu_t)

    with the coat's lobe by Schlick's form at
    :math:`F_{0c} = ((\\eta_i - 1)/(\\eta_i + 1))^2` (:math:`A_c, B_c` at
    ``coat_roughness``), and the base's albedo :math:`E_s` of
    :func:`split_sum_model` at the refracted cosine
    :math:`\\mu_t = \\sqrt{1 - (1 - \\mu_v^2)/\\eta_i^2}`, transmitted in and
    out at the view angle. Exact for a smooth coat over a smooth base (the
    light leaves at the mirror angle); for a rough base it ignores the light
    lost by total internal reflection, so it overestimates (docs/shading.md
    gives its error against Monte Carlo). Equals :func:`split_sum_model` at
    eta_i = 1.
    """
    lut = lut or default_lut()
    mu, r = _inputs(NdotV, roughness)
    eta = max(float(as_finite_array("eta_i", eta_i)), 1.0)
    mu = np.clip(mu, 0.0, 1.0)
    F0c = ((eta - 1.0) / (eta + 1.0)) ** 2
    coat = split_sum_schlick(mu, coat_roughness, np.full(3, F0c), lut) if eta > 1.0 else 0.0
    T = (1.0 - fresnel_dielectric(mu, 1.0, eta))[..., None]
    mu_t = np.sqrt(1.0 - (1.0 - mu * mu) / (eta * eta))
    return coat + T * T * split_sum_model(mu_t, r, F0, a, alpha, lut)


def average_fresnel(F0, a, alpha) -> np.ndarray:
    """
    Closed-form hemispherical average of the model,
    :math:`\\bar F = 2\\int_0^1 F(\\mu)\\,\\mu\\,d\\mu`:

    .. math::

        \\bar F = F_0 + \\frac{1 - F_0}{21} - \\frac{4a}{(\\alpha + 1)(\\alpha + 2)(\\alpha + 3)}

    from :math:`2\\int\\mu(1-\\mu)^5 d\\mu = 2B(2, 6) = 1/21` and
    :math:`2\\int\\mu^2(1-\\mu)^\\alpha d\\mu = 2B(3, \\alpha + 1)` with the Beta
    function :math:`B(3, \\alpha+1) = 2/((\\alpha+1)(\\alpha+2)(\\alpha+3))`.
    Alpha is clamped to :data:`fitting.models.coated_conductor.ALPHA_MIN` as the model does.
    """
    F0, a = np.asarray(F0, dtype=np.float64), np.asarray(a, dtype=np.float64)
    alpha = np.maximum(np.asarray(alpha, dtype=np.float64), ALPHA_MIN)
    return F0 + (1.0 - F0) / 21.0 - 4.0 * a / ((alpha + 1.0) * (alpha + 2.0) * (alpha + 3.0))


def energy_compensation(E_white, F_average) -> np.ndarray:
    """
    Multiple-scattering factor of the specular lobe (Kulla & Conty 2017;
    Fdez-Aguera 2019; Filament's form):
    :math:`1 + \\bar F\\,(1 - E)/E` with :math:`E = A + B` the single-scattering
    albedo of a white (F = 1) lobe. Multiply the single-scattering specular
    by it; *E* is floored at 1e-4 (a lobe can never be that dark: E >= 0.45
    for GGX at any roughness with NdotV >= 0.05).
    """
    E = np.maximum(np.asarray(E_white, dtype=np.float64), 1.0e-4)
    return 1.0 + np.asarray(F_average, dtype=np.float64) * (1.0 - E) / E
