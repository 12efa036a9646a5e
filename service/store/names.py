"""
When two names are the same name
================================

A saved edited material is found by its name, so two of them must not be
told apart only by a look-alike letter. :func:`name_key` is what the
store compares: the Unicode TR39 skeleton (ICU's ``SpoofChecker``, the
confusables table of the Unicode version ICU ships) of the name after NFKC
case folding and with its runs of white space made one space. So ``gold``,
``Gold``, ``gоld`` (a Cyrillic о), ``ｇｏｌｄ`` (full width), ``go\u200bld``
(a zero-width space) and ``g o l d`` with two spaces have one key, and
``rn`` has the key of ``m``.

Case is folded before the skeleton is taken, so a capital ``I`` is the
letter ``i`` there, not the ``l`` it resembles in some fonts.
"""

from __future__ import annotations

import functools
import unicodedata

import icu

__all__ = ["name_key", "UNICODE_VERSION"]

UNICODE_VERSION = icu.UNICODE_VERSION
"""The Unicode version of the confusables table the skeletons come from."""


@functools.cache
def _checker() -> "icu.SpoofChecker":
    return icu.SpoofChecker()


def name_key(name: str) -> str:
    """The key two names share when they look the same (see the module's text); NFC."""
    folded = unicodedata.normalize("NFKC", unicodedata.normalize("NFKC", name).casefold())
    skeleton = _checker().getSkeleton(0, " ".join(folded.split()))
    # NUL (which PostgreSQL text refuses) as the summary's name shows it.
    return unicodedata.normalize("NFC", skeleton).replace("\x00", "\ufffd")
