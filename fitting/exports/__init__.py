"""
Exports
=======

A coated metal as the documents the tools users already have take, each for
one coating index eta_i, each saying what it was made from:

-   ``mtlx``: MaterialX, ``conductor_bsdf`` at the relative index under a
    ``dielectric_bsdf`` coat (:mod:`fitting.exports.mtlx`);
-   ``openpbr``: MaterialX ``open_pbr_surface``, F0 and F82 tint fitted under
    the coat (:mod:`fitting.exports.openpbr`);
-   ``blender``: a Blender Python script, Principled BSDF with coat and a
    Metallic BSDF in Physical Conductor mode (:mod:`fitting.exports.blender`);
-   ``gltf``: glTF 2.0 with ``KHR_materials_clearcoat`` and a sphere
    (:mod:`fitting.exports.gltf`), and the model itself in
    ``EXT_materials_coated_conductor`` (:mod:`fitting.exports.gltf_coated`).

The values come from :mod:`fitting.exports.values`: each fitted so that the
tool's own layering of its coat over its base
(:mod:`fitting.exports.tool_layering`) follows the physical coat on the
metal seen from air (:mod:`fitting.exports.seen_fit`,
:func:`fitting.colour.seen.seen_ACEScg`); at eta_i 1 no export has a coat.
:mod:`fitting.exports.tool_fresnel` has the tools' base Fresnel terms and
the earlier (naive) fidelity under the coat.

-   :data:`EXPORT_FORMATS`: the registry of formats (:mod:`fitting.exports.formats`).
-   :func:`export_material`: the document of a material in a format.
"""

from __future__ import annotations

from .formats import (EXPORT_FORMATS, ExportFormat, export_format, register_export_format,
                      unregister_export_format)
from .seen_fit import seen_fidelity
from .tool_fresnel import TOOL_MODELS, export_fidelity, tool_curve
from ..domain import check_eta_i
from .values import ETA_I_LIMITS, ExportValues, export_values

__all__ = [
    "EXPORT_FORMATS",
    "ExportFormat",
    "register_export_format",
    "unregister_export_format",
    "export_format",
    "ETA_I_LIMITS",
    "ExportValues",
    "TOOL_MODELS",
    "check_format",
    "export_fidelity",
    "seen_fidelity",
    "export_material",
    "export_values",
    "tool_curve",
]

def check_format(format: str) -> str:
    """``format`` if it is one of :data:`EXPORT_FORMATS`, else ``ValueError``."""
    return export_format(format).name


def export_material(
    fit_or_nk, format: str, eta_i, roughness: float = 0.2, coat_roughness: float = 0.03,
    model=None,
) -> bytes:
    """
    The export of a material for one coating index, as UTF-8 bytes.

    Parameters
    ----------
    fit_or_nk
        Measured n, k (:class:`fitting.optics.nk.SpectralNK`), a mapping
        ``{"name", "source", "n", "k"}`` of per-channel n, k (an
        ``rgb-conductor`` fit, linear ACEScg), a mapping with a
        ``reflectance(cos_theta, eta_i)`` model curve (see
        :func:`export_values`), or :class:`ExportValues` already computed
        (then ``eta_i`` must be theirs).
    format
        One of :data:`EXPORT_FORMATS`.
    eta_i
        Coating index, [1, 3].
    roughness, coat_roughness
        Perceptual roughness of the metal and the coat, [0, 1].
    model
        The fit's float16 model (:class:`fitting.models.pack.PackedMaterial`),
        or ``None``: the glTF export then also carries it in
        ``EXT_materials_coated_conductor`` (:mod:`fitting.exports.gltf_coated`).

    Raises
    ------
    ValueError
        For an unknown format, eta_i outside [1, 3], a roughness outside
        [0, 1], or unusable n, k; the message names the argument.
    """
    writer = export_format(format)
    eta = check_eta_i(eta_i)
    if isinstance(fit_or_nk, ExportValues):
        if abs(fit_or_nk.eta_i - eta) > 1e-12:
            raise ValueError(
                f"`eta_i` must be the values' own {fit_or_nk.eta_i:g} for ExportValues, got {eta_i}"
            )
        values = fit_or_nk
        missing = [tool for tool in writer.tools if tool not in values.tools]
        if missing:
            raise ValueError(
                f"`fit_or_nk` must carry the fitted values of {', '.join(missing)} for a "
                f"{format} export (export_values(..., tools=None) fits them all)"
            )
    else:
        values = export_values(fit_or_nk, eta, roughness, coat_roughness, model, writer.tools)
    return writer.document(values)
