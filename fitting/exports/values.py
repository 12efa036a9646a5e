"""
Export values
=============

The numbers an export carries, for one coating index eta_i, fitted in the
working space of the target tools (linear Rec.709 primaries, D65 white: the
default ``lin_rec709`` of MaterialX, Blender's scene linear, glTF's linear
sRGB) to the reflectance of the metal under the coat.

The target curve :math:`T(\\mu)` is the spectral reference under the coat
(:func:`fitting.colour.reference.reference_ACEScg` at eta_i, 1 nm, linear ACEScg)
converted to linear Rec.709 with CAT02 adaptation (a perfect reflector stays
(1, 1, 1)), at :data:`EXPORT_SAMPLES` values of :math:`\\mu = \\cos\\theta`
in the coating, evenly over [0, 1]. For a material given only as per-channel
n, k (an ``rgb-conductor`` fit, linear ACEScg) the target is that model's
curve at eta_i, and for a fit made from edited curves the fit's own model
curve. Each value is a per-channel least-squares fit to T:

-   relative index :math:`(n_c + i k_c)` of an exact conductor in air
    (MaterialX ``conductor_bsdf``, Blender Metallic BSDF "Physical
    Conductor"): :math:`\\min \\sum_s (F(\\mu_s; n_c + i k_c) - T_c(\\mu_s))^2`;
-   F0 and F82 tint of the F82-tint model (OpenPBR ``base_color`` and
    ``specular_color``, Blender Principled ``Base Color`` and ``Specular
    Tint``), both in [0, 1];
-   F0 of Schlick's approximation (glTF ``baseColorFactor``), closed form.

-   :data:`EXPORT_SAMPLES`, :data:`ETA_I_LIMITS`
-   :class:`ExportValues`: the fitted values and their provenance.
-   :func:`export_values`: computes them.
-   :func:`project_version`.

References
----------
Hoffman, N. (2023). Generalization of Adobe's Fresnel Model (F82 tint).
Kutz, P., Hasan, M., & Edmondson, P. (2021). Novel aspects of the Adobe
Standard Material.
Andersson, A. et al. (2024). OpenPBR Surface Specification, metal base.
"""

from __future__ import annotations

import functools
import importlib.metadata
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from ..colour.reference import reference_ACEScg
from ..domain import ETA_I_MAX, ETA_I_MIN, check_eta_i, check_number
from ..models.pack import PackedMaterial
from ..models.rgb_conductor import rgb_fresnel_conductor
from ..optics.fresnel import fresnel_conductor
from ..optics.nk import SpectralNK
from .colour_space import ACEScg_to_lin_rec709
from .tool_fresnel import f82_tint, schlick

__all__ = [
    "EXPORT_SAMPLES",
    "ETA_I_LIMITS",
    "ExportValues",
    "export_values",
    "project_version",
    "check_roughness",
]

EXPORT_SAMPLES = 100
"""Values of cos theta in the coating, evenly over [0, 1], fitted and scored."""

ETA_I_LIMITS = (ETA_I_MIN, ETA_I_MAX)
"""Accepted coating indices (the project's rule, :func:`fitting.domain.check_eta_i`)."""

# Per-channel relative index bounds: n > 0 as for any conductor; above every
# library conductor divided by eta_i >= 1 (n < 5, k < 12 in 360-830 nm).
_N_BOUNDS = (1.0e-3, 20.0)
_K_BOUNDS = (0.0, 50.0)


@functools.cache
def project_version() -> str:
    """This project's version: the installed ``coated-fresnel``, else pyproject.toml's."""
    try:
        return importlib.metadata.version("coated-fresnel")
    except importlib.metadata.PackageNotFoundError:
        pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
        try:
            return str(tomllib.loads(pyproject.read_text())["project"]["version"])
        except (OSError, KeyError, tomllib.TOMLDecodeError):
            return "unknown"


def check_roughness(name: str, value) -> float:
    """A perceptual roughness in [0, 1], else ``ValueError`` naming ``name``."""
    return check_number(name, value, 0.0, 1.0)


@dataclass(frozen=True)
class ExportValues:
    """
    What an export is made of, all colours linear Rec.709.

    Attributes
    ----------
    name, source
        Material name and the citation of its data.
    eta_i
        Coating index the values are for.
    origin
        How the target curve was obtained (spectral reference or model curve).
    cos_theta
        The :data:`EXPORT_SAMPLES` values of mu in the coating.
    target
        T(mu), shape (EXPORT_SAMPLES, 3), linear Rec.709.
    target_ACEScg
        The same in linear ACEScg (what the fidelity is scored against).
    n_rel, k_rel
        Per-channel relative index (n + i k) / eta_i, shape (3,).
    F0, F82_tint
        F82-tint model values, shape (3,) each, in [0, 1].
    F0_schlick
        Schlick F0, shape (3,), in [0, 1].
    roughness, coat_roughness
        Perceptual roughness of the metal and of the coat, [0, 1].
    model
        The fit's own float16 model (:class:`fitting.models.pack.PackedMaterial`),
        when the export carries it as well as the tool's values (glTF's
        ``EXT_materials_coated_conductor``); ``None`` otherwise.
    """

    name: str
    source: str
    eta_i: float
    origin: str
    cos_theta: np.ndarray
    target: np.ndarray
    target_ACEScg: np.ndarray
    n_rel: np.ndarray
    k_rel: np.ndarray
    F0: np.ndarray
    F82_tint: np.ndarray
    F0_schlick: np.ndarray
    roughness: float = 0.2
    coat_roughness: float = 0.03
    model: PackedMaterial | None = None
    version: str = field(default_factory=project_version)

    def provenance(self, model_kind: str, fidelity: dict | None = None) -> dict:
        """
        What the export was made from, for a comment or ``extras``: material,
        source (one line), eta_i, model kind, what was fitted, colour space,
        generator and version, and the export's Delta E 2000 under the coat
        (``fidelity``, from :func:`fitting.exports.tool_fresnel.export_fidelity`).
        """
        info = {
            "material": self.name,
            "source": " ".join(self.source.split()),
            "eta_i": self.eta_i,
            "model_kind": model_kind,
            "fitted_to": self.origin,
            "colour_space": "lin_rec709",
            "generator": f"coated-fresnel {self.version}",
        }
        if fidelity is not None:
            info["delta_E_2000_under_coat"] = (
                f"mean {fidelity['delta_E_mean']:.3f}, max {fidelity['delta_E_max']:.3f}"
            )
        return info


def _fit_relative_index(mu: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n_out, k_out = np.empty(3), np.empty(3)
    lo, hi = [_N_BOUNDS[0], _K_BOUNDS[0]], [_N_BOUNDS[1], _K_BOUNDS[1]]
    for c in range(3):
        R = T[:, c]
        # At normal incidence with n = 1, R = k^2 / (4 + k^2): a start from F0.
        F0 = float(np.clip(R[-1], 0.0, 0.999))
        x0 = np.clip([1.0, np.sqrt(4.0 * F0 / (1.0 - F0))], lo, hi)
        fit = least_squares(
            lambda x: fresnel_conductor(mu, 1.0, x[0], x[1]) - R, x0, bounds=(lo, hi),
            method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12,
        )
        n_out[c], k_out[c] = fit.x
    return n_out, k_out


def _fit_f82_tint(mu: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    F0, tint = np.empty(3), np.empty(3)
    for c in range(3):
        R = T[:, c]
        x0 = np.clip([R[-1], 1.0], 0.0, 1.0)
        fit = least_squares(
            lambda x: f82_tint(mu, x[0], x[1]) - R, x0, bounds=([0.0, 0.0], [1.0, 1.0]),
            method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12,
        )
        F0[c], tint[c] = fit.x
    return F0, tint


def _fit_schlick(mu: np.ndarray, T: np.ndarray) -> np.ndarray:
    # Schlick is linear in F0: F - w = F0 (1 - w) with w = (1 - mu)^5.
    w = schlick(mu, 0.0)[:, None]
    F0 = np.sum((1.0 - w) * (T - w), axis=0) / np.sum((1.0 - w) ** 2)
    return np.clip(F0, 0.0, 1.0)


def export_values(
    fit_or_nk, eta_i, roughness: float = 0.2, coat_roughness: float = 0.03,
    model: PackedMaterial | None = None,
) -> ExportValues:
    """
    The values of every export of a material at one coating index.

    Parameters
    ----------
    fit_or_nk
        A :class:`fitting.optics.nk.SpectralNK` (measured n, k: the target is the
        1 nm spectral reference), or a mapping ``{"name", "source", "n",
        "k"}`` with per-channel n, k in linear ACEScg (an ``rgb-conductor``
        fit: the target is its exact Fresnel curve of (n + i k) / eta_i), or
        a mapping ``{"name", "source", "reflectance", "origin"}`` whose
        ``reflectance(cos_theta, eta_i)`` gives a fitted model's linear ACEScg
        curve (a fit made from edited curves: the target is that curve).
    eta_i
        Coating index, in [1, 3].
    roughness, coat_roughness
        Perceptual roughness of the metal and the coat, [0, 1].
    model
        The fit's float16 model, carried as is (:attr:`ExportValues.model`).

    Raises
    ------
    ValueError
        For eta_i or a roughness outside its range, an input of another
        type, ``model`` not a ``PackedMaterial``, or n, k covering too little
        of 360-830 nm.
    """
    eta = check_eta_i(eta_i)
    roughness = check_roughness("roughness", roughness)
    coat_roughness = check_roughness("coat_roughness", coat_roughness)
    if model is not None and not isinstance(model, PackedMaterial):
        raise ValueError(f"`model` must be a PackedMaterial or None, got {type(model).__name__}")
    mu = np.linspace(0.0, 1.0, EXPORT_SAMPLES)
    if isinstance(fit_or_nk, SpectralNK):
        name, source = fit_or_nk.name, fit_or_nk.source
        target_ACEScg = reference_ACEScg(fit_or_nk, mu, eta, 1.0)
        origin = f"spectral reference under the coat, 1 nm, {EXPORT_SAMPLES} cos theta"
    elif isinstance(fit_or_nk, dict) and callable(fit_or_nk.get("reflectance")):
        name = str(fit_or_nk.get("name", "material"))
        source = str(fit_or_nk.get("source", ""))
        target_ACEScg = np.asarray(fit_or_nk["reflectance"](mu, eta), dtype=np.float64)
        if target_ACEScg.shape != (EXPORT_SAMPLES, 3) or not np.all(np.isfinite(target_ACEScg)):
            raise ValueError(
                f"`fit_or_nk['reflectance']` must give finite ({EXPORT_SAMPLES}, 3) RGB, "
                f"got shape {target_ACEScg.shape}"
            )
        origin = str(fit_or_nk.get("origin", "the fit's model curve under the coat"))
    elif isinstance(fit_or_nk, dict) and {"n", "k"} <= set(fit_or_nk):
        name = str(fit_or_nk.get("name", "material"))
        source = str(fit_or_nk.get("source", ""))
        target_ACEScg = rgb_fresnel_conductor(mu, eta, fit_or_nk["n"], fit_or_nk["k"])
        origin = f"rgb-conductor model curve under the coat, {EXPORT_SAMPLES} cos theta"
    else:
        raise ValueError(
            "`fit_or_nk` must be a SpectralNK or a mapping with per-channel `n` and `k` "
            "or a `reflectance` function, "
            f"got {type(fit_or_nk).__name__}"
        )
    target = ACEScg_to_lin_rec709(target_ACEScg)
    n_rel, k_rel = _fit_relative_index(mu, target)
    F0, tint = _fit_f82_tint(mu, target)
    return ExportValues(
        name=name, source=source, eta_i=eta, origin=origin, cos_theta=mu, target=target,
        target_ACEScg=target_ACEScg, n_rel=n_rel, k_rel=k_rel, F0=F0, F82_tint=tint,
        F0_schlick=_fit_schlick(mu, target), roughness=roughness, coat_roughness=coat_roughness,
        model=model,
    )
