"""
Export names and identity
=========================

What makes an export's elements unique and says which fit it came from, so
that any set of exports merges into one document with nothing lost (two
golds at coat indices 1.33 and 1.5, or two fits of one gold, define
different node definitions and materials).

-   :func:`export_id`: the fit id an export carries, in full (the stored
    fit's id, else a content address of the material's data).
-   :func:`eta_tag`: a coat index as a name part, ``1.33`` -> ``eta1p33``.
-   :func:`element_stem`: ``<material>_<first 8 of the id>_<eta tag>``, a
    MaterialX element name (``Au_1a2b3c4d_eta1p33``).
-   :func:`identity`: the fields every export carries (fit id, service
    version, coat index, working space).
-   :func:`carried_pack`: the fit's float16 model as the binary pack of one
    material (its CRC inside), base64: what an export carries to be read
    back to the same coefficients (:mod:`fitting.exports.readback`).
"""

from __future__ import annotations

import base64
import hashlib
import json
import re

import numpy as np

from ..models.pack import encode_pack
from ._xml import element_name

__all__ = [
    "FIT_ID_LENGTH",
    "SHORT_ID_LENGTH",
    "export_id",
    "eta_tag",
    "element_stem",
    "identity",
    "check_fit_id",
    "carried_pack",
]

FIT_ID_LENGTH = 32
"""Hex digits of a fit id (SHA-256, as the service's content addresses)."""
SHORT_ID_LENGTH = 8
"""Hex digits of the id inside element names."""

_FIT_ID = re.compile(r"[0-9a-f]{%d}" % FIT_ID_LENGTH)


def check_fit_id(fit_id) -> str | None:
    """``fit_id`` if ``None`` or 32 lower-case hex digits, else ``ValueError``."""
    if fit_id is None:
        return None
    if not isinstance(fit_id, str) or not _FIT_ID.fullmatch(fit_id):
        raise ValueError(f"`fit_id` must be {FIT_ID_LENGTH} lower-case hex digits, got {fit_id!r}")
    return fit_id


def _content_id(values) -> str:
    """
    A content address of what an export was made from, for a material that
    is no stored fit: its name, source, what was fitted, the target under
    the coat (float64 bytes) and the float16 model's coefficients.
    """
    digest = hashlib.sha256()
    digest.update(json.dumps([values.name, values.source, values.origin]).encode("utf-8"))
    digest.update(np.ascontiguousarray(values.target_ACEScg, dtype="<f8").tobytes())
    if values.model is not None:
        digest.update(values.model.model.encode("utf-8"))
        digest.update(np.ascontiguousarray(values.model.coefficients, dtype="<f2").tobytes())
    return digest.hexdigest()[:FIT_ID_LENGTH]


def export_id(values) -> str:
    """The fit id of ``values`` (:class:`fitting.exports.values.ExportValues`), 32 hex digits."""
    return values.fit_id if values.fit_id is not None else _content_id(values)


def eta_tag(eta_i: float) -> str:
    """A coat index as a name part: ``eta`` and up to 4 decimals, ``.`` as ``p`` (1.33 -> ``eta1p33``)."""
    text = f"{float(eta_i):.4f}".rstrip("0").rstrip(".")
    return "eta" + text.replace(".", "p")


def element_stem(values) -> str:
    """``<material>_<id[:8]>_<eta tag>`` as a MaterialX element name (``Au_1a2b3c4d_eta1p33``)."""
    return element_name(f"{values.name}_{export_id(values)[:SHORT_ID_LENGTH]}_{eta_tag(values.eta_i)}")


def identity(values, with_pack: bool = False) -> dict:
    """
    What every export carries to be traced and read back: ``fit_id`` (in
    full), ``fit_id_kind`` (``stored`` for a service fit, ``content`` for a
    content address), ``service_version``, ``eta_i`` (the coat index) and
    ``working_space``; with ``with_pack`` also ``pack`` (:func:`carried_pack`).
    """
    return {
        "fit_id": export_id(values),
        "fit_id_kind": "stored" if values.fit_id is not None else "content",
        "service_version": values.version,
        "eta_i": values.eta_i,
        "working_space": values.working_space,
        **({"pack": carried_pack(values)} if with_pack else {}),
    }


def carried_pack(values) -> str | None:
    """
    ``values.model`` as a binary pack of one material (:func:`fitting.models.pack.encode_pack`,
    CRC-32 checked when read) in base64 ASCII; ``None`` when the export has no model.
    """
    if values.model is None:
        return None
    return base64.b64encode(encode_pack([values.model])).decode("ascii")
