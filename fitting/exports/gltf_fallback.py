"""
The glTF fallback on a rough metal, and the coat it keeps
=========================================================

A viewer without ``EXT_materials_coated_conductor`` draws the glTF export's
fallback: three.js's ``MeshPhysicalMaterial`` (metallic base of the
``baseColorFactor`` under its GGX at the material's ``roughnessFactor``,
``KHR_materials_clearcoat`` over it,
:func:`fitting.exports.tool_layering.three_clearcoat`). The glTF fit
(:func:`fitting.exports.seen_fit.fit_tool_values`) follows what the user sees
at roughness 0 **and** at the material's roughness, with a smooth coat:

-   :func:`rough_seen_ACEScg`: the coated metal seen from air at a metal
    roughness r under a smooth coat, for image-based light (a white sky):
    the seen target at roughness 0 (the spectral stack,
    :func:`fitting.colour.seen.seen_ACEScg`) plus the change that roughness
    makes to the light through the coat,
    :math:`S_r(\\mu) - S_0(\\mu)` of :func:`fitting.shading.coated_layer.seen_base`
    (the metal's GGX lobe at the in-coat cosine through the coat, with its
    bounces and total internal reflection), evaluated on the metal's own
    curve under the coat (the export's target, linear ACEScg, per channel).
    The coat's own reflection is the same at every metal roughness, so it
    cancels in the change. At r = 0 it is the seen target exactly. The
    change is taken at :data:`ROUGH_NODES` view cosines evenly spaced from
    the export's most grazing one to 1 and interpolated linearly in the
    cosine (measured against every angle's own: at most 0.12 Delta E 2000 on
    Cu, Ag, W at eta_i 1.33 and 2, roughness 0.3; a sixth of the time).
-   :data:`GLTF_COAT_FACTOR`: the ``clearcoatFactor`` the export writes
    wherever there is a coat (eta_i > 1): 1, the coat's weight, which
    ``EXT_materials_coated_conductor`` composes with (the coat's factor,
    roughness and index are glTF's, not the extension's). The fit is then of
    the base colour alone, and a coated metal reads as coated in a viewer
    without the plugin: its factor is above 0.5 wherever the physical coat's
    own reflectance at normal incidence, :func:`coat_F0`, is at least
    :data:`VISIBLE_COAT_F0` (2 %, eta_i >= 1.33), and everywhere else too.
-   :func:`gltf_seen_delta_E`: Delta E 2000 per angle of glTF values drawn
    by three at a metal roughness, against :func:`rough_seen_ACEScg`.
"""

from __future__ import annotations

import numpy as np

from ..colour.delta_e import delta_E_map
from ..shading.coated_layer import seen_base
from .colour_space import DEFAULT_WORKING_SPACE, working_to_ACEScg
from .tool_layering import three_clearcoat

__all__ = ["ROUGH_NODES", "VISIBLE_COAT_F0", "GLTF_COAT_FACTOR", "coat_F0", "rough_seen_ACEScg", "gltf_seen_delta_E"]

VISIBLE_COAT_F0 = 0.02
"""The coat's own reflectance at normal incidence from which the coat is visible (eta_i about 1.33)."""
ROUGH_NODES = 16
"""View cosines at which :func:`rough_seen_ACEScg` evaluates the rough lobe."""
GLTF_COAT_FACTOR = 1.0
"""The ``clearcoatFactor`` of a coat: its weight, composed with the extension (not fitted)."""


def coat_F0(eta: float) -> float:
    """The coat's own reflectance at normal incidence from air, ((eta - 1)/(eta + 1))^2."""
    return ((float(eta) - 1.0) / (float(eta) + 1.0)) ** 2


def _curve(cos_model, model_ACEScg):
    """The metal's curve under the coat as a Fresnel function of the in-coat cosine, (..., 3)."""
    mu = np.asarray(cos_model, dtype=np.float64)
    order = np.argsort(mu)
    mu, T = mu[order], np.asarray(model_ACEScg, dtype=np.float64)[order]

    def fresnel(c):
        c = np.asarray(c, dtype=np.float64)
        return np.stack([np.interp(c, mu, T[:, ch]) for ch in range(3)], axis=-1)

    return fresnel


def rough_seen_ACEScg(
    view_cos, eta: float, seen_ACEScg, cos_model, model_ACEScg, roughness: float, rough_nodes: int | None = ROUGH_NODES
) -> np.ndarray:
    """
    The coated metal seen from air at view cosines ``view_cos`` (S,) with a
    metal of perceptual ``roughness`` under a smooth coat of index ``eta``,
    linear ACEScg (S, 3): ``seen_ACEScg`` (the smooth stack at those
    cosines) plus :math:`S_r - S_0` of the metal's curve under the coat
    (``model_ACEScg`` at in-coat cosines ``cos_model``), at least 0;
    ``rough_nodes`` view cosines interpolated (``None``: at every one).
    """
    seen = np.asarray(seen_ACEScg, dtype=np.float64)
    if roughness <= 0.0 or eta <= 1.0:
        return seen
    view = np.asarray(view_cos, dtype=np.float64)
    fresnel = _curve(cos_model, model_ACEScg)
    nodes = view if rough_nodes is None else np.linspace(float(view.min()), 1.0, int(rough_nodes))
    change = seen_base(nodes, eta, float(roughness), fresnel) - seen_base(nodes, eta, 0.0, fresnel)
    if rough_nodes is not None:
        change = np.stack([np.interp(view, nodes, change[:, ch]) for ch in range(3)], axis=-1)
    return np.maximum(seen + change, 0.0)


def gltf_seen_delta_E(
    values: dict, view_cos, eta: float, target_ACEScg, roughness: float = 0.0, space: str = DEFAULT_WORKING_SPACE
) -> np.ndarray:
    """
    Delta E 2000 per angle of the glTF ``values`` (``base_color``,
    ``clearcoat``, ``coat``, in the working space ``space``) drawn by three
    at metal ``roughness`` with a smooth coat, against ``target_ACEScg``
    (:func:`rough_seen_ACEScg` at that roughness).
    """
    rgb = three_clearcoat(
        view_cos,
        values["base_color"],
        values.get("clearcoat", 1.0),
        bool(values.get("coat", eta > 1.0)),
        roughness=roughness,
    )
    return delta_E_map(target_ACEScg, working_to_ACEScg(rgb, space))
