"""
Coefficient packs
=================

The float16 coefficient pack a renderer loads: a documented binary format
(``docs/pack-format.md``) and its JSON view, with exact round trips.

-   :class:`PackedMaterial`: one material's float16 coefficients and metadata.
-   :func:`encode_pack`, :func:`decode_pack`: binary.
-   :func:`pack_to_json`, :func:`pack_from_json`: the JSON view.
-   :func:`to_float16`: float16 with a refusal (never inf) past the range.
-   :func:`halves_to_uint32`: the 14 uint32 words a shader reads with
    ``unpackHalf2x16``.

Binary layout (little-endian), version 2::

    magic "CFPK" | version u16 = 2 | count u16 | total_length u32
    count x material:
        name_len u16 | name utf-8 | source_len u16 | source utf-8
        eta_lo f32 | eta_hi f32 | degree u8 | kind u8 | reserved u8 (0) x 2
        coefficients, float16:
            kind 0, coated-conductor: 9 * (degree + 1), order [parameter][channel][power]
            kind 1, rgb-conductor: 6 (degree 0), order [n, k][channel]
    crc32 u32 of every byte before it

Version 1 is the same with the kind byte reserved (0): every material a
coated-conductor. Version 1 packs still decode; :func:`encode_pack` writes
version 2 (or version 1 on request, for coated-conductor materials only).
"""

from __future__ import annotations

import json
import struct
import zlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..domain import DEFAULT_ETA_I_RANGE, check_eta_i_range
from .coated_conductor import CHANNELS
from .kinds import DEFAULT_MODEL, kind_of_code, model_kind

__all__ = [
    "PACK_MAGIC",
    "PACK_VERSION",
    "PACK_VERSIONS",
    "FLOAT16_MAX",
    "PackedMaterial",
    "to_float16",
    "encode_pack",
    "decode_pack",
    "material_to_json",
    "material_from_json",
    "pack_to_json",
    "pack_from_json",
    "halves_to_uint32",
    "material_record_bytes",
]

PACK_MAGIC = b"CFPK"
PACK_VERSION = 2
PACK_VERSIONS = (1, 2)
"""Versions :func:`decode_pack` and :func:`pack_from_json` read."""
FLOAT16_MAX = float(np.finfo(np.float16).max)
_HEADER = struct.Struct("<4sHHI")
_MAX_TEXT = 65535


def to_float16(values, name: str = "coefficients") -> np.ndarray:
    """
    Round to float16 (nearest, ties to even); values whose magnitude rounds
    past the float16 range are refused, never stored as inf.
    """
    array = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"`{name}` must be finite")
    with np.errstate(over="ignore"):
        halves = array.astype(np.float16)
    if not np.all(np.isfinite(halves)):
        worst = float(np.max(np.abs(array)))
        raise ValueError(f"`{name}` must lie within the float16 range +/-{FLOAT16_MAX:g}, got {worst:g}")
    return halves


@dataclass(frozen=True)
class PackedMaterial:
    """
    One material of a pack.

    ``model`` is its kind (:data:`fitting.models.kinds.MODEL_KINDS`);
    ``coefficients`` a float16 array of shape (3, 3, degree + 1) for a
    ``coated-conductor`` (layout of :mod:`fitting.models.coated_conductor`) or (2, 3), n and k
    per channel, for an ``rgb-conductor``; ``eta_i_range`` is the fitted
    domain.
    """

    name: str
    coefficients: np.ndarray
    eta_i_range: tuple[float, float] = DEFAULT_ETA_I_RANGE
    source: str = ""
    metrics: dict[str, Any] = field(default_factory=dict, compare=False)
    model: str = DEFAULT_MODEL

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError("`name` must be a non-empty string")
        for label, text in (("name", self.name), ("source", self.source)):
            if len(text.encode("utf-8")) > _MAX_TEXT:
                raise ValueError(f"`{label}` must be at most {_MAX_TEXT} bytes of UTF-8")
        C = model_kind(self.model).check(self.coefficients)
        halves = to_float16(C)
        if not np.array_equal(halves.astype(np.float64), C):
            raise ValueError(
                "`coefficients` must be exactly representable in float16; round them with `to_float16` first"
            )
        lo, hi = check_eta_i_range(self.eta_i_range)
        # The pack stores the domain as float32.
        lo, hi = float(np.float32(lo)), float(np.float32(hi))
        halves.setflags(write=False)
        object.__setattr__(self, "coefficients", halves)
        object.__setattr__(self, "eta_i_range", (lo, hi))

    @property
    def degree(self) -> int:
        """Polynomial degree in t (0 for a kind without a power axis, e.g. an rgb-conductor)."""
        return model_kind(self.model).degree_of(self.coefficients)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, PackedMaterial):
            return NotImplemented
        return (
            self.model == other.model
            and self.name == other.name
            and self.source == other.source
            and self.eta_i_range == other.eta_i_range
            and self.coefficients.shape == other.coefficients.shape
            and self.coefficients.tobytes() == other.coefficients.tobytes()
        )

    __hash__ = None  # type: ignore[assignment]


def material_record_bytes(name: str, source: str, degree: int, model: str = DEFAULT_MODEL) -> int:
    """
    Bytes of one material in the binary pack (see the layout above): name and
    source with their u16 lengths, the f32 domain, degree, kind and padding,
    and the float16 coefficients (9 (degree + 1), or 6 for an rgb-conductor).
    """
    return 2 + len(name.encode()) + 2 + len(source.encode()) + 12 + 2 * model_kind(model).count(degree)


def encode_pack(materials: list[PackedMaterial], version: int = PACK_VERSION) -> bytes:
    """
    Encode materials into the binary pack format (see module docstring):
    version 2, or version 1 (readers older than the model kinds) when every
    material is a coated-conductor.
    """
    materials = list(materials)
    if version not in PACK_VERSIONS:
        raise ValueError(f"`version` must be one of {PACK_VERSIONS}, got {version!r}")
    if not materials:
        raise ValueError("`materials` must hold at least one material")
    if len(materials) > 65535:
        raise ValueError(f"`materials` must hold at most 65535 materials, got {len(materials)}")
    body = bytearray()
    for material in materials:
        if not isinstance(material, PackedMaterial):
            raise ValueError("`materials` must hold PackedMaterial instances")
        if version == 1 and model_kind(material.model).code != 0:
            raise ValueError(
                f"`version` 1 holds only coated-conductor materials, {material.name!r} is an {material.model}"
            )
        for text in (material.name, material.source):
            raw = text.encode("utf-8")
            body += struct.pack("<H", len(raw)) + raw
        lo, hi = material.eta_i_range
        body += struct.pack("<ffBB2x", lo, hi, material.degree, model_kind(material.model).code)
        body += material.coefficients.astype("<f2").tobytes()
    total = _HEADER.size + len(body) + 4
    head = _HEADER.pack(PACK_MAGIC, version, len(materials), total)
    data = head + bytes(body)
    return data + struct.pack("<I", zlib.crc32(data))


class _Reader:
    def __init__(self, data: bytes, end: int) -> None:
        self.data, self.offset, self.end = data, _HEADER.size, end

    def take(self, size: int, what: str) -> bytes:
        if self.offset + size > self.end:
            raise ValueError(f"`data` is truncated: {what} at byte {self.offset} runs past the end")
        chunk = self.data[self.offset : self.offset + size]
        self.offset += size
        return chunk


def decode_pack(data: bytes) -> list[PackedMaterial]:
    """
    Decode a binary pack.

    Raises
    ------
    ValueError
        On a wrong magic or version, a truncated file, a wrong length, a
        checksum mismatch, or invalid content.
    """
    data = bytes(data)
    if len(data) < _HEADER.size + 4:
        raise ValueError(f"`data` is truncated: {len(data)} bytes is shorter than a pack header")
    magic, version, count, total = _HEADER.unpack_from(data)
    if magic != PACK_MAGIC:
        raise ValueError(f"`data` is not a coefficient pack: magic {magic!r}, expected {PACK_MAGIC!r}")
    if version not in PACK_VERSIONS:
        raise ValueError(
            f"`data` has pack version {version}, only versions {', '.join(map(str, PACK_VERSIONS))} are supported"
        )
    if total != len(data):
        raise ValueError(
            f"`data` has the wrong length: the header says {total} bytes, got {len(data)}"
            + (" (truncated)" if len(data) < total else "")
        )
    (crc,) = struct.unpack_from("<I", data, total - 4)
    if crc != zlib.crc32(data[: total - 4]):
        raise ValueError("`data` is damaged: checksum mismatch")
    reader = _Reader(data, total - 4)
    materials = []
    for _ in range(count):
        texts = []
        for what in ("name", "source"):
            (size,) = struct.unpack("<H", reader.take(2, f"{what} length"))
            try:
                texts.append(reader.take(size, what).decode("utf-8"))
            except UnicodeDecodeError:
                raise ValueError(f"`data` has a {what} that is not UTF-8") from None
        lo, hi, degree, code = struct.unpack("<ffBB2x", reader.take(12, "eta_i range"))
        # Version 1 reserved the kind byte: every material is a coated-conductor.
        if version == 1:
            code = 0
        kind = kind_of_code(code)
        if degree > kind.max_degree:
            raise ValueError(
                f"`data` has polynomial degree {degree}, must be at most {kind.max_degree} for an {kind.name}"
            )
        shape = kind.shape(degree)
        model = kind.name
        raw = reader.take(2 * int(np.prod(shape)), "coefficients")
        halves = np.frombuffer(raw, dtype="<f2").astype(np.float16).reshape(shape)
        if not np.all(np.isfinite(halves)):
            raise ValueError("`data` holds a coefficient that is not finite")
        materials.append(PackedMaterial(texts[0], halves, (lo, hi), source=texts[1], model=model))
    if reader.offset != reader.end:
        raise ValueError(
            f"`data` has the wrong length: {reader.end - reader.offset} unexpected bytes after the last material"
        )
    return materials


def material_to_json(material: PackedMaterial) -> dict[str, Any]:
    """
    The JSON view of one material (values exactly as stored in float16):
    ``"model"``, and ``"coefficients"``: per parameter of the kind, three
    rows R, G, B of degree + 1 powers each for a kind with a power axis (a
    coated-conductor's ``{"F0", "a", "alpha"}``, with ``"degree"``), else
    three numbers R, G, B (an rgb-conductor's ``{"n": [R, G, B], "k": [R,
    G, B]}``).
    """
    C = material.coefficients.astype(np.float64)
    view: dict[str, Any] = {
        "name": material.name,
        "model": material.model,
        "eta_i_range": list(material.eta_i_range),
        "colour_space": "ACEScg",
    }
    kind = model_kind(material.model)
    if kind.polynomial:
        view["degree"] = material.degree
        view["coefficients"] = {
            p: [[float(v) for v in C[i, c]] for c in range(3)] for i, p in enumerate(kind.parameters)
        }
    else:
        view["coefficients"] = {p: [float(v) for v in C[i]] for i, p in enumerate(kind.parameters)}
    view["source"] = material.source
    view["metrics"] = material.metrics
    return view


def material_from_json(view: dict[str, Any]) -> PackedMaterial:
    """Inverse of :func:`material_to_json`; values must be exact float16."""
    if not isinstance(view, dict):
        raise ValueError("material must be a JSON object")
    kind = model_kind(view.get("model", DEFAULT_MODEL))
    model, parameters = kind.name, kind.parameters
    what = "three rows of numbers" if kind.polynomial else "three numbers"
    try:
        coefficients = np.array(
            [[view["coefficients"][p][c] for c in range(3)] for p in parameters],
            dtype=np.float64,
        )
        if coefficients.ndim != len(kind.shape()):
            raise ValueError("not the layout of the kind")
    except (KeyError, IndexError, TypeError, ValueError) as error:
        raise ValueError(
            f"`coefficients` must hold {', '.join(parameters[:-1])} and {parameters[-1]}, each {what} "
            f"({', '.join(CHANNELS)}) for an {model}: {error!r}"
        ) from None
    if view.get("colour_space", "ACEScg") != "ACEScg":
        raise ValueError(f"`colour_space` must be 'ACEScg', got {view.get('colour_space')!r}")
    return PackedMaterial(
        name=view.get("name", ""),
        coefficients=coefficients,
        eta_i_range=tuple(view.get("eta_i_range", DEFAULT_ETA_I_RANGE)),
        source=view.get("source", "") or "",
        metrics=view.get("metrics") or {},
        model=model,
    )


def pack_to_json(materials: list[PackedMaterial]) -> str:
    """The JSON view of a pack: ``{"format", "version", "materials": [...]}``."""
    return json.dumps(
        {
            "format": "coated-fresnel-pack",
            "version": PACK_VERSION,
            "materials": [material_to_json(m) for m in materials],
        },
        indent=2,
    )


def pack_from_json(text: str | bytes) -> list[PackedMaterial]:
    """Inverse of :func:`pack_to_json`."""
    try:
        view = json.loads(text)
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise ValueError(f"pack JSON is not valid JSON: {error}") from None
    if not isinstance(view, dict) or view.get("format") != "coated-fresnel-pack":
        raise ValueError("pack JSON must be an object with `format` 'coated-fresnel-pack'")
    if view.get("version") not in PACK_VERSIONS:
        raise ValueError(
            f"pack JSON `version` must be one of {', '.join(map(str, PACK_VERSIONS))}, got {view.get('version')!r}"
        )
    if view["version"] == 1 and any(
        isinstance(m, dict) and _code(m.get("model", DEFAULT_MODEL)) != 0 for m in view.get("materials") or []
    ):
        raise ValueError("pack JSON `version` 1 holds only coated-conductor materials")
    materials = view.get("materials")
    if not isinstance(materials, list) or not materials:
        raise ValueError("pack JSON `materials` must be a non-empty list")
    return [material_from_json(m) for m in materials]


def _code(model) -> int | None:
    """The pack code of a kind name, None for an unknown one (refused later, with its message)."""
    try:
        return model_kind(model).code
    except ValueError:
        return None


def halves_to_uint32(coefficients) -> np.ndarray:
    """
    Pack float16 coefficients in layout order into uint32 words, two halves
    per word, the earlier one in the low 16 bits (GLSL ``unpackHalf2x16``
    returns it in ``.x``). 27 halves give 14 words, the last padded with 0;
    the 6 of an rgb-conductor give 3.
    """
    halves = np.ascontiguousarray(np.asarray(coefficients, dtype=np.float16).ravel())
    bits = halves.view(np.uint16).astype(np.uint32)
    if bits.size % 2:
        bits = np.append(bits, np.uint32(0))
    return bits[0::2] | (bits[1::2] << 16)
