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
    ``EXT_materials_coated_conductor`` (:mod:`fitting.exports.gltf_coated`);
    ``glb``: the same asset as binary glTF.

Each carries the fit's float16 model, read back by :mod:`fitting.exports.readback`.

The values come from :mod:`fitting.exports.values`: each fitted so that the
tool's own layering of its coat over its base
(:mod:`fitting.exports.tool_layering`) follows the physical coat on the
metal seen from air (:mod:`fitting.exports.seen_fit`,
:func:`fitting.colour.seen.seen_ACEScg`); at eta_i 1 no export has a coat.
:mod:`fitting.exports.tool_fresnel` has the tools' base Fresnel terms and
the earlier (naive) fidelity under the coat.

Every export is named and carries its identity through
:mod:`fitting.exports.naming` (unique per fit and coat index), and is fitted
and written in one working space (:data:`WORKING_SPACES`).

-   :data:`EXPORT_FORMATS`: the registry of formats (:mod:`fitting.exports.formats`).
-   :func:`export_material`: the document of a material in a format.
"""

from __future__ import annotations

from .formats import EXPORT_FORMATS, ExportFormat, export_format, register_export_format, unregister_export_format
from .colour_space import DEFAULT_WORKING_SPACE, WORKING_SPACES, check_working_space
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
    "WORKING_SPACES",
    "DEFAULT_WORKING_SPACE",
    "check_working_space",
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
    fit_or_nk,
    format: str,
    eta_i,
    roughness: float = 0.2,
    coat_roughness: float = 0.03,
    model=None,
    fit_id: str | None = None,
    working_space: str | None = None,
) -> bytes:
    """
    The export of a material for one coating index, as bytes (UTF-8 text but for ``glb``).

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
    fit_id
        The stored fit's id (32 lower-case hex digits) the export carries
        and is named by; ``None``: a content address of the material.
    working_space
        ``lin_rec709`` or ``acescg`` (:data:`WORKING_SPACES`): the space the
        values are fitted and written in; ``None``: ``lin_rec709``, or for
        :class:`ExportValues` their own.

    Raises
    ------
    ValueError
        For an unknown format, eta_i outside [1, 3], a roughness outside
        [0, 1], an unknown working space, a fit id that is not 32 hex
        digits, or unusable n, k; the message names the argument.
    """
    writer = export_format(format)
    eta = check_eta_i(eta_i)
    if isinstance(fit_or_nk, ExportValues):
        if abs(fit_or_nk.eta_i - eta) > 1e-12:
            raise ValueError(f"`eta_i` must be the values' own {fit_or_nk.eta_i:g} for ExportValues, got {eta_i}")
        values = fit_or_nk
        if working_space is not None and check_working_space(working_space) != values.working_space:
            raise ValueError(
                f"`working_space` must be the values' own {values.working_space!r} for "
                f"ExportValues, got {working_space!r}"
            )
        missing = [tool for tool in writer.tools if tool not in values.tools]
        if missing:
            raise ValueError(
                f"`fit_or_nk` must carry the fitted values of {', '.join(missing)} for a "
                f"{format} export (export_values(..., tools=None) fits them all)"
            )
    else:
        values = export_values(
            fit_or_nk,
            eta,
            roughness,
            coat_roughness,
            model,
            writer.tools,
            fit_id=fit_id,
            working_space=working_space or DEFAULT_WORKING_SPACE,
        )
    return writer.document(values)
