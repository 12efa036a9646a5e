"""
Error metrics
=============

One typed result for every error the project reports:

-   :class:`ErrorMetrics`: mean and max CIE Delta E 2000, the breakdown per
    eta_i row, and what they were measured against; :meth:`ErrorMetrics.to_dict`
    gives the JSON the packs and the API have always carried.
-   :func:`error_metrics`: the metrics between a reference and an
    approximation on a grid indexed [eta_i, cos_theta] (material fits).
-   :func:`grid_metrics`: :func:`error_metrics` of several models against
    one reference, its Lab computed once.
-   :func:`curve_metrics`: the metrics of a model against edited curves.
-   :func:`delta_E_summary`: mean and max of a Delta E map (scenes).
-   :func:`baseline_metrics`: :func:`error_metrics` of every baseline of
    :mod:`fitting.models.baselines`.
-   :class:`MaxAt`: where a maximum is (eta_i, angle in degrees).
-   :meth:`ErrorMetrics.figure`, :func:`headline`: **the one figure** of a
    fit, the same object in the core, its JSON (``metrics["figure"]``), the
    API (``FitMetrics.figure``), the pack JSON and the shader headers:
    ``{"against", "delta_E_mean", "delta_E_max", "max_at": {"eta_i",
    "theta_deg"}}``, ``against`` in words a user reads
    (:data:`AGAINST_MEASURED`, :data:`AGAINST_CURVES`).

Lab uses the ACES white as reference white (:func:`fitting.colour.colorimetry.ACEScg_to_Lab`).

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Sections 4.1 and 4.3.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab
from ..colour.delta_e import delta_E_2000, delta_E_map
from ..domain import DEFAULT_MIN_COVERAGE
from ..models.baselines import baselines_ACEScg

__all__ = [
    "AGAINST_MEASURED",
    "AGAINST_CURVES",
    "MaxAt",
    "headline",
    "BREAKDOWN_ETA_I",
    "LAYOUTS",
    "EtaRow",
    "ErrorMetrics",
    "delta_E_map",
    "error_metrics",
    "grid_metrics",
    "curve_metrics",
    "delta_E_summary",
    "baseline_metrics",
]

BREAKDOWN_ETA_I = (1.0, 1.5, 2.0, 2.5)
"""The eta_i of the per-row breakdown of material fits (Vernooij 2024, Section 4.3)."""

AGAINST_MEASURED = "the measured metal (1 nm spectral reference)"
"""What a fit of measured n, k is measured against, in words."""
AGAINST_CURVES = "your edited curves"
"""What a fit of edited curves is measured against, in words."""

LAYOUTS = ("grid", "curves", "summary")
"""JSON layouts of :meth:`ErrorMetrics.to_dict`, one per kind of fit (see there)."""


@dataclass(frozen=True)
class EtaRow:
    """Mean and max Delta E 2000 of one eta_i row (or one edited curve)."""

    eta_i: float
    mean: float
    max: float


@dataclass(frozen=True)
class MaxAt:
    """Where a maximum Delta E is: the coating index and the angle in the coating (degrees)."""

    eta_i: float
    theta_deg: float

    def to_dict(self) -> dict[str, float]:
        return {"eta_i": self.eta_i, "theta_deg": self.theta_deg}


def _theta_deg(cos_theta) -> np.ndarray:
    """The angle of cos theta in degrees (exactly 90 at 0)."""
    return np.degrees(np.arccos(np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)))


def headline(metrics: dict[str, Any] | None) -> str:
    """
    The one figure of a fit's metrics JSON (``metrics["figure"]``) in words:
    ``"Delta E 2000 against <what>: mean m, max x at eta_i e, theta t deg"``;
    ``"Delta E 2000: not measured"`` without one.
    """
    figure = (metrics or {}).get("figure")
    if not figure:
        return "Delta E 2000: not measured"
    text = (
        f"Delta E 2000 against {figure['against']}: mean {figure['delta_E_mean']:.3f}, max {figure['delta_E_max']:.3f}"
    )
    at = figure.get("max_at")
    if at:
        text += f" at eta_i {at['eta_i']:.3g}, theta {at['theta_deg']:.1f} deg"
    return text


@dataclass(frozen=True)
class ErrorMetrics:
    """
    CIE Delta E 2000 of a model against what it approximates.

    Attributes
    ----------
    mean, max
        Over every sample.
    rows
        Per eta_i row (material fits: the rows of :data:`BREAKDOWN_ETA_I`
        inside the grid; curve fits: one per edited curve); None when not
        broken down.
    against
        What the model was measured against, in words
        (``"the measured metal (1 nm spectral reference), 100 x 100 grid"``).
    rmse
        Root mean square difference in linear RGB, where measured.
    layout
        The JSON layout of :meth:`to_dict`, one of :data:`LAYOUTS`.
    max_at
        Where the max is (:class:`MaxAt`), where known.
    """

    mean: float
    max: float
    against: str
    rows: tuple[EtaRow, ...] | None = None
    rmse: float | None = None
    layout: str = "grid"
    max_at: MaxAt | None = None

    def figure(self) -> dict[str, Any]:
        """The one figure (module docstring): what, mean, max and where the max is."""
        return {
            "against": self.against,
            "delta_E_mean": self.mean,
            "delta_E_max": self.max,
            "max_at": None if self.max_at is None else self.max_at.to_dict(),
        }

    def __post_init__(self) -> None:
        if self.layout not in LAYOUTS:
            raise ValueError(f"`layout` must be one of {', '.join(LAYOUTS)}, got {self.layout!r}")

    def row(self, eta_i: float) -> EtaRow:
        """The row at ``eta_i``; ``LookupError`` if there is none."""
        for row in self.rows or ():
            if abs(row.eta_i - eta_i) < 1e-9:
                return row
        raise LookupError(f"no row at eta_i {eta_i:g}")

    def to_dict(self) -> dict[str, Any]:
        """
        The JSON of this result, in the layout packs and API answers carry:

        -   ``grid``: ``delta_E_mean``, ``delta_E_max``, ``rmse`` and, with
            rows, ``by_eta_i`` keyed by eta_i (``"1.5"``) of
            ``{delta_E_mean, delta_E_max}``.
        -   ``curves``: ``delta_E_mean``, ``delta_E_max`` and ``by_curve``, a
            list of ``{eta_i, delta_E_mean, delta_E_max}``.
        -   ``summary``: ``mean`` and ``max``.
        """
        if self.layout == "summary":
            return {"mean": self.mean, "max": self.max}
        out: dict[str, Any] = {"delta_E_mean": self.mean, "delta_E_max": self.max}
        if self.against:
            out["against"] = self.against
        if self.max_at is not None:
            out["max_at"] = self.max_at.to_dict()
        if self.layout == "curves":
            out["by_curve"] = [
                {"eta_i": r.eta_i, "delta_E_mean": r.mean, "delta_E_max": r.max} for r in self.rows or ()
            ]
            return out
        if self.rmse is not None:
            out["rmse"] = self.rmse
        if self.rows is not None:
            out["by_eta_i"] = {f"{r.eta_i:g}": {"delta_E_mean": r.mean, "delta_E_max": r.max} for r in self.rows}
        return out


def error_metrics(reference_RGB, model_RGB, eta_i_rows=None, against: str = "") -> ErrorMetrics:
    """
    Metrics between ``reference_RGB`` and ``model_RGB``, both (E, M, 3)
    linear ACEScg on a grid indexed [eta_i, cos_theta].

    Returns
    -------
    ErrorMetrics
        Mean and max Delta E 2000, ``rmse`` (linear RGB), and, when
        ``eta_i_rows`` (the eta_i of each row) is given, ``rows``: for each of
        :data:`BREAKDOWN_ETA_I` inside the grid, the mean and max Delta E of
        the nearest row.
    """
    return grid_metrics(reference_RGB, {"model": model_RGB}, eta_i_rows, against)["model"]


def grid_metrics(
    reference_RGB, models, eta_i_rows=None, against: str = "", cos_theta_columns=None
) -> dict[str, ErrorMetrics]:
    """
    :func:`error_metrics` of each of ``models`` (a mapping of name to (E, M,
    3) linear ACEScg) against the one ``reference_RGB``, keyed as
    ``models``: the reference is converted to Lab once for all of them.
    With ``eta_i_rows`` and ``cos_theta_columns`` (the grid's axes), each
    result says where its max is (``max_at``).
    """
    reference_RGB = np.asarray(reference_RGB, dtype=np.float64)
    reference_Lab = ACEScg_to_Lab(reference_RGB)
    breakdown: list[tuple[float, int]] = []
    if eta_i_rows is not None:
        grid = np.asarray(eta_i_rows, dtype=np.float64)
        breakdown = [
            (eta, int(np.argmin(np.abs(grid - eta))))
            for eta in BREAKDOWN_ETA_I
            if grid.min() - 1e-9 <= eta <= grid.max() + 1e-9
        ]
    out = {}
    # One map per model: stacked into one call they fall out of cache, and
    # take twice as long.
    for name, model_RGB in models.items():
        model_RGB = np.asarray(model_RGB, dtype=np.float64)
        dE = delta_E_2000(reference_Lab, ACEScg_to_Lab(model_RGB))
        max_at = None
        if eta_i_rows is not None and cos_theta_columns is not None:
            i, j = np.unravel_index(int(np.argmax(dE)), dE.shape)
            max_at = MaxAt(float(np.ravel(eta_i_rows)[i]), float(_theta_deg(np.ravel(cos_theta_columns)[j])))
        out[name] = ErrorMetrics(
            mean=float(dE.mean()),
            max=float(dE.max()),
            against=against,
            rows=None
            if eta_i_rows is None
            else tuple(EtaRow(eta, float(dE[i].mean()), float(dE[i].max())) for eta, i in breakdown),
            rmse=float(np.sqrt(np.mean((reference_RGB - model_RGB) ** 2))),
            max_at=max_at,
        )
    return out


def curve_metrics(curves, model_of, against: str = f"{AGAINST_CURVES}, at their samples") -> ErrorMetrics:
    """
    Delta E 2000 of a model against curves at their own samples: ``curves``
    have ``eta_i``, ``cos_theta`` and ``rgb``; ``model_of(curve)`` is the
    model's RGB at the curve's samples. One row per curve, in order.
    """
    maps = [delta_E_map(c.rgb, model_of(c)) for c in curves]
    every = np.concatenate(maps)
    worst = int(np.argmax(every))
    eta = np.concatenate([np.full(len(d), c.eta_i) for c, d in zip(curves, maps)])
    mu = np.concatenate([np.asarray(c.cos_theta, dtype=np.float64) for c in curves])
    return ErrorMetrics(
        mean=float(every.mean()),
        max=float(every.max()),
        against=against,
        rows=tuple(EtaRow(c.eta_i, float(d.mean()), float(d.max())) for c, d in zip(curves, maps)),
        layout="curves",
        max_at=MaxAt(float(eta[worst]), float(_theta_deg(mu[worst]))),
    )


def delta_E_summary(reference_RGB, model_RGB, against: str = "", layout: str = "summary") -> ErrorMetrics:
    """Mean and max Delta E 2000 of two linear ACEScg arrays, without breakdown."""
    dE = delta_E_map(reference_RGB, model_RGB)
    return ErrorMetrics(mean=float(dE.mean()), max=float(dE.max()), against=against, layout=layout)


def baseline_metrics(
    nk,
    cos_theta,
    eta_i,
    reference_RGB,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    against: str = "",
) -> dict[str, ErrorMetrics]:
    """
    :func:`error_metrics` of every baseline (:data:`fitting.models.baselines.BASELINES`)
    of ``nk`` against ``reference_RGB`` on the grid (cos_theta, eta_i), both
    (E, M) indexed [eta_i, cos_theta]; keyed by baseline name.
    """
    rows = np.asarray(eta_i)[:, 0]
    return grid_metrics(reference_RGB, baselines_ACEScg(nk, cos_theta, eta_i, 1.0, min_coverage), rows, against)
