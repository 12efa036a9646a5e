"""
Shared types and the error body
===============================

Constants and constrained field types of the API, built from the core's
rules (eta_i limits, objectives, library names), and the one error shape
every 4xx and 5xx answer has (:class:`ErrorBody`). :class:`Mirror` is the
base of response models that mirror a core result: extra keys kept, keys the
result did not have left out, so the JSON is the core's, key for key.
"""

from __future__ import annotations

import functools
import unicodedata
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator

from fitting.domain import DEFAULT_ETA_I_RANGE, ETA_I_MAX, ETA_I_MIN
from fitting.exports import EXPORT_FORMATS
from fitting.exports.colour_space import WORKING_SPACES as WORKING_SPACE_NAMES
from fitting.fits.settings import DEFAULT_OBJECTIVE, OBJECTIVES
from fitting.models.kinds import DEFAULT_MODEL, MODEL_KINDS
from fitting.optics.bounded import excerpt
from fitting.optics.catalogue import catalogue, resolve_material

from ..jobs.nk import MAX_NK_SAMPLES
from ..store.names import name_key

__all__ = [
    "API_PREFIX",
    "INT64_MAX",
    "MAX_NK_SAMPLES",
    "FIT_ID_PATTERN",
    "MATERIAL_ID_PATTERN",
    "PACK_FORMATS",
    "DownloadFormat",
    "download_formats",
    "MAX_EXPORT_PACK",
    "ETA_I_LIMITS",
    "DEFAULT_ETA_I_RANGE",
    "DEFAULT_OBJECTIVE",
    "DEFAULT_MODEL",
    "FiniteFloat",
    "EtaI",
    "FitId",
    "LibraryName",
    "Objective",
    "ModelKind",
    "PackFormat",
    "Text",
    "MaterialName",
    "material_name",
    "RequestModel",
    "WORKING_SPACES",
    "WorkingSpace",
    "Mirror",
    "absent",
    "ErrorItem",
    "ErrorBody",
]

API_PREFIX = "/api/v1"
INT64_MAX = 2**63 - 1
"""Largest integer a query may give where it reaches the store (SQLite integers are 64-bit)."""
FIT_ID_PATTERN = r"^[0-9a-f]{32}$"
MATERIAL_ID_PATTERN = r"^([A-Za-z]{1,8}|[0-9a-f]{32}|[A-Za-z0-9+-]{1,40}\.[A-Za-z0-9+-]{1,80})$"
"""A library symbol (``Au``), a saved material's id, or a catalogue page (``Ti.Johnson``)."""
PACK_FORMATS = ("binary", "json", "glsl", "hlsl")
WORKING_SPACES = WORKING_SPACE_NAMES
"""The working spaces an export is fitted and written in (docs/exports.md)."""
WorkingSpace = Literal[WORKING_SPACE_NAMES]  # type: ignore[valid-type]
MAX_EXPORT_PACK = 16
"""Most fits in one pack of exports (each export fits its tool's values, about 1 s)."""
ETA_I_LIMITS = (ETA_I_MIN, ETA_I_MAX)
"""Every coating index lies in [1, 3] (fitting.domain)."""

FiniteFloat = Annotated[float, Field(allow_inf_nan=False, strict=True)]
EtaI = Annotated[float, Field(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False, strict=True)]
FitId = Annotated[str, Field(pattern=FIT_ID_PATTERN, description="32 lowercase hex digits")]
LibraryName = Annotated[
    str,
    Field(
        min_length=1,
        max_length=200,
        description=(
            "A conductor of the library by name, symbol or id, any case: gold, Au, aluminum, TiN, Ti.Johnson "
            "(GET /library)"
        ),
    ),
    AfterValidator(resolve_material),
]
"""A catalogue conductor, checked and turned into its id (``gold`` -> ``Au``)."""
Objective = Literal[OBJECTIVES]  # type: ignore[valid-type]


def _check_model_kind(model: str) -> str:
    if model not in MODEL_KINDS:
        raise ValueError(f"`model` must be one of {', '.join(map(repr, MODEL_KINDS))}, got {model[:60]!r}")
    return model


ModelKind = Annotated[
    str,
    Field(description="A registered model kind (GET /api/v1/domain: model_kinds)"),
    AfterValidator(_check_model_kind),
]
"""A model kind's name (checked against the registry when the request is read, so a plugin's kind counts)."""
PackFormat = Literal[PACK_FORMATS]  # type: ignore[valid-type]


def download_formats() -> tuple[str, ...]:
    """Every download format: the pack formats, then the registered exports (:data:`fitting.exports.EXPORT_FORMATS`)."""
    return (*PACK_FORMATS, *EXPORT_FORMATS)


def _check_download_format(format: str) -> str:
    if format not in PACK_FORMATS and format not in EXPORT_FORMATS:
        raise ValueError(f"`format` must be one of {', '.join(map(repr, download_formats()))}, got {format!r}")
    return format


DownloadFormat = Annotated[str, AfterValidator(_check_download_format)]
"""A pack format or a registered export (checked against the registry when the request is read, so a
plugin's format counts; ``GET /api/v1/domain`` lists them)."""
Text = Annotated[str, Field(min_length=1, max_length=200, pattern=r"\S")]

_BIDI_CONTROLS = frozenset("\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")
_INVISIBLE = frozenset({"Zs", "Zl", "Zp", "Cc", "Cf", "Cn", "Co", "Cs", "Mn", "Me"})
"""Unicode general categories that show nothing on their own (spaces, controls, format, marks)."""


@functools.cache
def reserved_names() -> dict[str, str]:
    """
    The look-alike key (:func:`service.store.names.name_key`) of every
    name the catalogue answers to (each entry's id, name, other names and
    symbol: ``Au``, ``gold``, ``Ti.Johnson``), and the one it stands for.
    """
    reserved: dict[str, str] = {}
    for entry in catalogue().values():
        for name in (entry["name"], *entry["aliases"], entry["symbol"], entry["id"]):
            reserved.setdefault(name_key(name), name)
    return reserved


def material_name(value: str) -> str:
    """
    A saved material's name as stored: NFC-normalised (an NFD spelling is
    the same name) and stripped; ``ValueError`` when it holds a
    bidirectional control (it would show its letters out of order), has no
    visible character (only spaces, zero-width or format characters), or
    is, or looks the same as (:func:`service.store.names.name_key`: case,
    width, look-alike letters), a catalogue material's name, symbol or id
    (``Au``, ``Gold``, ``stainless steel 316``: :func:`reserved_names`).
    """
    value = unicodedata.normalize("NFC", value).strip()
    control = next((c for c in value if c in _BIDI_CONTROLS), None)
    if control is not None:
        raise ValueError(f"`name` must hold no bidirectional control, got U+{ord(control):04X}")
    if all(unicodedata.category(c) in _INVISIBLE for c in value):
        raise ValueError("`name` needs a visible character (spaces, zero-width and format characters show nothing)")
    reserved = reserved_names().get(name_key(value))
    if reserved is not None:
        same = "is" if reserved.casefold() == value.casefold() else "looks the same as"
        raise ValueError(
            f"`name` {value!r} is reserved: it {same} {reserved!r}, which names a material of "
            "the catalogue (GET /api/v1/library)"
        )
    return value


MaterialName = Annotated[str, Field(min_length=1, max_length=200), AfterValidator(material_name)]
"""A saved material's name (:func:`material_name`)."""


_MAX_UNKNOWN_LISTED = 5


class RequestModel(BaseModel):
    """
    Base of the request models: unknown fields are refused, and a body with
    many of them is refused in one error naming the first few (pydantic
    would make one error per field, tens of thousands from a 1 MB body, all
    on the event loop).
    """

    model_config = ConfigDict(extra="forbid")

    @model_validator(mode="before")
    @classmethod
    def _few_unknown_fields(cls, data: Any) -> Any:
        fields = cls.model_fields
        if isinstance(data, dict) and len(data) > len(fields) + _MAX_UNKNOWN_LISTED:
            unknown = [key for key in data if key not in fields]
            if len(unknown) > _MAX_UNKNOWN_LISTED:
                shown = ", ".join(excerpt(key, 30) for key in unknown[:_MAX_UNKNOWN_LISTED])
                raise ValueError(f"extra fields are not permitted: {len(unknown)} unknown fields ({shown}, ...)")
        return data


class Mirror(BaseModel):
    """
    A response model mirroring a core result: extra keys kept; optional
    fields declared with :func:`absent` are left out when the result did not
    have them, so the JSON is the core's key for key.
    """

    model_config = ConfigDict(extra="allow")


def _is_none(value: Any) -> bool:
    return value is None


def absent(description: str | None = None) -> Any:
    """An optional field of a :class:`Mirror`: None, and then not in the JSON."""
    return Field(None, exclude_if=_is_none, description=description)


class ErrorItem(BaseModel):
    loc: list[str | int]
    msg: str
    type: str


class ErrorBody(BaseModel):
    """Every 4xx and 5xx answer: what broke which rule."""

    detail: str
    errors: list[ErrorItem] = Field(default_factory=list)
