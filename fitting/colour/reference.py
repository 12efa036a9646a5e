"""
Spectral reference
==================

The exact reflectance of a conductor under a clear coating in linear ACEScg:
Fresnel per wavelength (:func:`fitting.optics.fresnel.fresnel_conductor`) integrated
with the weights of :func:`fitting.colour.colorimetry.spectral_to_ACEScg_weights`.

-   :func:`spectral_grid`: the wavelength nodes for a spectral step.
-   :func:`reference_ACEScg`: the reference at any (cos theta, eta_i).
-   :func:`reference_ACEScg_grid`: the same on a product grid (cos theta
    values x eta_i values), the same numbers at a fraction of the cost:
    what the scoring grid and the preview tables use.
-   :func:`evaluation_grid`: the paper's N x N scoring grid.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Sections 3.1 and 4.1.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..domain import (
    DEFAULT_ETA_I_RANGE,
    DEFAULT_MIN_COVERAGE,
    ETA_I_MIN,
    VISIBLE_RANGE_NM,
    as_finite_array,
    check_choice,
    check_step_nm,
)
from ..optics.fresnel import fresnel_conductor
from ..optics.nk import SpectralNK, resample_nk
from .colorimetry import spectral_to_ACEScg_weights

__all__ = [
    "spectral_grid",
    "spectral_weights",
    "reference_ACEScg",
    "spectral_integral",
    "reference_ACEScg_grid",
    "evaluation_grid",
    "DTYPES",
]


def spectral_grid(step_nm: float = 1.0) -> np.ndarray:
    """
    Wavelength nodes in nm from 360 to 830 with about ``step_nm`` spacing
    (the last interval is shortened to end exactly at 830 nm).
    """
    step = check_step_nm(step_nm)
    lo, hi = VISIBLE_RANGE_NM
    nodes = np.arange(lo, hi, step)
    return np.append(nodes, hi)


@functools.lru_cache(maxsize=16)
def _weights(step_nm: float) -> np.ndarray:
    W = spectral_to_ACEScg_weights(spectral_grid(step_nm))
    W.setflags(write=False)
    return W


def spectral_weights(step_nm: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The nodes (nm) and their 3 x N ACEScg weights, computed once per step."""
    return spectral_grid(step_nm), _weights(float(step_nm))


def reference_ACEScg(
    nk: SpectralNK,
    cos_theta,
    eta_i,
    step_nm: float = 1.0,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> np.ndarray:
    """
    Exact reflectance of ``nk`` seen from a coating of index ``eta_i`` in
    linear ACEScg.

    Parameters
    ----------
    nk
        Spectral optical constants of the conductor.
    cos_theta
        :math:`\\mu` in the coating, [0, 1].
    eta_i
        Real index of the coating, >= 1; broadcast against ``cos_theta``.
    step_nm
        Spectral step; 1 nm is the reference, coarser steps integrate the
        reflectance interpolated linearly between nodes.
    min_coverage
        Refuse data covering less of 360-830 nm than this fraction.

    Returns
    -------
    numpy.ndarray
        Shape ``broadcast(cos_theta, eta_i).shape + (3,)``, linear ACEScg;
        a perfect reflector is (1, 1, 1).
    """
    return spectral_integral(fresnel_conductor, nk, cos_theta, eta_i, step_nm, min_coverage)


def spectral_integral(
    reflectance,
    nk: SpectralNK,
    cos_theta,
    eta_i,
    step_nm: float = 1.0,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    chunk_values: int = 32_768,
) -> np.ndarray:
    """
    ``reflectance(mu (P, 1), eta_i (P, 1), n (L,), k (L,)) -> (P, L)`` of
    ``nk`` resampled at the ``step_nm`` nodes, integrated to linear ACEScg
    at every broadcast (``cos_theta``, ``eta_i``): the spectral integral of
    :func:`reference_ACEScg` (the exact conductor) and
    :func:`fitting.colour.seen.seen_ACEScg` (the coated stack seen from
    air). Chunked at about ``chunk_values`` spectral values, so that memory
    stays bounded for large images and a chunk's temporaries (a dozen
    complex arrays of its size) stay in the CPU's cache: on a 100 x 100 grid
    at 1 nm, chunks of 2,000,000 values took about three times as long as
    chunks of 32,768 (measured by hand; the results differ in the last bits
    only, as the weights' matrix product is blocked otherwise).
    """
    nodes, W = spectral_weights(step_nm)
    sampled = resample_nk(nk, nodes, min_coverage)
    mu, eta = np.broadcast_arrays(as_finite_array("cos_theta", cos_theta), as_finite_array("eta_i", eta_i))
    if np.any(eta < ETA_I_MIN):
        raise ValueError(f"`eta_i` must be >= {ETA_I_MIN:g}, got {eta.min():g}")
    shape = mu.shape
    mu, eta = mu.reshape(-1, 1), eta.reshape(-1, 1)
    out = np.empty((mu.shape[0], 3))
    chunk = max(1, chunk_values // nodes.size)
    for start in range(0, mu.shape[0], chunk):
        stop = start + chunk
        out[start:stop] = reflectance(mu[start:stop], eta[start:stop], sampled.n, sampled.k) @ W.T
    return out.reshape(shape + (3,))


# Values per block of one numpy call: small enough that the block's buffers
# stay in cache, large enough that numpy's per-call overhead does not dominate.
_BLOCK = 50
# From this many eta_i values on, the kernel loops over cos theta and
# vectorises over (eta_i, wavelength), a quarter faster than broadcasting a
# column of cos theta terms; with fewer (a preview table: one eta_i, a
# thousand cos theta) it loops over eta_i.
_MIN_ETA_FOR_MU_LOOP = 16
DTYPES = ("float64", "float32")
"""Arithmetic of :func:`reference_ACEScg_grid`: float64 is the definition."""


def _fresnel_ACEScg_into(RE, s_t0, B, c, s, s2, sqrt2_mu, WT, buffers) -> np.ndarray:
    """
    One block of :func:`_fresnel_ACEScg_block`: ``RE`` = Re(eta^2) (float64)
    less ``s_t0`` = sin^2 theta (float64) is the one difference that can
    cancel, formed in float64 whatever the buffers' dtype; ``B`` =
    Im(eta^2)^2, ``c`` = cos^2 theta, ``s`` = 1 - c, ``s2`` = s^2 and
    ``sqrt2_mu`` = sqrt(2) cos theta in the buffers' dtype, each a scalar or
    an array broadcasting to the buffers' shape (rows, L). Returns the
    reflectance integrated by ``WT`` (L, 3), (rows, 3). The same operations
    on the same values in either orientation, so the numbers do not depend
    on it.
    """
    t0, X, P, Q, R, positive, R64, rgb, tiny = buffers
    np.subtract(RE, s_t0, out=t0, casting="same_kind")
    np.multiply(t0, t0, out=X)
    X += B
    np.sqrt(X, out=X)  # X = |eta^2 - s|
    np.abs(t0, out=P)
    P += X
    np.maximum(P, tiny, out=P)  # 0 only when index matched at grazing
    np.divide(B, P, out=Q)
    np.greater_equal(t0, 0.0, out=positive)
    np.copyto(Q, P, where=positive)  # Q = 2 a^2
    np.sqrt(Q, out=Q)
    Q *= sqrt2_mu  # Q = 2 mu a
    np.add(X, c, out=P)  # P = X + c
    X *= c
    X += s2  # X = c X + s^2
    np.multiply(Q, s, out=t0)
    t0 += X  # t0 = c X + s^2 + 2 mu a s
    np.subtract(P, Q, out=R)
    R *= X  # numerator
    P += Q
    P *= t0  # denominator
    # Zero only for the index-matched interface at grazing, where the
    # numerator is 0 too: R = 0, as the complex form gives.
    np.maximum(P, tiny, out=P)
    R /= P
    # The wavelength sum in float64 whatever the buffers' dtype: a float32
    # sum over ~470 nodes rounds by up to L * 2^-24 relative to the sum of
    # |terms|, and how much depends on the BLAS kernel (sgemm's FMA kernels
    # differ between OpenBLAS core types). Every operation above is a single
    # correctly rounded IEEE operation, identical on every CPU and SIMD width.
    if R64 is not None:
        np.copyto(R64, R)
        R = R64
    return np.dot(R, WT, out=rgb)


def _buffers(rows: int, L: int, dtype) -> tuple:
    """
    The kernel's work arrays for ``rows`` x ``L`` values, a float64 copy of
    the reflectance for the wavelength sum (None when ``dtype`` is float64),
    its (rows, 3) float64 result, its floor.
    """
    dtype = np.dtype(dtype)
    R64 = None if dtype == np.float64 else np.empty((rows, L))
    return (
        *(np.empty((rows, L), dtype) for _ in range(5)),
        np.empty((rows, L), dtype=bool),
        R64,
        np.empty((rows, 3)),
        np.finfo(dtype).tiny,
    )


def _fresnel_ACEScg_block(mu, eta_i, n, k, WT, out, loop_mu: bool, dtype=np.float64) -> None:
    """
    Fresnel reflectance of ``n + i k`` (L,) for cos theta ``mu`` (M,) under
    each real ``eta_i`` (E,), integrated by the weights ``WT`` (L, 3) into
    ``out`` (E, M, 3), in real arithmetic with preallocated buffers of
    ``dtype``.

    With :math:`c = \\mu^2`, :math:`s = 1 - c`, the relative index
    :math:`\\eta = (n + ik)/\\eta_i`, :math:`t_0 = \\mathrm{Re}(\\eta^2) - s`,
    :math:`B = \\mathrm{Im}(\\eta^2)^2`, :math:`X = |\\eta^2 - s| = \\sqrt{t_0^2 + B}`
    and :math:`a = \\mathrm{Re}\\sqrt{\\eta^2 - s}`:

    .. math::

        R_s = \\frac{X + c - 2\\mu a}{X + c + 2\\mu a},\\quad
        \\frac{R_p}{R_s} = \\frac{cX + s^2 - 2\\mu a s}{cX + s^2 + 2\\mu a s},\\quad
        R = \\frac{R_s + R_p}{2} = R_s \\frac{cX + s^2}{cX + s^2 + 2\\mu a s},

    the unpolarised reflectance of :func:`fitting.optics.fresnel.fresnel_conductor`
    (whose complex form is the definition; agreement to 1e-14 is tested).
    Rounding care: :math:`2a^2 = X + t_0` cancels where :math:`t_0 < 0` (every
    metal, and a dielectric past its critical angle), so there it is taken
    as :math:`B/(X + |t_0|)` (from :math:`4a^2b^2 = B`), and :math:`X + |t_0|`
    never cancels. Then the only difference that can cancel is :math:`t_0`
    itself (near the critical angle of a weak absorber), always formed in
    float64; the numerator :math:`X + c - 2\\mu a` cancels only as R goes
    to 0, with an error relative to the terms, not to R. Total internal
    reflection (k = 0) gives a = 0 and R = 1; the index-matched interface at
    grazing incidence (every term 0) gives 0, as in the complex form.

    ``loop_mu``: loop over cos theta with every ``eta_i`` in one block
    (vectorised over (eta_i, wavelength), every operand a whole block or a
    scalar: numpy's fast loops), else loop over eta_i with cos theta in
    blocks (vectorised over (cos theta, wavelength), for few eta_i). Every
    sample is computed by the same operations on the same values in either
    orientation; only the matrix product by ``WT`` may round differently
    for a different number of rows.
    """
    L = n.size
    re0, im0 = n * n - k * k, (2.0 * n * k) ** 2
    WT = np.ascontiguousarray(WT, dtype=np.float64)
    if loop_mu:
        e2 = (eta_i * eta_i)[:, None]
        RE, B = re0 / e2, (im0 / (e2 * e2)).astype(dtype, copy=False)
        buffers = _buffers(eta_i.size, L, dtype)
        # Python floats: numpy keeps the buffers' dtype with them.
        for j, m in enumerate(mu.tolist()):
            c = m * m
            s = 1.0 - c
            out[:, j] = _fresnel_ACEScg_into(RE, s, B, c, s, s * s, math.sqrt(2.0) * m, WT, buffers)
        return
    for m0 in range(0, mu.size, _BLOCK):
        m = mu[m0 : m0 + _BLOCK]
        c = (m * m)[:, None]
        s_t0 = 1.0 - c
        s2, sqrt2_mu = s_t0 * s_t0, (math.sqrt(2.0) * m)[:, None]
        c, s, s2, sqrt2_mu = (v.astype(dtype, copy=False) for v in (c, s_t0, s2, sqrt2_mu))
        buffers = _buffers(m.size, L, dtype)
        for i, e in enumerate(eta_i.tolist()):
            e2 = e * e
            B = (im0 / (e2 * e2)).astype(dtype, copy=False)
            out[i, m0 : m0 + m.size] = _fresnel_ACEScg_into(re0 / e2, s_t0, B, c, s, s2, sqrt2_mu, WT, buffers)


def reference_ACEScg_grid(
    nk: SpectralNK,
    cos_theta,
    eta_i,
    step_nm: float = 1.0,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    dtype="float64",
) -> np.ndarray:
    """
    :func:`reference_ACEScg` on the product grid of the 1-D ``cos_theta``
    (M,) and ``eta_i`` (E,) values: shape (E, M, 3) indexed [eta_i,
    cos_theta], linear ACEScg, as ``reference_ACEScg(nk, M, E)`` of
    :func:`evaluation_grid`, at about a seventh of the cost.

    Parameters
    ----------
    nk, step_nm, min_coverage
        As :func:`reference_ACEScg`.
    cos_theta
        :math:`\\mu` values in the coating (M,), clipped to [0, 1].
    eta_i
        Real coating indices (E,), >= 1.
    dtype
        The arithmetic, one of :data:`DTYPES`. ``float64`` is the
        definition. ``float32`` runs the kernel in float32 (nearly twice as
        fast), except :math:`\\mathrm{Re}(\\eta^2) - \\sin^2\\theta`, the
        one difference that can cancel, and the wavelength sum, both in
        float64: every other operation is one correctly rounded float32
        operation (the same on every CPU and SIMD width), relative to terms
        whose ratio to the reflectance is at most 1, so each node's
        reflectance is within 20 float32 roundings (1.2e-6) of float64 and
        the reference within 20 * 2^-24 * 1.147 = 1.4e-6 per channel (the
        weights' largest sum of magnitudes). Its Delta E 2000 from float64
        is within the promise of 1e-3 (tested); measured 7.1e-6 at most on
        the library conductors, the same under every numpy dispatch target
        and OpenBLAS core type. The result is float64 either way.

    Exact reductions first: repeated cos theta or eta_i values are computed
    once, and wavelengths with the same *n*, *k* (data held constant past
    their range) are merged, their weights summed. Then Fresnel in real
    arithmetic (:func:`_fresnel_ACEScg_block`), block by block in cache,
    each block reduced to ACEScg by the wavelength weights at once. In
    float64 the numbers equal the complex-arithmetic reference to rounding
    (about 1e-15).
    """
    mu = np.clip(as_finite_array("cos_theta", cos_theta), 0.0, 1.0)
    eta = as_finite_array("eta_i", eta_i)
    if mu.ndim != 1 or eta.ndim != 1:
        raise ValueError("`cos_theta` and `eta_i` must be 1-D arrays of grid values")
    if np.any(eta < 1.0):
        raise ValueError(f"`eta_i` must be >= 1, got {eta.min():g}")
    try:
        dtype = np.dtype(dtype)
    except TypeError:
        pass
    check_choice("dtype", getattr(dtype, "name", dtype), DTYPES)
    nodes, W = spectral_weights(step_nm)
    sampled = resample_nk(nk, nodes, min_coverage)
    mu_u, mu_inverse = np.unique(mu, return_inverse=True)
    eta_u, eta_inverse = np.unique(eta, return_inverse=True)
    nk_u, nk_inverse = np.unique(np.stack([sampled.n, sampled.k], axis=1), axis=0, return_inverse=True)
    WT = np.zeros((nk_u.shape[0], 3))
    np.add.at(WT, nk_inverse.reshape(-1), W.T)
    n, k = nk_u[:, 0].copy(), nk_u[:, 1].copy()
    out = np.empty((eta_u.size, mu_u.size, 3))
    if eta_u.size < _MIN_ETA_FOR_MU_LOOP:
        _fresnel_ACEScg_block(mu_u, eta_u, n, k, WT, out, False, dtype)
    else:
        # Blocks of equal size, none larger than _BLOCK.
        for rows in np.array_split(np.arange(eta_u.size), math.ceil(eta_u.size / _BLOCK)):
            lo, hi = rows[0], rows[-1] + 1
            _fresnel_ACEScg_block(mu_u, eta_u[lo:hi], n, k, WT, out[lo:hi], True, dtype)
    return out[eta_inverse.reshape(-1)][:, mu_inverse.reshape(-1)]


def evaluation_grid(
    samples: int = 100, eta_i_range: tuple[float, float] = DEFAULT_ETA_I_RANGE
) -> tuple[np.ndarray, np.ndarray]:
    """
    The scoring grid of the paper (Section 4.1): ``samples`` values of
    :math:`\\mu` evenly over [0, 1] times ``samples`` values of eta_i evenly
    over ``eta_i_range``; returns (cos_theta, eta_i) each of shape (samples,
    samples) indexed [eta_i, cos_theta].
    """
    mu = np.linspace(0.0, 1.0, samples)
    eta = np.linspace(eta_i_range[0], eta_i_range[1], samples)
    E, M = np.meshgrid(eta, mu, indexing="ij")
    return M, E
