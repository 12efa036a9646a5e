"""
Export formats
==============

The registry of export formats, as ``fitting.models.kinds`` is of model
kinds: one :class:`ExportFormat` per format (its name, media type, file
extension, the tools whose fitted values it carries, its writer and the
options it takes), from which every list of formats is derived: the CLI's
``--export`` choices, the REST API's ``format`` values (``GET
/api/v1/fits/{id}/pack``, ``POST /api/v1/packs``), ``GET /api/v1/domain``
and so the editor's download menu. No other module names a format.

-   :class:`ExportFormat`: one format.
-   :data:`EXPORT_FORMATS`: name -> :class:`ExportFormat`, in registration order.
-   :func:`register_export_format`, :func:`unregister_export_format`.
-   :func:`export_format`: a format by name (``ValueError`` naming ``format``).
-   :func:`describe_export_formats`: the registry as JSON for clients.

Adding a format is one module that writes the document from
:class:`fitting.exports.values.ExportValues` and calls
:func:`register_export_format` when imported; the service and the CLI load
such a module named in ``COATED_PLUGINS`` at their start
(:mod:`fitting.cli.plugins`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from .blender import blender_script
from .gltf import glb_document, gltf_document
from .mtlx import mtlx_document
from .openpbr import openpbr_document
from .values import ExportValues

__all__ = [
    "ExportFormat",
    "EXPORT_FORMATS",
    "EXPORT_OPTIONS",
    "register_export_format",
    "unregister_export_format",
    "export_format",
    "describe_export_formats",
]

EXPORT_OPTIONS = ("eta_i", "roughness", "coat_roughness", "working_space")
"""The options every export takes: the coating index, the two perceptual roughnesses and the
working space it is fitted and written in (:mod:`fitting.exports.colour_space`)."""


@dataclass(frozen=True)
class ExportFormat:
    """
    One export format.

    Attributes
    ----------
    name
        The format's name in every interface (``--export NAME``, ``?format=NAME``).
    label
        What a menu shows, with the file extension ("MaterialX, conductor under a coat (.mtlx)").
    media_type
        The HTTP ``Content-Type`` of the document.
    extension
        The file name's suffix, without the leading dot (``openpbr.mtlx``).
    tools
        The tools whose fitted values the writer reads (``fitting.exports.tool_layering``).
    write
        ``ExportValues -> str | bytes``: the document (text is written as UTF-8).
    options
        The options it takes, of :data:`EXPORT_OPTIONS`.
    """

    name: str
    label: str
    media_type: str
    extension: str
    tools: tuple[str, ...]
    write: Callable[[ExportValues], str | bytes]
    options: tuple[str, ...] = EXPORT_OPTIONS

    def document(self, values: ExportValues) -> bytes:
        """The document of ``values`` as bytes."""
        out = self.write(values)
        return out.encode("utf-8") if isinstance(out, str) else bytes(out)


EXPORT_FORMATS: dict[str, ExportFormat] = {}
"""Every registered export format by name, in registration order."""


def register_export_format(format: ExportFormat) -> ExportFormat:
    """Add ``format`` to :data:`EXPORT_FORMATS`; ``ValueError`` for a name taken or options not known."""
    if not format.name or not format.name.replace("-", "").isalnum() or format.name != format.name.lower():
        raise ValueError(f"`format.name` must be lowercase letters, digits and '-', got {format.name!r}")
    if format.name in EXPORT_FORMATS:
        raise ValueError(f"`format.name` {format.name!r} is registered already")
    unknown = [option for option in format.options if option not in EXPORT_OPTIONS]
    if unknown:
        raise ValueError(f"`format.options` must be among {', '.join(EXPORT_OPTIONS)}, got {unknown}")
    EXPORT_FORMATS[format.name] = format
    return format


def unregister_export_format(name: str) -> None:
    """Remove the format ``name`` (for tests that register one of their own)."""
    EXPORT_FORMATS.pop(name, None)


def export_format(name: str) -> ExportFormat:
    """The registered format ``name``; ``ValueError`` naming ``format`` and the choices otherwise."""
    if name not in EXPORT_FORMATS:
        raise ValueError(f"`format` must be one of {', '.join(EXPORT_FORMATS)}, got {name!r}")
    return EXPORT_FORMATS[name]


def describe_export_formats() -> list[dict]:
    """The registry for clients (``GET /api/v1/domain``): name, label, media type, extension, options."""
    return [
        {
            "name": f.name,
            "label": f.label,
            "media_type": f.media_type,
            "extension": f.extension,
            "options": list(f.options),
        }
        for f in EXPORT_FORMATS.values()
    ]


register_export_format(
    ExportFormat(
        name="mtlx",
        label="MaterialX, conductor under a coat (.mtlx)",
        media_type="application/xml",
        extension="mtlx",
        tools=("mtlx",),
        write=mtlx_document,
    )
)
register_export_format(
    ExportFormat(
        name="openpbr",
        label="OpenPBR surface, MaterialX (.openpbr.mtlx)",
        media_type="application/xml",
        extension="openpbr.mtlx",
        tools=("openpbr",),
        write=openpbr_document,
    )
)
register_export_format(
    ExportFormat(
        name="blender",
        label="Blender script (.py)",
        media_type="text/x-python; charset=utf-8",
        extension="py",
        tools=("blender", "blender-conductor"),
        write=blender_script,
    )
)
register_export_format(
    ExportFormat(
        name="gltf",
        label="glTF asset (.gltf)",
        media_type="model/gltf+json",
        extension="gltf",
        tools=("gltf",),
        write=gltf_document,
    )
)
register_export_format(
    ExportFormat(
        name="glb",
        label="glTF binary asset (.glb)",
        media_type="model/gltf-binary",
        extension="glb",
        tools=("gltf",),
        write=glb_document,
    )
)
