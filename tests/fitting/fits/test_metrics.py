"""fitting.fits.metrics: one typed result for every error, and its JSON."""

from dataclasses import FrozenInstanceError

import numpy as np
import pytest

from fitting.colour.delta_e import delta_E_map
from fitting.fits.metrics import (
    BREAKDOWN_ETA_I,
    ErrorMetrics,
    EtaRow,
    curve_metrics,
    delta_E_summary,
    error_metrics,
    grid_metrics,
)
from fitting.fits.curves_input import RGBCurve

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

RNG = np.random.default_rng(9)
REF = RNG.uniform(0.05, 0.9, (4, 7, 3))
MODEL = np.clip(REF + RNG.normal(0.0, 0.02, REF.shape), 0.0, 1.0)


class TestErrorMetrics:
    def test_grid_json_is_todays(self):
        rows = np.array([1.0, 1.5, 2.0, 2.5])
        m = error_metrics(REF, MODEL, rows, "a 4 x 7 test grid")
        dE = delta_E_map(REF, MODEL)
        assert m.against == "a 4 x 7 test grid"
        assert m.mean == float(dE.mean()) and m.max == float(dE.max())
        assert [r.eta_i for r in m.rows] == list(BREAKDOWN_ETA_I)
        assert m.row(2.0) == EtaRow(2.0, float(dE[2].mean()), float(dE[2].max()))
        view = m.to_dict()
        assert list(view) == ["delta_E_mean", "delta_E_max", "against", "rmse", "by_eta_i"]
        assert list(view["by_eta_i"]) == ["1", "1.5", "2", "2.5"]
        assert view["by_eta_i"]["1.5"] == {"delta_E_mean": float(dE[1].mean()), "delta_E_max": float(dE[1].max())}
        assert view["rmse"] == pytest.approx(np.sqrt(np.mean((REF - MODEL) ** 2)), rel=1e-15)  # the same sum, once
        # more: 28 squares, a sqrt: <= 4 u64 relative

    def test_without_rows_there_is_no_breakdown(self):
        assert "by_eta_i" not in error_metrics(REF, MODEL).to_dict()
        # Rows outside every breakdown eta_i: an empty breakdown, as before.
        view = error_metrics(REF, MODEL, np.array([2.6, 2.7, 2.8, 2.9])).to_dict()
        assert view["by_eta_i"] == {}
        with pytest.raises(LookupError, match="no row at eta_i 1.5"):
            error_metrics(REF, MODEL).row(1.5)

    def test_curve_and_summary_layouts(self):
        mu = np.linspace(0.0, 1.0, 7)
        curves = [RGBCurve(1.0, mu, REF[0]), RGBCurve(2.0, mu, REF[2])]
        models = {1.0: MODEL[0], 2.0: MODEL[2]}
        m = curve_metrics(curves, lambda c: models[c.eta_i])
        view = m.to_dict()
        assert list(view) == ["delta_E_mean", "delta_E_max", "against", "max_at", "by_curve"]
        assert view["against"] == "your edited curves, at their samples"
        assert [c["eta_i"] for c in view["by_curve"]] == [1.0, 2.0]
        both = np.concatenate([delta_E_map(REF[0], MODEL[0]), delta_E_map(REF[2], MODEL[2])])
        worst = int(np.argmax(both))  # the max's place: the curve and the angle of that sample
        assert view["max_at"] == {
            "eta_i": [1.0, 2.0][worst // 7],
            "theta_deg": float(np.degrees(np.arccos(mu[worst % 7]))),
        }
        assert m.figure() == {
            "against": view["against"],
            "delta_E_mean": m.mean,
            "delta_E_max": m.max,
            "max_at": view["max_at"],
        }
        assert view["delta_E_mean"] == float(both.mean())
        s = delta_E_summary(REF, MODEL, "x")
        assert s.to_dict() == {"mean": m_mean(REF, MODEL), "max": float(delta_E_map(REF, MODEL).max())}
        assert delta_E_summary(REF, MODEL, layout="grid").to_dict() == {
            "delta_E_mean": m_mean(REF, MODEL),
            "delta_E_max": float(delta_E_map(REF, MODEL).max()),
        }

    def test_frozen_and_layout_checked(self):
        m = ErrorMetrics(0.1, 0.2, "x")
        with pytest.raises(FrozenInstanceError):
            m.mean = 0.0
        with pytest.raises(ValueError, match="`layout` must be one of grid, curves, summary"):
            ErrorMetrics(0.1, 0.2, "x", layout="table")


class TestGridMetrics:
    def test_each_model_as_error_metrics(self):
        rows = np.array([1.0, 1.5, 2.0, 2.5])
        other = np.clip(REF * 1.03, 0.0, 1.0)
        every = grid_metrics(REF, {"b": other, "a": MODEL}, rows, "grid")
        assert list(every) == ["b", "a"]
        assert every["a"] == error_metrics(REF, MODEL, rows, "grid")
        assert every["b"] == error_metrics(REF, other, rows, "grid")
        assert grid_metrics(REF, {}) == {}


def m_mean(ref, model) -> float:
    return float(delta_E_map(ref, model).mean())
