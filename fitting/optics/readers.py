"""
Optical constants from user files
=================================

-   :func:`read_nk_csv`, :func:`read_nk_json`, :func:`read_nk_yaml`: user files.
-   :func:`read_nk`: dispatches on a format name or file suffix.

All return :class:`fitting.optics.nk.SpectralNK` with wavelengths in nm; each
refusal is a ``ValueError`` naming the line, the field or the rule. The files
are untrusted: every reader bounds its work before doing it (size, nesting,
YAML aliases, rows, samples; :mod:`fitting.optics.bounded`), checks the type
of every field it reads, and repeats at most a short excerpt of bad input.

References
----------
Polyanskiy, M. N. (2024). Refractiveindex.info database of optical constants.
Scientific Data, 11, 94 (the YAML file format).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from .bounded import (
    MAX_LINE_CHARS,
    MAX_SAMPLES,
    check_text_size,
    csv_rows_bounded,
    excerpt,
    kind_of,
    load_json_bounded,
    load_yaml_bounded,
    is_number,
    parse_number,
)
from .database import clean_citation, merge_nk
from .formulas import formula_from_yaml, sample_model
from .nk import SpectralNK

__all__ = ["FORMATS", "read_nk_csv", "read_nk_json", "read_nk_yaml", "read_nk"]

FORMATS = ("csv", "json", "yaml")
# Longest citation kept from a file's REFERENCES (characters; cut, not refused).
_MAX_CITATION_CHARS = 2_000
# Most entries in a YAML `DATA` list and coefficients in one formula entry
# (refractiveindex.info files have at most 2 entries and 17 coefficients).
_MAX_YAML_ENTRIES = 16
_MAX_COEFFICIENTS = 64


def _unit_scale(header: str) -> float:
    """nm -> 1, um/µm/micrometre -> 1000 (from a column header)."""
    h = header.lower()
    if re.search(r"(^|[^a-z])nm([^a-z]|$)|nanomet", h):
        return 1.0
    if re.search(r"(^|[^a-z])(um|µm|μm)([^a-z]|$)|micron|micromet", h):
        return 1e3
    raise ValueError(f"CSV header {excerpt(header.strip())} must state the wavelength unit (nm or um)")


def read_nk_csv(
    text: str, name: str = "uploaded", source: str = "user CSV", max_samples: int = MAX_SAMPLES
) -> SpectralNK:
    """
    Read a CSV with columns wavelength, n, k; the wavelength header states
    its unit, e.g. ``wavelength_nm,n,k`` or ``wavelength (um),n,k``. At most
    ``max_samples`` data rows (counted before any row is parsed).
    """
    rows = csv_rows_bounded(text, max_rows=max_samples + 1)
    if not rows:
        raise ValueError("CSV is empty: expected a header `wavelength_nm,n,k` and rows")
    header = [c.strip() for c in rows[0]]
    if len(header) < 3 or not header[0].lower().startswith(("wavelength", "lambda", "wl")):
        raise ValueError(f"CSV header must be `wavelength_<unit>,n,k`, got {excerpt(','.join(header))}")
    if header[1].lower() != "n" or header[2].lower() != "k":
        raise ValueError(
            f"CSV columns 2 and 3 must be `n` and `k`, got {excerpt(header[1], 30)}, {excerpt(header[2], 30)}"
        )
    scale = _unit_scale(header[0])
    values = []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) < 3:
            raise ValueError(f"CSV line {line} must have 3 columns, got {len(row)}")
        try:
            values.append([parse_number(cell, f"CSV line {line} column {i + 1}") for i, cell in enumerate(row[:3])])
        except ValueError:
            raise ValueError(f"CSV line {line} must hold three numbers, got {excerpt(','.join(row[:3]))}") from None
    if not values:
        raise ValueError("CSV has a header but no data rows")
    data = np.array(values)
    return SpectralNK(data[:, 0] * scale, data[:, 1], data[:, 2], name=name, source=source)


def read_nk_json(
    text: str | bytes, name: str = "uploaded", source: str = "user JSON", max_samples: int = MAX_SAMPLES
) -> SpectralNK:
    """
    Read JSON ``{"wavelength_nm": [...], "n": [...], "k": [...]}`` (or
    ``wavelength_um``), optionally with ``name`` and ``source``; lists of
    numbers (booleans are refused), at most ``max_samples`` long.
    """
    view = load_json_bounded(text)
    if not isinstance(view, dict):
        raise ValueError(f"JSON must be an object with `wavelength_nm`, `n` and `k`, got {kind_of(view)}")
    if "wavelength_nm" in view:
        label, scale = "wavelength_nm", 1.0
    elif "wavelength_um" in view:
        label, scale = "wavelength_um", 1e3
    else:
        raise ValueError("JSON must have `wavelength_nm` (or `wavelength_um`)")
    for key in ("n", "k"):
        if key not in view:
            raise ValueError(f"JSON must have `{key}`")
    wl = _json_numbers(label, view[label], max_samples) * scale
    texts = {}
    for key, default, limit in (("name", name, 200), ("source", source, _MAX_CITATION_CHARS)):
        value = view.get(key)
        if value is None:
            texts[key] = default
        elif not isinstance(value, str):
            raise ValueError(f"JSON `{key}` must be text, got {kind_of(value)}")
        elif len(value) > limit:
            raise ValueError(f"JSON `{key}` must be at most {limit} characters, got {len(value)}")
        else:
            texts[key] = value.strip() or default
    return SpectralNK(
        wl,
        _json_numbers("n", view["n"], max_samples),
        _json_numbers("k", view["k"], max_samples),
        name=texts["name"],
        source=texts["source"],
    )


def _json_numbers(label: str, values: Any, max_samples: int) -> np.ndarray:
    """A JSON list of numbers (booleans are not numbers here) as float64."""
    if not isinstance(values, list):
        raise ValueError(f"JSON `{label}` must be a list of numbers, got {kind_of(values)}")
    if len(values) > max_samples:
        raise ValueError(f"JSON `{label}` must hold at most {max_samples} numbers, got {len(values)}")
    for index, value in enumerate(values):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"JSON `{label}[{index}]` must be a number, got {kind_of(value)}")
    try:
        return np.array(values, dtype=np.float64)
    except OverflowError:  # an integer literal beyond float64
        raise ValueError(f"JSON `{label}` holds a number too large for float64") from None


def _numbers(text: Any, what: str, max_samples: int) -> np.ndarray:
    if not isinstance(text, str):
        raise ValueError(f"YAML `{what}` `data` must be text (rows of numbers), got {kind_of(text)}")
    lines = text.strip().count("\n") + 1
    if lines > max_samples:
        raise ValueError(f"YAML `{what}` `data` must have at most {max_samples} rows, got {lines}")
    lines = [line for line in text.strip().splitlines() if line.strip()]
    longest = max(map(len, lines), default=0)
    if longest > MAX_LINE_CHARS:
        raise ValueError(f"YAML `{what}` `data` rows must be at most {MAX_LINE_CHARS} characters, got {longest}")
    words = [line.split() for line in lines]
    bad_word = next((v for row in words for v in row if not is_number(v)), None)
    if bad_word is not None:
        raise ValueError(f"YAML `{what}` data must be rows of numbers, got {excerpt(bad_word, 60)}")
    rows = [[float(v) for v in row] for row in words]
    widths = {len(r) for r in rows}
    if not rows or len(widths) != 1:
        raise ValueError(f"YAML `{what}` data must be rows of equal length")
    table = np.array(rows)
    bad = np.argwhere(~np.isfinite(table))
    if bad.size:
        row, column = (int(v) for v in bad[0])
        raise ValueError(f"YAML `{what}` data must be finite numbers, got {table[row, column]} in row {row + 1}")
    steps = np.diff(table[:, 0])
    if np.any(steps <= 0):
        row = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise ValueError(
            f"YAML `{what}` wavelengths must be strictly increasing, got {table[row, 0]:g} "
            f"after {table[row - 1, 0]:g} in row {row + 1}"
        )
    return table


def read_nk_yaml(
    text: str | bytes, name: str = "uploaded", source: str = "user YAML", max_samples: int = MAX_SAMPLES
) -> SpectralNK:
    """
    Read a refractiveindex.info YAML file: ``tabulated nk``, ``tabulated n``
    plus ``tabulated k``, and ``formula 1``-``formula 9`` entries (with an
    optional ``tabulated k``). Wavelengths in the file are micrometres.
    """
    view = load_yaml_bounded(text)
    if not isinstance(view, dict) or "DATA" not in view:
        raise ValueError("YAML must be a refractiveindex.info file with a `DATA` list")
    entries = view["DATA"]
    if not isinstance(entries, list) or not entries:
        raise ValueError(f"YAML `DATA` must be a non-empty list of entries, got {kind_of(entries)}")
    if len(entries) > _MAX_YAML_ENTRIES:
        raise ValueError(f"YAML `DATA` must have at most {_MAX_YAML_ENTRIES} entries, got {len(entries)}")
    references = view.get("REFERENCES")
    if references is not None and not isinstance(references, str):
        raise ValueError(f"YAML `REFERENCES` must be text, got {kind_of(references)}")
    wl_n = n = wl_k = k = None
    for index, item in enumerate(entries):
        if not isinstance(item, dict) or "type" not in item:
            raise ValueError(f"YAML `DATA[{index}]` must be a map with a `type`, got {kind_of(item)}")
        if not isinstance(item["type"], str):
            raise ValueError(f"YAML `DATA[{index}].type` must be text, got {kind_of(item['type'])}")
        kind = item["type"].strip()
        if kind == "tabulated nk":
            table = _numbers(item.get("data", ""), kind, max_samples)
            if table.shape[1] != 3:
                raise ValueError("YAML `tabulated nk` rows must have 3 numbers")
            wl_n, n, wl_k, k = table[:, 0], table[:, 1], table[:, 0], table[:, 2]
        elif kind in ("tabulated n", "tabulated k"):
            table = _numbers(item.get("data", ""), kind, max_samples)
            if table.shape[1] != 2:
                raise ValueError(f"YAML `{kind}` rows must have 2 numbers")
            if kind.endswith("n"):
                wl_n, n = table[:, 0], table[:, 1]
            else:
                wl_k, k = table[:, 0], table[:, 1]
        elif kind.startswith("formula"):
            try:
                number = int(kind.split()[1])
            except (IndexError, ValueError):
                raise ValueError(
                    f"YAML `DATA[{index}].type` must be `formula 1`-`formula 9`, got {excerpt(kind)}"
                ) from None
            if not 1 <= number <= 9:
                raise ValueError(f"YAML formula type must be 1-9, got {number}")
            coefficients = _yaml_floats(item, "coefficients", kind)
            if len(coefficients) > _MAX_COEFFICIENTS:
                raise ValueError(
                    f"YAML `{kind}` must have at most {_MAX_COEFFICIENTS} `coefficients`, got {len(coefficients)}"
                )
            wr = tuple(_yaml_floats(item, "wavelength_range", kind))
            if len(wr) != 2 or not wr[0] < wr[1]:
                raise ValueError(
                    f"YAML `{kind}` `wavelength_range` must be two increasing numbers, "
                    f"got {excerpt(' '.join(f'{v:g}' for v in wr[:4]))}"
                )
            wl_n, n = sample_model(formula_from_yaml(number, coefficients, wr), max_samples=max_samples)
        else:
            raise ValueError(f"YAML data type {excerpt(kind)} is not supported")
    if n is None:
        raise ValueError("YAML has no refractive index n")
    if k is None:
        wl, k = wl_n, np.zeros_like(n)
    elif wl_k is wl_n:  # one `tabulated nk` table: n and k share their wavelengths
        wl = wl_n
    else:
        wl, n, k = merge_nk(wl_n, n, wl_k, k)
    citation = clean_citation((references or "")[: 4 * _MAX_CITATION_CHARS])[:_MAX_CITATION_CHARS]
    return SpectralNK(wl * 1e3, n, k, name=name, source=citation or source)


def _yaml_floats(item: dict, key: str, kind: str) -> list[float]:
    """A formula entry's space-separated numbers (text, or one plain number)."""
    value = item.get(key)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = str(value)
    if not isinstance(value, str):
        raise ValueError(f"YAML `{kind}` `{key}` must be text of numbers, got {kind_of(value)}")
    words = value.split()
    if len(words) > _MAX_COEFFICIENTS:
        raise ValueError(f"YAML `{kind}` `{key}` must have at most {_MAX_COEFFICIENTS} numbers, got {len(words)}")
    try:
        return [parse_number(v, f"YAML `{kind}` `{key}`") for v in words]
    except ValueError:
        raise ValueError(f"YAML `{kind}` `{key}` must be numbers, got {excerpt(value)}") from None


def read_nk(data: str | bytes, format: str, name: str = "uploaded", max_samples: int = MAX_SAMPLES) -> SpectralNK:
    """
    Read *n*, *k* from file content in ``format`` (``csv``, ``json`` or
    ``yaml``; a file name's suffix also works, e.g. ``gold.yml``): UTF-8 text
    (a byte-order mark is skipped), at most ``max_samples`` wavelengths.
    Every reader bounds its work before doing it
    (:mod:`fitting.optics.bounded`): size, nesting, YAML aliases, rows.
    """
    fmt = Path(format).suffix.lstrip(".").lower() if "." in format else format.lower()
    fmt = {"yml": "yaml", "txt": "csv"}.get(fmt, fmt)
    if fmt not in FORMATS:
        raise ValueError(f"`format` must be one of {', '.join(FORMATS)}, got {excerpt(format)}")
    check_text_size(data, "the file")
    if isinstance(data, bytes):
        try:
            data = data.decode("utf-8-sig")
        except UnicodeDecodeError as error:
            raise ValueError(f"the file must be UTF-8 text: byte {error.start} is not (UTF-16 or binary?)") from None
    if "\x00" in data:
        raise ValueError(
            f"the file must be UTF-8 text: it holds a NUL character at {data.index(chr(0))} (UTF-16 or binary?)"
        )
    reader = {"csv": read_nk_csv, "json": read_nk_json, "yaml": read_nk_yaml}[fmt]
    return reader(data, name=name, max_samples=max_samples)
