"""
The speed-against-error report (``benchmarks/speed_vs_error.py``,
docs/speed-vs-error.md) on small inputs: every model kind and split-sum
variant has its row, the split-sum error agrees with the Fresnel error where
the lobe is a mirror, and the summaries (error, Pareto front, batch
accuracy, tables) compute what they say. Correctness only; no timing.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmarks import speed_vs_error as sve
from benchmarks.speed_vs_error_figures import figure_batch
from benchmarks.speed_vs_error_report import (
    BATCH_BINS,
    batch_cell,
    batch_rows,
    batch_table,
    error_summary,
    kinds_table,
    models_table,
    pareto_front,
    read_batch_report,
    run_header,
    split_sum_table_lines,
)
from benchmarks.speed_vs_error_split_sum import (
    KIND_SPLIT_SUM,
    SPLIT_VARIANTS,
    split_sum_albedos,
    split_sum_errors,
)
from fitting.batch.report import accuracy_summary, report_rows
from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import reference_ACEScg
from fitting.fits.kinds import fit_model
from fitting.models.baselines import BASELINES, baseline_inputs, lazanyi_adjusted
from fitting.models.kinds import MODEL_KINDS, coefficient_count, model_ACEScg
from fitting.optics.library import library_material
from preview_shaders.evaluate import MODEL_VARIANTS, VARIANTS
from preview_shaders.shading import SPLIT_SUM_VARIANTS


class TestEveryKindAndVariant:
    def test_every_model_kind_has_a_row_with_its_shader_and_bytes(self):
        for kind in MODEL_KINDS:
            _, variant, size, _ = sve.MODELS[kind]
            assert variant == MODEL_VARIANTS[kind]
            assert size == 2 * coefficient_count(kind)

    def test_every_shader_variant_is_a_real_one(self):
        assert {spec[1] for spec in sve.MODELS.values() if spec[1]} <= set(VARIANTS)
        assert {spec[1] for spec in SPLIT_VARIANTS.values()} <= set(SPLIT_SUM_VARIANTS)

    def test_every_model_kind_has_its_split_sum_or_none(self):
        assert set(KIND_SPLIT_SUM) == set(MODEL_KINDS)
        assert all(v is None or v in SPLIT_VARIANTS for v in KIND_SPLIT_SUM.values())


@pytest.fixture(scope="module")
def gold():
    nk = library_material("Au")
    return nk, fit_model(nk, model="coated-conductor"), baseline_inputs(nk)


class TestSplitSum:
    @pytest.mark.slow  # 7.0 s (all cases 7.0 s) in a --durations=0 run
    def test_mirror_lobe_gives_the_fresnel_error(self, gold):
        # At roughness 0 (raised to ROUGHNESS_MIN) the lobe is a mirror: the albedo is F(NdotV),
        # so the split sum's Delta E is the Fresnel term's, up to the LUT's interpolation.
        nk, fit, air = gold
        mu = np.linspace(0.2, 1.0, 9)
        errors = split_sum_errors("Au", eta_i=(1.5,), roughness=(0.0,), NdotV=mu)
        reference = reference_ACEScg(nk, mu, 1.5)
        model = model_ACEScg("coated-conductor", mu, 1.5, fit.coefficients_float16, fit.eta_i_range)
        lazanyi = lazanyi_adjusted(mu, 1.5, air["F0_air"], air["F82_air"])
        # Not rounding: the LUT's interpolation at ROUGHNESS_MIN (the lobe is
        # almost a mirror) moves the albedo by ~1e-4, Delta E by ~0.01 at most
        # (Delta E 2000 ~100 per unit RGB here); a model claim, absolute for
        # the small model error, relative (1%) for Lazanyi's larger one.
        np.testing.assert_allclose(errors["split_sum_model"][0, 0], delta_E_map(reference, model), atol=0.01)
        np.testing.assert_allclose(errors["split_sum_lazanyi"][0, 0], delta_E_map(reference, lazanyi), rtol=0.01)

    def test_shapes_and_rough_lobe_ranking(self):
        errors = split_sum_errors("Au", eta_i=(1.0, 2.5), roughness=(0.5,), NdotV=np.array([0.3, 0.7]))
        assert set(errors) == set(SPLIT_VARIANTS)
        assert all(e.shape == (2, 1, 2) and np.all(np.isfinite(e)) for e in errors.values())
        assert errors["split_sum_model"].mean() < errors["split_sum_lazanyi"].mean()

    def test_reference_is_the_albedo_not_the_fresnel(self, gold):
        nk, fit, air = gold
        albedo = split_sum_albedos(nk, fit.coefficients_float16, fit.eta_i_range, 1.5, 1.0, np.array([0.5]), air)
        # A rough lobe darkens: its albedo is below the Fresnel term at normal incidence.
        assert np.all(albedo["reference"] < reference_ACEScg(nk, 1.0, 1.5))
        assert all(a.shape == (1, 3) for a in albedo.values())

    def test_nan_NdotV_is_refused_by_name(self, gold):
        nk, fit, air = gold
        with pytest.raises(ValueError, match="NdotV"):
            split_sum_albedos(nk, fit.coefficients_float16, fit.eta_i_range, 1.5, 0.3, np.array([np.nan]), air)


class TestErrorSummary:
    def test_mean_of_means_max_and_worst(self):
        s = error_summary({"A": np.array([1.0, 3.0]), "B": np.array([[0.5, 5.0], [0.5, 0.0]])})
        assert s == {"mean": 1.75, "max": 5.0, "worst": "A", "worst_mean": 2.0, "worst_max": 3.0}

    def test_nothing_is_refused(self):
        with pytest.raises(ValueError, match="per_material"):
            error_summary({})


class TestParetoFront:
    def test_dominated_and_ties(self):
        points = {"cheap": (1.0, 5.0), "good": (3.0, 1.0), "worse": (3.0, 2.0), "same": (1.0, 5.0), "mid": (2.0, 5.0)}
        # "same" ties "cheap" exactly: neither dominates the other.
        assert pareto_front(points) == ["cheap", "same", "good"]

    def test_one_point(self):
        assert pareto_front({"a": (1.0, 1.0)}) == ["a"]


MODELS = {
    "fast": ("Fast", "schlick", 12, ""),
    "base": ("Base", "lazanyi", 24, ""),
    "ref": ("Reference", None, 3768, ""),
}


class TestTables:
    def test_models_table_ratios_fronts_and_no_shader(self):
        rows = {
            m: {"mean": e, "max": 2 * e, "worst": "Au", "worst_mean": e, "worst_max": 2 * e}
            for m, e in (("fast", 3.0), ("base", 2.0), ("ref", 0.0))
        }
        lines, out = models_table(
            MODELS, rows, {"fast": 10.0, "base": 20.0, "ref": 1e4}, {"schlick": 50.0, "lazanyi": 100.0}, pixels=1000
        )
        assert out["ratio"] == {"fast": 0.5, "base": 1.0, "ref": None}
        assert out["shader"] == ["fast", "base"] and out["cpu"] == ["fast", "base", "ref"]
        assert len(lines) == 2 + len(MODELS)
        assert "| Fast | 3.000 | 6.00 | Au: 3.000 / 6.00 | 0.50x | 50.00 | 10 | 12 | yes / yes / yes |" in lines
        assert "n/a (no shader)" in lines[-1]

    def test_split_sum_raw_and_net_ratios(self):
        variants = {"m": ("model", "split_sum_model", 24), "l": ("Lazanyi", "split_sum_lazanyi", 8)}
        split = {
            "m": {
                "mean": 0.1,
                "max": 0.5,
                "worst": "W",
                "worst_mean": 0.2,
                "worst_max": 0.5,
                "by_roughness": [0.05, 0.15],
            },
            "l": {
                "mean": 4.0,
                "max": 9.0,
                "worst": "Au",
                "worst_mean": 6.0,
                "worst_max": 9.0,
                "by_roughness": [4.0, 4.0],
            },
        }
        shader = {"split_sum_model": 300.0, "split_sum_lazanyi": 150.0, "split_sum_fixed": 50.0}
        lines, out = split_sum_table_lines(variants, split, {"m": 90.0, "l": 30.0}, shader, 100, (0.1, 0.6))
        assert out["raw"] == {"m": 2.0, "l": 1.0} and out["net"] == {"m": 2.5, "l": 1.0}
        assert out["front"] == ["l", "m"]
        assert "roughness 0.1 / 0.6" in lines[0]
        assert (
            "| model | 0.100 | 0.50 | W: 0.200 / 0.50 | 0.050 / 0.150 | 3000.00 | 2.00x / 2.50x | 90 | 24 | yes |"
            in lines
        )

    def test_run_header_names_command_and_load(self):
        lines = run_header(["--models-only", "--batch-report", "a b/report.json"], "llvmpipe")
        assert lines[0] == (
            "Command: `.venv/bin/python benchmarks/speed_vs_error.py --models-only --batch-report 'a b/report.json'`"
        )
        assert "load average" in lines[1] and lines[1].endswith("GL: llvmpipe")


def _record(page, status, kinds=None, laz=None):
    """A journal record as fitting.batch.page makes it, with only the means that matter here."""
    fitted = status == "fitted"
    return {
        "page": page,
        "status": status,
        "reason": None if fitted else "covers 10% of 360-830 nm",
        "coverage": 1.0 if fitted else 0.1,
        "wavelength_range_nm": [300.0, 900.0],
        "kinds": {k: {"delta_E_mean": v, "delta_E_max": 2 * v} for k, v in (kinds or {}).items()},
        "baselines": {b: {"delta_E_mean": laz, "delta_E_max": 2 * laz} for b in BASELINES} if fitted else {},
    }


@pytest.fixture
def report(tmp_path):
    """A report.json as fitting.batch.report.write_outputs writes it, over 4 fitted pages and
    one skipped; rgb-conductor beats adjusted Lazanyi on 3 of 4."""
    kinds, baselines = ("coated-conductor", "rgb-conductor"), BASELINES
    records = [
        _record("main/A/x", "fitted", {"coated-conductor": 0.2, "rgb-conductor": 0.1}, laz=4.0),
        _record("main/B/x", "fitted", {"coated-conductor": 0.7, "rgb-conductor": 0.3}, laz=4.0),
        _record("main/C/x", "fitted", {"coated-conductor": 3.0, "rgb-conductor": 12.0}, laz=8.0),
        _record("main/D/x", "fitted", {"coated-conductor": 9.0, "rgb-conductor": 1.5}, laz=2.0),
        _record("main/E/x", "skipped"),
    ]
    config = {
        "model_kinds": list(kinds),
        "baselines": list(baselines),
        "grid": "100x100",
        "eta_i_range": [1.0, 2.5],
        "reference_step_nm": 1.0,
    }
    body = {
        "config": config,
        "summary": accuracy_summary(records, kinds, baselines),
        "pages": report_rows(records, kinds, baselines),
    }
    path = tmp_path / "shelf" / "report.json"
    path.parent.mkdir()
    path.write_text(json.dumps(body), encoding="utf-8")
    return read_batch_report(path)


class TestBatchSummary:
    def test_rows_per_kind_and_baseline(self, report):
        rows = {r["name"]: r for r in batch_rows(report)}
        assert list(rows) == ["coated-conductor", "rgb-conductor", *BASELINES]
        coated, rgb = rows["coated-conductor"], rows["rgb-conductor"]
        assert coated["pages"] == 4 and coated["kind"] and not rows["lazanyi_adjusted"]["kind"]
        # Order statistics of 4 given numbers: exact up to one interpolation
        # (a few u64); approx's default rel=1e-6 tightened to 1e-12.
        assert coated["median"] == pytest.approx(1.85, rel=1e-12) and coated["max"] == 9.0
        assert coated["p90"] == pytest.approx(np.quantile([0.2, 0.7, 3.0, 9.0], 0.9), rel=1e-12)
        # Bins 0-0.5, 0.5-1, 1-2, 2-5, 5-10, >10.
        assert len(coated["shares"]) == len(BATCH_BINS) - 1
        assert coated["shares"] == [0.25, 0.25, 0.0, 0.25, 0.25, 0.0]
        assert rgb["shares"] == [0.5, 0.0, 0.25, 0.0, 0.0, 0.25]
        assert coated["beats"] == 0.75 and rgb["beats"] == 0.75
        assert rows["lazanyi_adjusted"]["beats"] is None

    def test_cells_and_tables(self, report):
        assert batch_cell(report, "coated-conductor") == "1.850 / 7.200 / 9.00; 75.0%"
        assert batch_cell(report, "lazanyi_adjusted") == "4.000 / 6.800 / 8.00"
        assert batch_cell(report, "no-such-kind") == "not in this batch"
        lines = batch_table(report)
        assert lines[0].startswith("## Database batch: 4 of 5 pages fitted (1 skipped, 0 failed)")
        assert "| rgb-conductor | 3.475 | 0.900 | 8.850 | 12.00 | 50% | 0% | 25% | 0% | 0% | 25% | 75.0% |" in lines

    def test_kinds_table_one_column_per_report(self, report):
        rows = [
            {
                "name": "coated-conductor",
                "label": "coated",
                "bytes": 54,
                "mean": 0.147,
                "max": 1.27,
                "shader_ns_px": 10.0,
                "shader_ratio": 2.9,
                "cpu_ns": 236.0,
                "split_mean": 0.2,
                "split_ratio": 2.7,
            },
            {
                "name": "rgb-conductor",
                "label": "rgb",
                "bytes": 12,
                "mean": 0.019,
                "max": 0.22,
                "shader_ns_px": 6.0,
                "shader_ratio": 1.6,
                "cpu_ns": 500.0,
                "split_mean": None,
                "split_ratio": None,
            },
        ]
        lines = kinds_table(rows, [report, report])
        assert lines[0].count("batch shelf (4 pages)") == 2
        assert lines[1].count("|") == lines[0].count("|")
        assert lines[2] == (
            "| coated | 54 | 0.147 | 1.27 | 10.00 | 2.90x | 236 | 0.200 | 2.70x | "
            "1.850 / 7.200 / 9.00; 75.0% | 1.850 / 7.200 / 9.00; 75.0% |"
        )
        assert "| no split-sum table | n/a |" in lines[3]

    def test_not_a_report_is_refused_by_file(self, tmp_path):
        path = tmp_path / "pack.json"
        path.write_text('{"materials": []}', encoding="utf-8")
        with pytest.raises(ValueError, match="pack.json.*not a batch report.*no config, summary, pages"):
            read_batch_report(path)
        path.write_text("[]", encoding="utf-8")
        with pytest.raises(ValueError, match="not a JSON object"):
            read_batch_report(path)

    @pytest.mark.slow  # 2.5 s at load 3.5 in the quick loop's run, 1.1 s of CPU
    def test_batch_figure_is_a_png(self, report, tmp_path):
        path = tmp_path / "images" / "batch.png"
        figure_batch(path, [report], ["coated-conductor", "rgb-conductor", "lazanyi_adjusted"])
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
