"""
The split-sum LUT: table, generation, file format and on-disk cache
===================================================================

The pre-integrated (A, B, G) of :mod:`fitting.shading.ibl` on a regular grid
(NdotV x roughness x alpha), split out of that module:

-   :class:`SplitSumLUT`: the table and its lookup.
-   :func:`generate_lut`: deterministic pre-integration (Hammersley points
    through Heitz's visible-normal sampling).
-   :func:`encode_lut`, :func:`decode_lut`: the file format (docs/shading.md).
-   :func:`cached_lut`, :func:`default_lut`: the LUT through a deterministic
    on-disk cache (generated once per machine, not once per process):
    :func:`cache_dir`, :func:`lut_cache_path`.

References
----------
Karis, B. (2013). Real shading in Unreal Engine 4. SIGGRAPH course.
Heitz, E. (2018). Sampling the GGX distribution of visible normals. JCGT 7(4).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import struct
import tempfile
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..domain import cached_once
from .microfacet import alpha_g_from_roughness, sample_visible_normal, smith_G1, smith_G2

__all__ = [
    "LUT_SHAPE",
    "ALPHA_RANGE",
    "LUT_SAMPLES",
    "MAGIC",
    "CACHE_FORMAT_VERSION",
    "CACHE_ENV",
    "SplitSumLUT",
    "generate_lut",
    "encode_lut",
    "decode_lut",
    "cache_dir",
    "lut_cache_path",
    "cached_lut",
    "default_lut",
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
            return (1.0 - fy) * ((1.0 - fx) * data[k, j0, i0] + fx * data[k, j0, i0 + 1]) + fy * (
                (1.0 - fx) * data[k, j0 + 1, i0] + fx * data[k, j0 + 1, i0 + 1]
            )

        low, high = bilinear(k0), bilinear(k0 + 1)
        nodes = self.alpha_nodes()
        alpha = np.clip(np.broadcast_to(np.asarray(alpha, dtype=np.float64), x.shape), *self.alpha_range)
        t = np.clip((alpha - nodes[k0]) / (nodes[k0 + 1] - nodes[k0]), 0.0, 1.0)
        # G > 0 wherever the lobe has weight; the floor keeps log2 finite
        # at NdotV = 0, where every term is 0.
        G = np.exp2(
            (1.0 - t) * np.log2(np.maximum(low[..., 2], _G_FLOOR)) + t * np.log2(np.maximum(high[..., 2], _G_FLOOR))
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
    w = np.where(NdotL > 0.0, smith_G2(mu[:, None], NdotL, alpha_g) / smith_G1(mu[:, None], alpha_g), 0.0)
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


CACHE_FORMAT_VERSION = 1
"""Bumped whenever :func:`generate_lut` or the file format changes, so that
stale cache files are never read."""

CACHE_ENV = "CF_CACHE_DIR"
"""Environment variable naming the cache folder (default
``$XDG_CACHE_HOME/coated-fresnel``, else ``~/.cache/coated-fresnel``)."""


def cache_dir() -> Path:
    """The on-disk cache folder (:data:`CACHE_ENV`)."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "coated-fresnel"


def lut_cache_path(
    shape: tuple[int, int, int] = LUT_SHAPE,
    alpha_range: tuple[float, float] = ALPHA_RANGE,
    samples: int = LUT_SAMPLES,
) -> Path:
    """
    The cache file of one LUT: the name holds the format version and a
    SHA-256 of the generation parameters (shape, alpha range as float32
    bits, samples), so that any change of them misses the cache.
    """
    n_alpha, n_r, n_mu = (int(v) for v in shape)
    lo, hi = (float(v) for v in alpha_range)
    key = struct.pack("<4I3I2f", CACHE_FORMAT_VERSION, n_alpha, n_r, n_mu, int(samples), 3, 0, lo, hi)
    digest = hashlib.sha256(MAGIC + key).hexdigest()[:16]
    return cache_dir() / f"ibl_lut_v{CACHE_FORMAT_VERSION}_{n_mu}x{n_r}x{n_alpha}_{int(samples)}_{digest}.cflut"


def cached_lut(
    shape: tuple[int, int, int] = LUT_SHAPE,
    alpha_range: tuple[float, float] = ALPHA_RANGE,
    samples: int = LUT_SAMPLES,
) -> SplitSumLUT:
    """
    :func:`generate_lut` through the on-disk cache: a valid cache file
    (:func:`decode_lut` checks its CRC and header, and its shape and alpha
    range must match) is read; otherwise the LUT is generated and written
    atomically (a temporary file in the same folder, then ``os.replace``),
    so concurrent processes never see a partial file. A cache folder that
    cannot be written only costs the regeneration.
    """
    path = lut_cache_path(shape, alpha_range, samples)
    expected_range = tuple(float(np.float32(v)) for v in alpha_range)
    try:
        lut = decode_lut(path.read_bytes())
        if lut.shape == tuple(int(v) for v in shape) and lut.alpha_range == expected_range:
            return lut
    except (OSError, ValueError):
        pass
    lut = generate_lut(shape, alpha_range, samples)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as handle:
                handle.write(encode_lut(lut))
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    except OSError:
        pass
    return decode_lut(encode_lut(lut))


@cached_once
def default_lut() -> SplitSumLUT:
    """The LUT at the default shape and sample count, from the on-disk cache
    (:func:`cached_lut`), once per process."""
    return cached_lut()
