"""
Pack downloads
==============

Stored fits as the files a renderer loads:

-   ``binary``: the documented binary pack (:func:`fitting.models.pack.encode_pack`).
-   ``json``: its JSON view (:func:`fitting.models.pack.pack_to_json`).
-   ``glsl``, ``hlsl``: ready-to-paste snippets (:mod:`fitting.exports.snippets`):
    the project's function of each model kind in the pack and per material
    its float16 coefficients and a ``cf_material_<name>(NdotV, eta_i)``.

Exports of one fit for one coating index (:mod:`fitting.exports`), made
from the fit's measured n, k, or for a fit of edited curves from its model:

-   ``mtlx``, ``openpbr``: MaterialX documents; ``blender``: a Blender
    Python script; ``gltf``: a glTF 2.0 asset.

-   :data:`PACK_MEDIA_TYPES`: media type and file suffix per format.
-   :func:`is_export`: whether a format is an export (of the registry,
    :data:`fitting.exports.EXPORT_FORMATS`, which has their media types and suffixes).
-   :func:`render_pack`: the bytes of a download.
-   :func:`render_export`: the bytes of an export of one fit (each fits its
    tool's values, up to about a second of CPU: the routes run it, and
    :func:`render_export_pack`, in the fitting pool's workers).
-   :func:`kept_export`, :func:`export_key`: :func:`render_export` as a job
    of the fitting pool, kept in the service's :class:`service.derived.DerivedCache`
    (a fit never changes: a repeated download costs a lookup).
-   :func:`download_name`: a safe file name for Content-Disposition.
-   :func:`glsl_identifier`: a material name as a GLSL/HLSL identifier.
"""

from __future__ import annotations

import io
import re
import zipfile

from fitting.domain import cached_once
from fitting.exports import EXPORT_FORMATS, export_format, export_material
from fitting.exports.snippets import TEMPLATE_DIR, SnippetMaterial, glsl_identifier, snippet
from fitting.fits.metrics import headline
from fitting.models.kinds import model_ACEScg
from fitting.models.pack import PackedMaterial, encode_pack, material_from_json
from fitting.models.pack import pack_to_json

from .jobs.common import FIT_FORMAT_VERSION, measured_nk, stored_fit
from .store import FitRecord

__all__ = [
    "PACK_MEDIA_TYPES",
    "is_export",
    "PACK_CONTENT",
    "TEMPLATE_DIR",
    "render_pack",
    "render_export",
    "export_key",
    "kept_export",
    "export_download",
    "render_export_pack",
    "pack_response",
    "export_response",
    "download_name",
    "unique_names",
    "glsl_identifier",
    "IBL_LUT_FILENAME",
    "ibl_lut_file",
]

IBL_LUT_FILENAME = "cf_ibl_lut.cflut"
PACK_MEDIA_TYPES = {
    "binary": ("application/octet-stream", "cfpk"),
    "json": ("application/json", "json"),
    "glsl": ("text/plain; charset=utf-8", "glsl"),
    "hlsl": ("text/plain; charset=utf-8", "hlsl"),
}


def is_export(format: str) -> bool:
    """Whether ``format`` is a registered export format (one coating index) rather than a pack format."""
    return format in EXPORT_FORMATS


@cached_once
def ibl_lut_file() -> bytes:
    """The default split-sum LUT as its file (:func:`fitting.shading.lut.encode_lut`),
    from the on-disk cache, once per process."""
    from fitting.shading.lut import default_lut, encode_lut

    return encode_lut(default_lut())


def render_pack(records: list[FitRecord], format: str, pack_name: str) -> bytes:
    """
    The download of ``records`` in ``format`` (one of :data:`PACK_MEDIA_TYPES`).

    Raises
    ------
    ValueError
        For an unknown format or an empty list.
    """
    if format not in PACK_MEDIA_TYPES:
        raise ValueError(f"`format` must be one of {', '.join(PACK_MEDIA_TYPES)}, got {format!r}")
    if not records:
        raise ValueError("`fit_ids` must name at least one fit")
    if format == "binary":
        return encode_pack([material_from_json(r.material) for r in records])
    if format == "json":
        materials = []
        for record in records:
            view = material_from_json(record.material)
            materials.append(
                PackedMaterial(
                    view.name,
                    view.coefficients,
                    view.eta_i_range,
                    view.source,
                    model=view.model,
                    metrics={
                        "fit_id": record.id,
                        **{
                            key: record.metrics[key]
                            for key in ("figure", "grid", "model_float16", "lazanyi_adjusted")
                            if key in record.metrics
                        },
                    },
                )
            )
        return pack_to_json(materials).encode("utf-8")
    materials = [
        SnippetMaterial(r.name, r.source, r.id, headline(r.metrics), material_from_json(r.material)) for r in records
    ]
    return snippet(format, materials, pack_name, FIT_FORMAT_VERSION).encode("utf-8")


def render_export(
    record: FitRecord, format: str, eta_i: float, roughness=0.2, coat_roughness=0.03, working_space: str = "lin_rec709"
) -> bytes:
    """
    The export of one stored fit in ``format`` (one of
    :data:`fitting.exports.EXPORT_FORMATS`) for the coating index ``eta_i`` and
    roughnesses, fitted and written in ``working_space``, named by and
    carrying the fit's id (:mod:`fitting.exports.naming`).

    A fit of measured n, k is exported from them (the spectral reference
    under the coat); a fit made from edited curves from its own float16
    model curve, which it defines only on its eta_i domain. The fit's
    float16 model travels too (glTF: ``EXT_materials_coated_conductor``).

    Raises
    ------
    ValueError
        For an unknown format, eta_i outside [1, 3], or, for a curve fit,
        eta_i outside the fit's domain.
    """
    packed = material_from_json(record.material)
    if record.kind != "curves":
        nk = measured_nk(record)
        if nk is not None:
            return export_material(
                nk,
                format,
                eta_i,
                roughness,
                coat_roughness,
                model=packed,
                fit_id=record.id,
                working_space=working_space,
            )
    lo, hi = packed.eta_i_range
    if not lo <= eta_i <= hi:
        raise ValueError(
            f"`eta_i` must lie in the fit's domain [{lo:g}, {hi:g}] for an export of a fit "
            f"made from curves, got {eta_i:g}"
        )
    model = {
        "name": record.name,
        "source": record.source,
        "origin": f"float16 model curve of fit {record.id} (edited curves) under the coat",
        "reflectance": lambda mu, eta: model_ACEScg(packed.model, mu, eta, packed.coefficients, packed.eta_i_range),
    }
    return export_material(
        model, format, eta_i, roughness, coat_roughness, model=packed, fit_id=record.id, working_space=working_space
    )


def export_key(
    fit_id: str, format: str, eta_i: float, roughness: float, coat_roughness: float, working_space: str = "lin_rec709"
) -> str:
    """The key of one export of a fit (:func:`kept_export`)."""
    return f"export {fit_id} {format} {eta_i!r} {roughness!r} {coat_roughness!r} {working_space}"


async def kept_export(
    cache,
    runner,
    record: FitRecord,
    format: str,
    eta_i: float,
    roughness: float,
    coat_roughness: float,
    working_space: str = "lin_rec709",
) -> tuple[str, bytes]:
    """
    ``(record.name, render_export(...))`` of ``record``, made in
    ``runner``'s pool (its CPU limit and time limit; identical requests
    share one job) and kept in ``cache`` (:class:`service.derived.DerivedCache`)
    by :func:`export_key`: a later download is answered from it without
    reading the store.
    """
    key = export_key(record.id, format, eta_i, roughness, coat_roughness, working_space)

    async def make() -> tuple[str, bytes]:
        body = await runner.run(
            render_export, record, format, eta_i, roughness, coat_roughness, working_space, cost_s=1.0
        )
        return record.name, body

    return await cache.get_or_make(key, lambda: runner.once(key, make))


async def export_download(
    cache,
    store,
    runner,
    fit_id: str,
    format: str,
    eta_i: float,
    roughness: float,
    coat_roughness: float,
    working_space: str = "lin_rec709",
):
    """
    The download of one export of the stored fit ``fit_id``: from ``cache``
    when it was made before (without reading the store), else made by
    :func:`kept_export` (a job of the fitting pool, up to about a second of
    CPU) and kept: a fit never changes. ``LookupError`` (404) when no such
    fit is stored.
    """
    from fastapi.concurrency import run_in_threadpool

    kept = cache.get(export_key(fit_id, format, eta_i, roughness, coat_roughness, working_space))
    if kept is None:
        record = await run_in_threadpool(stored_fit, store, fit_id)
        kept = await kept_export(cache, runner, record, format, eta_i, roughness, coat_roughness, working_space)
    return export_response(kept[1], format, eta_i, f"{kept[0]}-{fit_id[:8]}", roughness, coat_roughness, working_space)


def render_export_pack(
    records: list[FitRecord],
    format: str,
    eta_i: float,
    roughness=0.2,
    coat_roughness=0.03,
    working_space: str = "lin_rec709",
) -> bytes:
    """
    The exports of several fits for one ``eta_i``, roughnesses and working
    space (:func:`render_export`): a zip archive with one
    ``<name>-eta<eta_i>.<suffix>`` per fit, in order, byte-for-byte
    deterministic (fixed time stamps), so the same request gives the same
    archive. Entry names are unique (:func:`unique_names`), so that no
    material overwrites another when the archive is unpacked.
    """
    buffer = io.BytesIO()
    names = unique_names([download_name(f"{record.name}-eta{eta_i:g}", format) for record in records])
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for record, name in zip(records, names):
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, render_export(record, format, eta_i, roughness, coat_roughness, working_space))
    return buffer.getvalue()


def unique_names(names: list[str]) -> list[str]:
    """``names``, each that repeats an earlier one ignoring case (``gold alloy`` and ``gold_alloy``
    both make ``gold_alloy``; a case-insensitive disk unpacks ``Gold`` over ``gold``) with ``-2``, ... added."""
    seen: set[str] = set()
    out = []
    for name in names:
        stem, dot, suffix = name.rpartition(".")
        candidate, k = name, 1
        while candidate.lower() in seen:
            k += 1
            candidate = f"{stem}-{k}{dot}{suffix}"
        seen.add(candidate.lower())
        out.append(candidate)
    return out


def download_name(stem: str, format: str) -> str:
    """``<stem>.<suffix>`` with only [A-Za-z0-9._-] in the stem (a safe header value)."""
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", stem).strip("._") or "material"
    suffix = PACK_MEDIA_TYPES[format][1] if format in PACK_MEDIA_TYPES else export_format(format).extension
    return f"{safe[:80]}.{suffix}"


def pack_response(records: list[FitRecord], format: str, stem: str):
    """A download with its media type and Content-Disposition file name."""
    from fastapi import Response

    body = render_pack(records, format, stem)
    media_type, _ = PACK_MEDIA_TYPES[format]
    return Response(
        body,
        media_type=media_type,
        headers={"Content-Disposition": f'attachment; filename="{download_name(stem, format)}"'},
    )


def export_response(
    body: bytes,
    format: str,
    eta_i: float,
    stem: str,
    roughness=0.2,
    coat_roughness=0.03,
    working_space: str = "lin_rec709",
):
    """
    An export's bytes (:func:`render_export`) as a download named for
    ``eta_i``, the roughnesses and (when not ``lin_rec709``) the working space.
    """
    from fastapi import Response

    stem = f"{stem}-eta{eta_i:g}-rough{roughness:g}-coat{coat_roughness:g}"
    if working_space != "lin_rec709":
        stem += f"-{working_space}"
    return Response(
        body,
        media_type=export_format(format).media_type,
        headers={"Content-Disposition": f'attachment; filename="{download_name(stem, format)}"'},
    )


PACK_CONTENT = {
    "application/octet-stream": {"schema": {"type": "string", "format": "binary"}},
    "application/json": {"schema": {"type": "object"}},
    "text/plain": {"schema": {"type": "string"}},
    "application/xml": {"schema": {"type": "string"}},
    "text/x-python": {"schema": {"type": "string"}},
    "model/gltf+json": {"schema": {"type": "object"}},
    "model/gltf-binary": {"schema": {"type": "string", "format": "binary"}},
    "application/zip": {"schema": {"type": "string", "format": "binary"}},
}
"""The OpenAPI content of a download."""
