"""
Colorimetry
===========

Spectral reflectance to linear ACEScg, and CIE 1976 L*a*b*.

-   :func:`spectral_to_ACEScg_weights`: the matrix that maps a reflectance
    spectrum sampled at given wavelengths to linear ACEScg, computed once.
-   :func:`reflectance_to_ACEScg`: applies those weights.
-   :func:`ACEScg_to_XYZ`, :func:`ACEScg_to_Lab`, :func:`ACEScg_to_Lab_jacobian`:
    CIE 1976 L*a*b* with the ACES white as reference white, and its derivative.
-   :func:`ACEScg_to_Lab_and_jacobian`, :func:`ACEScg_to_Lab_deferred`: both
    in one pass, or the Jacobian on demand (for solvers).
-   CIE Delta E 2000 and its linearisation: :mod:`fitting.colour.delta_e`.

Conventions: CIE 1931 2 degree observer; illuminant the CIE D series at the
ACES white point (D60, xy = 0.32168, 0.33767); CAT02 adaptation to the ACEScg
white; each row of the weights normalised so that a perfect reflector maps to
(1, 1, 1). The 1 nm weights and ACEScg's matrix are colour-science's,
stored with the package (:data:`STORED_CONSTANTS`); colour-science itself
is imported once, lazily, where a caller needs more of it
(:func:`colour_science`; its plotting package, and matplotlib with it,
only on use).

References
----------
Academy of Motion Picture Arts and Sciences (2016). S-2014-004, ACEScg.
CIE 015:2018 Colorimetry, 4th ed. (Lab, Section 8.2.1).
Sharma, G., Wu, W., & Dalal, E. N. (2005). The CIEDE2000 color-difference
formula. Color Research & Application, 30(1), 21-30.
"""

from __future__ import annotations

import functools
import sys
import threading
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..domain import VISIBLE_RANGE_NM

__all__ = [
    "colour_science",
    "ACES_WHITE_XY",
    "spectral_to_ACEScg_weights",
    "reflectance_to_ACEScg",
    "ACEScg_to_XYZ",
    "ACEScg_to_Lab",
    "ACEScg_to_Lab_jacobian",
    "ACEScg_to_Lab_and_jacobian",
    "ACEScg_to_Lab_deferred",
]

ACES_WHITE_XY = np.array([0.32168, 0.33767])
"""CIE xy chromaticity of the ACES white point (~D60)."""

_LOCK = threading.Lock()
_IMPORT_LOCK = threading.Lock()  # apart from _LOCK: callers of colour_science() hold that one

# CIE Lab constants: delta = 6/29 splits the cube root from its linear segment.
_DELTA = 6.0 / 29.0
_DELTA3 = _DELTA**3


def _lazy_plotting():
    """
    A finder of ``colour.plotting`` with a lazy loader (:class:`importlib.util.LazyLoader`):
    colour-science's ``__init__`` imports its plotting package, and with it
    matplotlib, about 0.4 s of every process that imports it (each server
    and fitting worker, each CLI run); nothing here plots with it. The
    package runs on its first attribute access, as a plain import would.
    (``importlib.abc`` is imported here, not with this module: it is a
    twentieth of a second of a command's start.)
    """
    import importlib.abc
    import importlib.machinery
    import importlib.util

    class LazyPlotting(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path, target=None):
            if name != "colour.plotting":
                return None
            spec = importlib.machinery.PathFinder.find_spec(name, path)
            if spec is not None and spec.loader is not None:
                spec.loader = importlib.util.LazyLoader(spec.loader)
            return spec

    return LazyPlotting()


@functools.cache
def colour_science():
    """colour-science, imported once, quietly (its plotting package on first use: :func:`_lazy_plotting`)."""
    import warnings

    with _IMPORT_LOCK:
        finder = _lazy_plotting()
        sys.meta_path.insert(0, finder)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                import colour
        finally:
            sys.meta_path.remove(finder)
    return colour


STORED_CONSTANTS = Path(__file__).with_name("ACEScg_1nm.npz")
"""The 1 nm weights and the ACEScg to XYZ matrix of :func:`colour_science_constants`,
stored (``weights`` (3, 471), ``RGB_to_XYZ`` (3, 3)): a fit reads them
without importing colour-science (with scipy, most of a command's start);
``tests/fitting/colour/test_colorimetry.py`` holds them equal to the bit to
colour-science's (:func:`write_stored_constants` writes them again)."""


def colour_science_constants() -> tuple[np.ndarray, np.ndarray]:
    """
    The definition of the stored constants, by colour-science: the weights
    (3, 471) from spectral reflectance at 360-830 nm, 1 nm, to linear ACEScg
    (CIE 1931 2 degree observer, the D series illuminant at the ACES white,
    CAT02 to the ACEScg white, each row normalised so that a perfect
    reflector maps to (1, 1, 1)), and ACEScg's RGB to XYZ matrix.
    """
    colour = colour_science()
    shape = colour.SpectralShape(VISIBLE_RANGE_NM[0], VISIBLE_RANGE_NM[1], 1)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    illuminant = colour.sd_CIE_illuminant_D_series(ACES_WHITE_XY).copy().align(shape)
    S = illuminant.values
    W_XYZ = (cmfs.values * S[:, None]).T  # 3 x N
    W_XYZ /= W_XYZ[1].sum()
    XYZ_w = W_XYZ.sum(axis=1)
    acescg = colour.RGB_COLOURSPACES["ACEScg"]
    XYZ_wr = acescg.matrix_RGB_to_XYZ @ np.ones(3)
    cat = colour.adaptation.matrix_chromatic_adaptation_VonKries(XYZ_w, XYZ_wr, transform="CAT02")
    W = acescg.matrix_XYZ_to_RGB @ cat @ W_XYZ
    # A perfect reflector maps to (1, 1, 1) exactly.
    W /= W.sum(axis=1, keepdims=True)
    return W, np.array(acescg.matrix_RGB_to_XYZ, dtype=np.float64)


def write_stored_constants(path: Path = STORED_CONSTANTS) -> Path:
    """Write :func:`colour_science_constants` to ``path`` (after a colour-science update changes them)."""
    weights, RGB_to_XYZ = colour_science_constants()
    np.savez(path, weights=weights, RGB_to_XYZ=RGB_to_XYZ)
    return path


@functools.cache
def _stored() -> tuple[np.ndarray, np.ndarray]:
    with np.load(STORED_CONSTANTS) as data:
        weights, RGB_to_XYZ = data["weights"], data["RGB_to_XYZ"]
    if weights.shape != (3, int(VISIBLE_RANGE_NM[1] - VISIBLE_RANGE_NM[0]) + 1) or RGB_to_XYZ.shape != (3, 3):
        raise ValueError(f"{STORED_CONSTANTS} holds arrays of the wrong shape: write it again")
    weights.setflags(write=False)
    RGB_to_XYZ.setflags(write=False)
    return weights, RGB_to_XYZ


def _weights_1nm() -> np.ndarray:
    return _stored()[0]


def _hat_matrix(fine: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """P such that P @ values(nodes) is their linear interpolation at ``fine``."""
    P = np.zeros((fine.size, nodes.size))
    index = np.clip(np.searchsorted(nodes, fine, side="right") - 1, 0, nodes.size - 2)
    lo, hi = nodes[index], nodes[index + 1]
    w = np.clip((fine - lo) / (hi - lo), 0.0, 1.0)
    rows = np.arange(fine.size)
    P[rows, index] = 1.0 - w
    P[rows, index + 1] += w
    return P


def spectral_to_ACEScg_weights(wavelength_nm) -> np.ndarray:
    """
    Weights :math:`W` (3 x N) with :math:`RGB = W R(\\lambda)`.

    ``wavelength_nm`` must span 360-830 nm. On the 1 nm grid the weights are
    the CIE integration itself; on a coarser grid they integrate the linear
    interpolation of the reflectance between the nodes, so a reflectance that
    is linear between nodes gives exactly the 1 nm result.

    Parameters
    ----------
    wavelength_nm
        Strictly increasing wavelengths :math:`\\lambda` in nm from 360 to 830.

    Returns
    -------
    numpy.ndarray
        3 x N weights to linear ACEScg; every row sums to 1.
    """
    nodes = np.asarray(wavelength_nm, dtype=np.float64)
    if nodes.ndim != 1 or nodes.size < 2 or np.any(np.diff(nodes) <= 0):
        raise ValueError("`wavelength_nm` must be strictly increasing with >= 2 samples")
    if nodes[0] != VISIBLE_RANGE_NM[0] or nodes[-1] != VISIBLE_RANGE_NM[1]:
        raise ValueError(
            f"`wavelength_nm` must span {VISIBLE_RANGE_NM[0]:.0f}-"
            f"{VISIBLE_RANGE_NM[1]:.0f} nm, got {nodes[0]:g}-{nodes[-1]:g}"
        )
    with _LOCK:
        W1 = _weights_1nm()
    fine = np.arange(VISIBLE_RANGE_NM[0], VISIBLE_RANGE_NM[1] + 0.5, 1.0)
    if nodes.size == fine.size and np.array_equal(nodes, fine):
        return W1.copy()
    return W1 @ _hat_matrix(fine, nodes)


def reflectance_to_ACEScg(reflectance, weights) -> np.ndarray:
    """
    Linear ACEScg of reflectance spectra: ``reflectance[..., N] @ weights.T``.
    """
    return np.asarray(reflectance, dtype=np.float64) @ np.asarray(weights).T


@functools.cache
def _matrices() -> tuple[np.ndarray, np.ndarray]:
    M = _stored()[1]
    XYZ_n = M @ np.ones(3)
    return M, XYZ_n


def ACEScg_to_XYZ(RGB) -> np.ndarray:
    """Linear ACEScg to CIE XYZ (Y of white = 1), ACES white."""
    with _LOCK:
        M, _ = _matrices()
    return np.asarray(RGB, dtype=np.float64) @ M.T


def _f_lab(t: np.ndarray) -> np.ndarray:
    return np.where(t > _DELTA3, np.cbrt(t), t / (3.0 * _DELTA * _DELTA) + 4.0 / 29.0)


def _df_lab(t: np.ndarray) -> np.ndarray:
    safe = np.maximum(t, _DELTA3)
    return np.where(t > _DELTA3, 1.0 / (3.0 * np.cbrt(safe) ** 2), 1.0 / (3.0 * _DELTA * _DELTA))


def ACEScg_to_Lab(RGB) -> np.ndarray:
    """
    Linear ACEScg to CIE 1976 L*a*b* (L in [0, 100]) with the ACES white as
    reference white. Negative values follow the linear segment of the CIE
    formula, so the map is defined and differentiable everywhere.
    """
    with _LOCK:
        M, XYZ_n = _matrices()
    XYZ = np.asarray(RGB, dtype=np.float64) @ M.T / XYZ_n
    f = _f_lab(XYZ)
    L = 116.0 * f[..., 1] - 16.0
    a = 500.0 * (f[..., 0] - f[..., 1])
    b = 200.0 * (f[..., 1] - f[..., 2])
    return np.stack([L, a, b], axis=-1)


def ACEScg_to_Lab_and_jacobian(RGB) -> tuple[np.ndarray, np.ndarray]:
    """
    :func:`ACEScg_to_Lab` and :func:`ACEScg_to_Lab_jacobian` of ``RGB`` (S, 3)
    in one pass (XYZ and its cube root once): for solvers that want both at
    every point.
    """
    Lab, jacobian = ACEScg_to_Lab_deferred(RGB)
    return Lab, jacobian()


def ACEScg_to_Lab_deferred(RGB) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
    """
    The Lab of :func:`ACEScg_to_Lab_and_jacobian` now and a function that
    returns its Jacobian (the same values, from the cube roots kept): for
    solvers that need the Jacobian at only some of the points they
    evaluate (SLSQP's line search asks for values alone).
    """
    with _LOCK:
        M, XYZ_n = _matrices()
    Mn = M / XYZ_n[:, None]
    XYZ = np.asarray(RGB, dtype=np.float64) @ Mn.T
    above = XYZ > _DELTA3
    root = np.cbrt(np.maximum(XYZ, _DELTA3))
    f = np.where(above, root, XYZ / (3.0 * _DELTA * _DELTA) + 4.0 / 29.0)
    Lab = f @ _LAB_OF_F.T
    Lab[..., 0] -= 16.0

    def jacobian() -> np.ndarray:
        df = np.where(above, 1.0 / (3.0 * root * root), 1.0 / (3.0 * _DELTA * _DELTA))
        return (df[..., None, :] * _LAB_OF_F) @ Mn

    return Lab, jacobian


# Lab = K f - (16, 0, 0) with f = f(X / Xn, Y / Yn, Z / Zn)
_LAB_OF_F = np.array([[0.0, 116.0, 0.0], [500.0, -500.0, 0.0], [0.0, 200.0, -200.0]])


def ACEScg_to_Lab_jacobian(RGB) -> np.ndarray:
    """
    :math:`\\partial Lab / \\partial RGB`, shape ``RGB.shape + (3,)``:
    ``J[..., i, j] = d Lab_i / d RGB_j``.
    """
    with _LOCK:
        M, XYZ_n = _matrices()
    Mn = M / XYZ_n[:, None]
    XYZ = np.asarray(RGB, dtype=np.float64) @ Mn.T
    df = _df_lab(XYZ)  # (..., 3)
    dF = df[..., :, None] * Mn  # d f_i / d RGB_j
    L = 116.0 * dF[..., 1, :]
    a = 500.0 * (dF[..., 0, :] - dF[..., 1, :])
    b = 200.0 * (dF[..., 1, :] - dF[..., 2, :])
    return np.stack([L, a, b], axis=-2)
