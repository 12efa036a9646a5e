"""
Numerical stability on hard cases (docs/hard-cases.md): the fit and the
shader on data that break naive code. Nothing yields NaN or infinity, fits
are bit-for-bit deterministic, and each case ends in a fit with its error
reported or a clear refusal.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.hard_cases import HARD_CASES, critical_cos_theta, run_case, tir_band
from fitting.colour.reference import reference_ACEScg
from fitting.fits.material import fit_material
from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import FLOAT16_MAX, PackedMaterial, decode_pack, encode_pack, to_float16
from fitting.optics.fresnel import fresnel_conductor
from fitting.optics.library import library_material
from precision import GLSL_F32_BOUND

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

# Where every node's reflectance is exactly 1 (total internal reflection of
# SiO2, k = 0; grazing), only the 471-node weight sum rounds: L u64 sum|w| =
# 6e-14 in any summation order; 1e-12 with a 16x margin. Measured: 2.2e-16.
UNIT_REFLECTANCE_BOUND = 1e-12
# The GLSL model on llvmpipe in float32 against float64 numpy: the derived
# GLSL_F32_BOUND (tests/precision.py), relative to max(1, |F|) for the float16
# extremes whose values reach ~2e5.
GLSL_MODEL_REL = GLSL_F32_BOUND

REFUSED = {"TiO2", "Au 400-900 nm"}
GAP_REFUSED = {"Au 2 samples"}  # A 470 nm gap inside 360-830 nm (fitting/optics/quality.py)
# A dielectric fitted with the max guarded: TiO2's mean rises from 0.971 to about 1.05
# while its max falls from 12.6 to about 3.6 and the model comes inside [0, 1]. Which guard
# candidate wins on this dielectric turns on the last bits of the solvers' BLAS and SIMD
# arithmetic (the paper fit and SLSQP run LAPACK): measured on 40 x 40, the mean is 1.040 with
# numpy's baseline kernels, 1.045 with OpenBLAS Prescott, 1.043 on the EPYC of 2026-12-01 and 1.060 on an
# AVX-512 one (its own kernels, and OpenBLAS Haswell), the max 3.52-3.67. The bound 1.05 was
# set from one of them and failed on another; 1.10 is the documented figure
# (docs/hard-cases.md), above that spread with room for the CPUs not measured.
MEAN_BOUND = {"TiO2 min_coverage 0.8": 1.10}
TIR = {"SiO2", "water", "diamond"}
SAMPLES = 40
"""Side of the scoring grid here (the docs page uses the paper's 100)."""


@pytest.fixture(scope="module")
def outcomes():
    return {}


def outcome(outcomes, name):
    if name not in outcomes:
        outcomes[name] = run_case(name, SAMPLES)
    return outcomes[name]


class TestEveryCase:
    @pytest.mark.parametrize("name", sorted(HARD_CASES))
    def test_fit_with_error_or_clear_refusal(self, outcomes, name):
        row = outcome(outcomes, name)
        if name in REFUSED:
            assert row["outcome"] == "refused"
            assert "`wavelength_nm` must cover at least 90% of 360-830 nm" in row["message"]
            return
        if name in GAP_REFUSED:
            assert row["outcome"] == "refused"
            assert "must have no gap wider than 120 nm" in row["message"]
            return
        assert row["outcome"] == "fit"
        assert row["finite"]
        assert np.all(np.isfinite(row["delta_E_map"]))
        assert row["deterministic"]
        assert np.isfinite(row["delta_E_mean"]) and np.isfinite(row["delta_E_max"])
        assert row["coefficient_max"] < FLOAT16_MAX

    @pytest.mark.parametrize("name", sorted(set(HARD_CASES) - REFUSED - GAP_REFUSED - TIR))
    def test_without_tir_the_model_follows(self, outcomes, name):
        row = outcome(outcomes, name)
        assert row["tir_fraction"] == 0.0
        # A product figure (docs/hard-cases.md: mean Delta E below 1; TiO2 see MEAN_BOUND).
        assert row["delta_E_mean"] < MEAN_BOUND.get(name, 1.0)

    @pytest.mark.parametrize("name", sorted(TIR))
    def test_tir_error_sits_at_the_critical_angle(self, outcomes, name):
        row = outcome(outcomes, name)
        assert row["tir_fraction"] > 0.0
        # The model has no critical angle: the error is large there and the
        # map shows it, well above the rest of the grid (water, the mildest
        # case, 2.8 times with the 12 x 4 default grid).
        # Product figures of docs/hard-cases.md (max Delta E 26 near the
        # critical angle), not precision bounds.
        assert row["delta_E_max"] > 20.0
        assert row["delta_E_mean_band"] > 2.5 * row["delta_E_mean_outside"]


class TestTotalInternalReflection:
    def test_reference_is_one_inside_tir(self):
        nk = HARD_CASES["SiO2"][0]()
        mu = np.linspace(0.0, 1.0, 201)
        eta_i = 2.0
        R = reference_ACEScg(nk, mu, eta_i)
        mu_c = float(critical_cos_theta(nk, eta_i))
        assert 0.0 < mu_c < 1.0
        # Below the critical angle of every wavelength, R = 1 in all channels.
        n_max = float(nk.n[(nk.wavelength_nm >= 360) & (nk.wavelength_nm <= 830)].max())
        inside = mu < np.sqrt(1.0 - (n_max / eta_i) ** 2)
        np.testing.assert_allclose(R[inside], 1.0, atol=UNIT_REFLECTANCE_BOUND)  # tightened
        # from 1e-6 (no derivation): SiO2's k is 0, so R is 1 per node
        assert np.all(R[mu > mu_c + 0.05] < 0.9)  # physics, not rounding

    def test_band_marks_the_critical_angle(self):
        nk = HARD_CASES["SiO2"][0]()
        assert not tir_band(nk, 0.5, 1.2)
        mu_c = float(critical_cos_theta(nk, 2.0))
        assert tir_band(nk, mu_c, 2.0) and not tir_band(nk, mu_c + 0.2, 2.0)

    def test_index_matched_interface_is_finite(self):
        # Away from grazing no reflection; at grazing any rounding of
        # (n + ik) / eta_i away from 1 is a real interface, where R -> 1.
        R = fresnel_conductor(np.array([0.0, 1e-300, 1e-8, 0.5, 1.0]), 1.46, 1.46, 0.0)
        assert np.all(np.isfinite(R)) and np.all((R >= 0.0) & (R <= 1.0))
        np.testing.assert_allclose(R[3:], 0.0, atol=1e-12)  # index matched: the
        # numerator's difference is exactly 0 (measured 5e-32: rounding of 0)
        np.testing.assert_array_equal(fresnel_conductor(np.array([0.0, 0.5]), 1.0, 1.0, 0.0), 0.0)


class TestDomainEnds:
    @pytest.mark.parametrize("eta_i_range", [(1.0, 1.0), (3.0, 3.0), (1.0, 3.0)])
    def test_fit_at_the_ends(self, eta_i_range):
        result = fit_material(library_material("Cr"), eta_i_range, evaluate=True)
        assert result.success
        assert result.eta_i_range == eta_i_range
        metrics = result.metrics["model_float16"]
        assert (
            np.isfinite(metrics["delta_E_mean"]) and metrics["delta_E_mean"] < 1.0
        )  # product figure (docs/hard-cases.md)
        assert result.degree == (0 if eta_i_range[0] == eta_i_range[1] else 2)

    @pytest.mark.parametrize("eta_i_range", [(0.99, 2.0), (1.0, 3.0000001), (2.0, 1.5), (1.0, float("nan"))])
    def test_outside_the_domain_is_refused(self, eta_i_range):
        with pytest.raises(ValueError, match="`eta_i_range` must"):
            fit_material(library_material("Cr"), eta_i_range)

    def test_model_clamps_eta_i_outside_its_domain(self):
        C = fit_material(library_material("Cr"), (1.2, 2.0)).coefficients_float16
        mu = np.linspace(0.0, 1.0, 11)
        np.testing.assert_array_equal(
            coated_conductor_model(mu, 1.0, C, (1.2, 2.0)), coated_conductor_model(mu, 1.2, C, (1.2, 2.0))
        )
        np.testing.assert_array_equal(
            coated_conductor_model(mu, 3.0, C, (1.2, 2.0)), coated_conductor_model(mu, 2.0, C, (1.2, 2.0))
        )


class TestGrazing:
    def test_model_and_reference_are_one_at_grazing(self):
        nk = library_material("Al")
        C = fit_material(nk).coefficients_float16
        eta = np.array([1.0, 1.7, 2.5])
        np.testing.assert_array_equal(coated_conductor_model(0.0, eta, C), 1.0)
        np.testing.assert_allclose(reference_ACEScg(nk, 0.0, eta), 1.0, atol=UNIT_REFLECTANCE_BOUND)  # tightened
        # from 1e-9 (no derivation)

    def test_cos_theta_outside_unit_interval_is_clamped(self):
        C = fit_material(library_material("Al")).coefficients_float16
        F = coated_conductor_model(np.array([-1e-3, -5.0, 1.0 + 1e-9, 7.0]), 1.5, C)
        np.testing.assert_array_equal(F[:2], coated_conductor_model(0.0, 1.5, C)[None].repeat(2, 0))
        np.testing.assert_array_equal(F[2:], coated_conductor_model(1.0, 1.5, C)[None].repeat(2, 0))

    def test_near_grazing_is_smooth(self):
        C = fit_material(library_material("Ag")).coefficients_float16
        mu = np.geomspace(1e-12, 1e-2, 50)
        F = coated_conductor_model(mu, 2.5, C)
        assert np.all(np.isfinite(F))
        assert np.all(np.abs(F - 1.0) < 0.2)  # smoothness near grazing, not rounding


FLOAT16_EXTREMES = {
    "max": np.full((3, 3, 3), FLOAT16_MAX),
    "min": np.full((3, 3, 3), -FLOAT16_MAX),
    "alpha negative": np.concatenate([np.full((2, 3, 3), 0.5), np.full((1, 3, 3), -FLOAT16_MAX)]),
    "subnormal": np.full((3, 3, 3), 2.0**-24),
    "mixed": np.stack([np.full((3, 3), FLOAT16_MAX), np.full((3, 3), -FLOAT16_MAX), np.full((3, 3), 2.0**-24)]),
}


class TestFloat16Limits:
    @pytest.mark.parametrize("name", sorted(FLOAT16_EXTREMES))
    def test_model_stays_finite(self, name):
        C = to_float16(FLOAT16_EXTREMES[name])
        mu, eta = np.meshgrid(np.linspace(0.0, 1.0, 65), np.linspace(1.0, 3.0, 9))
        F = coated_conductor_model(mu, eta, C, (1.0, 2.5))
        assert np.all(np.isfinite(F))
        # |F| <= |F0| + |1 - F0| + |a| whatever alpha is, with |F0| and |a|
        # at most three powers of t in [0, 1] times the float16 maximum each.
        assert np.abs(F).max() <= 9.0 * FLOAT16_MAX + 1.0

    @pytest.mark.parametrize("name", sorted(FLOAT16_EXTREMES))
    def test_pack_round_trips(self, name):
        material = PackedMaterial(name, to_float16(FLOAT16_EXTREMES[name]), (1.0, 2.5))
        assert decode_pack(encode_pack([material])) == [material]

    def test_past_the_range_is_refused_not_inf(self):
        with pytest.raises(ValueError, match=r"`coefficients` must lie within the float16 range"):
            to_float16(np.full((3, 3, 3), 65520.0))
        with pytest.raises(ValueError, match="exactly representable in float16"):
            PackedMaterial("x", np.full((3, 3, 1), 1.0 + 2.0**-12), (1.5, 1.5))


class TestEvaluateWithLowCoverage:
    def test_metrics_honour_min_coverage(self):
        nk = HARD_CASES["TiO2 min_coverage 0.8"][0]()
        result = fit_material(nk, min_coverage=0.8, evaluate=True)
        assert result.metrics["coverage"] == pytest.approx(0.851, abs=1e-3)  # the data's coverage printed to 3 decimals


class TestSingleIndexFitWithUnidentifiableExponent:
    @pytest.mark.parametrize(
        "name, eta_i", [("Ag", 1.5151515151515151), ("Fe", 1.8787878787878789), ("Ta", 2.121212121212121)]
    )
    def test_fits(self, name, eta_i):
        result = fit_material(library_material(name), (eta_i, eta_i))
        assert np.all(np.isfinite(result.coefficients_float16))


@pytest.fixture(scope="module")
def thread():
    from preview_shaders.gl import RenderThread

    with RenderThread("test-hard-cases") as render_thread:
        yield render_thread


@pytest.mark.gl
class TestShaderOnHardCases:
    @pytest.mark.parametrize("name", ["SiO2", "diamond", "Si k=0", "Ag"])
    def test_fitted_hard_cases_render_as_numpy(self, thread, name):
        from preview_shaders.evaluate import evaluate_grid, shader_inputs

        nk = HARD_CASES[name][0]()
        packed = fit_material(nk).packed
        F, mu, eta = evaluate_grid(
            thread, "packed", shader_inputs(packed), (0.0, 1.0 / 63.0, 64), (1.0, 2.0 / 31.0, 32)
        )
        expected = coated_conductor_model(
            mu.astype(np.float64), eta.astype(np.float64), packed.coefficients, packed.eta_i_range
        )
        assert np.all(np.isfinite(F))
        assert np.abs(F - expected).max() <= GLSL_MODEL_REL * max(1.0, np.abs(expected).max())

    @pytest.mark.parametrize("name", sorted(FLOAT16_EXTREMES))
    def test_float16_extremes_render_finite(self, thread, name):
        from preview_shaders.evaluate import evaluate_grid, shader_inputs

        packed = PackedMaterial(name, to_float16(FLOAT16_EXTREMES[name]), (1.0, 2.5))
        F, mu, eta = evaluate_grid(
            thread, "packed", shader_inputs(packed), (0.0, 1.0 / 63.0, 64), (1.0, 2.0 / 15.0, 16)
        )
        assert np.all(np.isfinite(F))
        expected = coated_conductor_model(
            mu.astype(np.float64), eta.astype(np.float64), packed.coefficients, packed.eta_i_range
        )
        # float32 arithmetic on values up to ~2e5: relative agreement.
        assert np.abs(F - expected).max() <= GLSL_MODEL_REL * max(1.0, np.abs(expected).max())

    def test_exact_rgb_fresnel_shader_under_tir(self, thread):
        from preview_shaders.evaluate import evaluate_grid, shader_inputs

        packed = PackedMaterial("x", np.zeros((3, 3, 1), np.float16), (1.5, 1.5))
        n, k = np.array([1.46, 1.46, 1.46]), np.zeros(3)
        F, mu, eta = evaluate_grid(
            thread, "exact", shader_inputs(packed, n=n, k=k), (0.0, 1.0 / 127.0, 128), (1.0, 2.0 / 15.0, 16)
        )
        assert np.all(np.isfinite(F))
        expected = fresnel_conductor(mu.astype(np.float64)[..., None], eta.astype(np.float64)[..., None], n, k)
        # float32 Fresnel near the critical angle: t0 = 1 - (eta_i / n)^2 (1 -
        # mu^2) carries ~4 u32 (eta_i / n)^2 = 1e-6 absolute, its square root
        # 1e-6 / (2 sqrt(t0)), and R moves by <= ~4 per unit of sqrt(t0): at the
        # grid's closest point to critical (t0 >= ~1e-3) 6e-5 < 1e-4.
        np.testing.assert_allclose(F, expected, atol=1e-4)
        inside = mu < np.sqrt(np.clip(1.0 - (1.46 / eta) ** 2, 0.0, 1.0)) - 1e-3
        assert inside.any()
        # Inside TIR: |a|^2 / |b|^2 of conjugates, ~10 float32 roundings: 6e-7 < 1e-5.
        np.testing.assert_allclose(F[inside], 1.0, atol=1e-5)
