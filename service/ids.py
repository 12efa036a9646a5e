"""
Content addresses
=================

-   :func:`content_address`: the id of a fit (or a scene) from its inputs in
    canonical JSON, so that the same request finds the same stored fit and
    two different requests never share an id (item 8).
-   :func:`content_id`: the earlier NUL-separated digest, kept for readers
    of ids made before ``fit/v2``; new ids never use it (a NUL inside a
    part moves content between parts).
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

import numpy as np

__all__ = ["content_address", "content_id"]


def content_id(*parts: bytes | str) -> str:
    """Stable content address (hex SHA-256, 32 characters) of the inputs of a fit."""
    digest = hashlib.sha256()
    for part in parts:
        digest.update(part.encode("utf-8") if isinstance(part, str) else part)
        digest.update(b"\x00")
    return digest.hexdigest()[:32]


def _canonical(value: Any) -> Any:
    if isinstance(value, bytes):
        return {"bytes": value.hex()}
    if isinstance(value, np.ndarray):
        return {"f8": np.ascontiguousarray(value, dtype="<f8").tobytes().hex()}
    if isinstance(value, dict):
        return {str(k): _canonical(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_canonical(v) for v in value]
    if isinstance(value, float):
        return {"float": value.hex()}  # exact, and NaN or inf cannot collide with a number
    return value


def content_address(*parts: Any) -> str:
    """
    The id (32 hex digits of SHA-256) of ``parts``: each part (str, number,
    bytes, array, list, dict) in canonical JSON, so that no content can move
    between parts (a NUL in a name is just a character) and two different
    inputs never share an encoding.
    """
    text = json.dumps(
        [_canonical(p) for p in parts], sort_keys=True, ensure_ascii=True, separators=(",", ":"), allow_nan=False
    )
    return hashlib.sha256(text.encode("ascii")).hexdigest()[:32]
