"""
Optical constants from user files
=================================

-   :func:`read_nk_csv`, :func:`read_nk_json`, :func:`read_nk_yaml`: user files.
-   :func:`read_nk`: dispatches on a format name or file suffix.

All return :class:`fitting.optics.nk.SpectralNK` with wavelengths in nm; each
refusal is a ``ValueError`` naming the line, the field or the rule.

References
----------
Polyanskiy, M. N. (2024). Refractiveindex.info database of optical constants.
Scientific Data, 11, 94 (the YAML file format).
"""

from __future__ import annotations

import csv
import io
import json
import re
from pathlib import Path

import numpy as np

from .database import clean_citation, merge_nk
from .formulas import formula_from_yaml, sample_model
from .nk import SpectralNK

__all__ = ["FORMATS", "read_nk_csv", "read_nk_json", "read_nk_yaml", "read_nk"]

FORMATS = ("csv", "json", "yaml")


def _unit_scale(header: str) -> float:
    """nm -> 1, um/µm/micrometre -> 1000 (from a column header)."""
    h = header.lower()
    if re.search(r"(^|[^a-z])nm([^a-z]|$)|nanomet", h):
        return 1.0
    if re.search(r"(^|[^a-z])(um|µm|μm)([^a-z]|$)|micron|micromet", h):
        return 1e3
    raise ValueError(
        f"CSV header `{header.strip()}` must state the wavelength unit (nm or um)"
    )


def read_nk_csv(text: str, name: str = "uploaded", source: str = "user CSV") -> SpectralNK:
    """
    Read a CSV with columns wavelength, n, k; the wavelength header states
    its unit, e.g. ``wavelength_nm,n,k`` or ``wavelength (um),n,k``.
    """
    try:
        rows = [r for r in csv.reader(io.StringIO(text)) if r and any(c.strip() for c in r)]
    except csv.Error as error:
        raise ValueError(f"CSV is malformed: {error}") from None
    if not rows:
        raise ValueError("CSV is empty: expected a header `wavelength_nm,n,k` and rows")
    header = [c.strip() for c in rows[0]]
    if len(header) < 3 or not header[0].lower().startswith(("wavelength", "lambda", "wl")):
        raise ValueError(
            f"CSV header must be `wavelength_<unit>,n,k`, got `{','.join(header)}`"
        )
    if header[1].lower() != "n" or header[2].lower() != "k":
        raise ValueError(f"CSV columns 2 and 3 must be `n` and `k`, got `{header[1]}`, `{header[2]}`")
    scale = _unit_scale(header[0])
    values = []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) < 3:
            raise ValueError(f"CSV line {line} must have 3 columns, got {len(row)}")
        try:
            values.append([float(row[0]), float(row[1]), float(row[2])])
        except ValueError:
            raise ValueError(f"CSV line {line} must hold three numbers, got {row[:3]}") from None
    if not values:
        raise ValueError("CSV has a header but no data rows")
    data = np.array(values)
    return SpectralNK(data[:, 0] * scale, data[:, 1], data[:, 2], name=name, source=source)


def read_nk_json(text: str | bytes, name: str = "uploaded", source: str = "user JSON") -> SpectralNK:
    """
    Read JSON ``{"wavelength_nm": [...], "n": [...], "k": [...]}`` (or
    ``wavelength_um``), optionally with ``name`` and ``source``.
    """
    try:
        view = json.loads(text)
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise ValueError(f"JSON is not valid: {error}") from None
    if not isinstance(view, dict):
        raise ValueError("JSON must be an object with `wavelength_nm`, `n` and `k`")
    if "wavelength_nm" in view:
        wavelength, scale = view["wavelength_nm"], 1.0
    elif "wavelength_um" in view:
        wavelength, scale = view["wavelength_um"], 1e3
    else:
        raise ValueError("JSON must have `wavelength_nm` (or `wavelength_um`)")
    for key in ("n", "k"):
        if key not in view:
            raise ValueError(f"JSON must have `{key}`")
    try:
        wl = np.asarray(wavelength, dtype=np.float64) * scale
    except (TypeError, ValueError):
        raise ValueError("`wavelength_nm` must be a list of numbers") from None
    return SpectralNK(
        wl, view["n"], view["k"],
        name=str(view.get("name") or name), source=str(view.get("source") or source),
    )


def _numbers(text: str, what: str) -> np.ndarray:
    try:
        rows = [[float(v) for v in line.split()] for line in str(text).strip().splitlines() if line.strip()]
    except ValueError:
        raise ValueError(f"YAML `{what}` data must be rows of numbers") from None
    widths = {len(r) for r in rows}
    if not rows or len(widths) != 1:
        raise ValueError(f"YAML `{what}` data must be rows of equal length")
    return np.array(rows)


def read_nk_yaml(text: str | bytes, name: str = "uploaded", source: str = "user YAML") -> SpectralNK:
    """
    Read a refractiveindex.info YAML file: ``tabulated nk``, ``tabulated n``
    plus ``tabulated k``, and ``formula 1``-``formula 9`` entries (with an
    optional ``tabulated k``). Wavelengths in the file are micrometres.
    """
    import yaml

    try:
        view = yaml.safe_load(text)
    except yaml.YAMLError as error:
        raise ValueError(f"YAML is not valid: {error}") from None
    if not isinstance(view, dict) or not isinstance(view.get("DATA"), list) or not view["DATA"]:
        raise ValueError("YAML must be a refractiveindex.info file with a `DATA` list")
    wl_n = n = wl_k = k = None
    for item in view["DATA"]:
        if not isinstance(item, dict) or "type" not in item:
            raise ValueError("YAML `DATA` entries must have a `type`")
        kind = str(item["type"]).strip()
        if kind == "tabulated nk":
            table = _numbers(item.get("data", ""), kind)
            if table.shape[1] != 3:
                raise ValueError("YAML `tabulated nk` rows must have 3 numbers")
            wl_n, n, wl_k, k = table[:, 0], table[:, 1], table[:, 0], table[:, 2]
        elif kind in ("tabulated n", "tabulated k"):
            table = _numbers(item.get("data", ""), kind)
            if table.shape[1] != 2:
                raise ValueError(f"YAML `{kind}` rows must have 2 numbers")
            if kind.endswith("n"):
                wl_n, n = table[:, 0], table[:, 1]
            else:
                wl_k, k = table[:, 0], table[:, 1]
        elif kind.startswith("formula"):
            try:
                number = int(kind.split()[1])
                coefficients = [float(v) for v in str(item.get("coefficients", "")).split()]
                wr = tuple(float(v) for v in str(item.get("wavelength_range", "")).split())
            except (IndexError, ValueError):
                raise ValueError(f"YAML `{kind}` needs numeric `coefficients` and `wavelength_range`") from None
            if len(wr) != 2 or not wr[0] < wr[1]:
                raise ValueError(f"YAML `{kind}` `wavelength_range` must be two increasing numbers")
            wl_n, n = sample_model(formula_from_yaml(number, coefficients, wr))
        else:
            raise ValueError(f"YAML data type `{kind}` is not supported")
    if n is None:
        raise ValueError("YAML has no refractive index n")
    if k is None:
        wl, k = wl_n, np.zeros_like(n)
    else:
        wl, n, k = merge_nk(wl_n, n, wl_k, k)
    citation = clean_citation(view.get("REFERENCES"))
    return SpectralNK(wl * 1e3, n, k, name=name, source=citation or source)


def read_nk(data: str | bytes, format: str, name: str = "uploaded") -> SpectralNK:
    """
    Read *n*, *k* from file content in ``format`` (``csv``, ``json`` or
    ``yaml``; a file name's suffix also works, e.g. ``gold.yml``).
    """
    fmt = Path(format).suffix.lstrip(".").lower() if "." in format else format.lower()
    fmt = {"yml": "yaml", "txt": "csv"}.get(fmt, fmt)
    if fmt not in FORMATS:
        raise ValueError(f"`format` must be one of {', '.join(FORMATS)}, got {format!r}")
    if isinstance(data, bytes):
        try:
            data = data.decode("utf-8-sig")
        except UnicodeDecodeError:
            raise ValueError("the file must be UTF-8 text") from None
    reader = {"csv": read_nk_csv, "json": read_nk_json, "yaml": read_nk_yaml}[fmt]
    return reader(data, name=name)
