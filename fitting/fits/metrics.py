"""
Error metrics
=============

-   :func:`error_metrics`: mean and max CIE Delta E 2000 and RMSE between a
    reference and an approximation on the scoring grid, with the breakdown per
    eta_i row.
-   :func:`baseline_metrics`: the same for every baseline of
    :mod:`fitting.models.baselines`.

Lab uses the ACES white as reference white (:func:`fitting.colour.colorimetry.ACEScg_to_Lab`).

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Sections 4.1 and 4.3.
"""

from __future__ import annotations

import numpy as np

from ..colour.delta_e import delta_E_map
from ..domain import DEFAULT_MIN_COVERAGE
from ..models.baselines import BASELINES, baseline_ACEScg

__all__ = ["BREAKDOWN_ETA_I", "delta_E_map", "error_metrics", "baseline_metrics"]

BREAKDOWN_ETA_I = (1.0, 1.5, 2.0, 2.5)


def error_metrics(reference_RGB, model_RGB, eta_i_rows=None) -> dict:
    """
    Metrics between ``reference_RGB`` and ``model_RGB``, both (E, M, 3)
    linear ACEScg on a grid indexed [eta_i, cos_theta].

    Returns
    -------
    dict
        ``delta_E_mean``, ``delta_E_max``, ``rmse`` (linear RGB), and, when
        ``eta_i_rows`` (the eta_i of each row) is given, ``by_eta_i``: for
        each of :data:`BREAKDOWN_ETA_I` inside the grid, the mean and max
        Delta E of the nearest row.
    """
    reference_RGB = np.asarray(reference_RGB, dtype=np.float64)
    model_RGB = np.asarray(model_RGB, dtype=np.float64)
    dE = delta_E_map(reference_RGB, model_RGB)
    out = {
        "delta_E_mean": float(dE.mean()),
        "delta_E_max": float(dE.max()),
        "rmse": float(np.sqrt(np.mean((reference_RGB - model_RGB) ** 2))),
    }
    if eta_i_rows is not None:
        rows = np.asarray(eta_i_rows, dtype=np.float64)
        by = {}
        for eta in BREAKDOWN_ETA_I:
            if rows.min() - 1e-9 <= eta <= rows.max() + 1e-9:
                i = int(np.argmin(np.abs(rows - eta)))
                by[f"{eta:g}"] = {
                    "delta_E_mean": float(dE[i].mean()),
                    "delta_E_max": float(dE[i].max()),
                }
        out["by_eta_i"] = by
    return out


def baseline_metrics(nk, cos_theta, eta_i, reference_RGB, min_coverage: float = DEFAULT_MIN_COVERAGE) -> dict:
    """
    :func:`error_metrics` of every baseline (:data:`fitting.models.baselines.BASELINES`)
    of ``nk`` against ``reference_RGB`` on the grid (cos_theta, eta_i), both
    (E, M) indexed [eta_i, cos_theta]; keyed by baseline name.
    """
    rows = np.asarray(eta_i)[:, 0]
    return {
        name: error_metrics(
            reference_RGB, baseline_ACEScg(name, nk, cos_theta, eta_i, 1.0, min_coverage), rows
        )
        for name in BASELINES
    }
