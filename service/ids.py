"""
Content addresses
=================

-   :func:`content_id`: the stable id of a fit from its inputs, so that the
    same request finds the same stored fit.
"""

from __future__ import annotations

import hashlib

__all__ = ["content_id"]


def content_id(*parts: bytes | str) -> str:
    """Stable content address (hex SHA-256, 32 characters) of the inputs of a fit."""
    digest = hashlib.sha256()
    for part in parts:
        digest.update(part.encode("utf-8") if isinstance(part, str) else part)
        digest.update(b"\x00")
    return digest.hexdigest()[:32]
