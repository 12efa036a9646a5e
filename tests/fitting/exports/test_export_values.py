"""The values every export carries, the tool Fresnel mirrors and the input rules."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.exports import ExportValues, export_fidelity, export_material, export_values
from fitting.exports.tool_fresnel import (
    F82_COS_THETA,
    TOOL_MODELS,
    f82_tint,
    mx_fresnel_conductor,
    schlick,
    tool_curve,
)
from fitting.exports.colour_space import ACEScg_to_lin_rec709, lin_rec709_to_ACEScg
from fitting.exports.seen_fit import (
    fit_channel_conductor as _fit_relative_index,
    fit_channel_f82 as _fit_f82_tint,
    fit_channel_schlick as _fit_schlick,
)
from fitting.exports.values import EXPORT_SAMPLES, project_version
from fitting.optics.fresnel import fresnel_conductor
from fitting.optics.library import library_material
from precision import F64_FEW_OPS
from fitting.fits.rgb_conductor import rgb_nk

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

# 3 x 3 colour-space matrices (condition ~3) applied once or twice: ~10
# roundings of values <= 1 each: 30 u64 = 3e-15; 1e-12 with a 300x margin.
MATRIX_BOUND = 1e-12

MU = np.linspace(0.0, 1.0, EXPORT_SAMPLES)


@pytest.fixture(scope="module")
def cu_values() -> ExportValues:
    return export_values(library_material("Cu"), 1.5)


class TestMxFresnelConductor:
    def test_matches_complex_fresnel(self):
        rng = np.random.default_rng(7)
        for _ in range(20):
            n, k = rng.uniform(0.05, 4.0, 3), rng.uniform(0.0, 8.0, 3)
            np.testing.assert_allclose(
                mx_fresnel_conductor(MU, n, k),
                fresnel_conductor(MU[:, None], 1.0, n, k),
                atol=1e-10,  # two closed forms (MaterialX's real-arithmetic one,
                # the complex one): ~30 roundings of terms up to n^2 + k^2 <= 80:
                # 2400 u64 = 2.7e-13, so 1e-10 has a 400x margin
            )

    def test_normal_incidence_closed_form(self):
        # R(0 deg) = ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2); gold-like index at 550 nm.
        n, k = np.array([0.43, 0.43, 0.43]), np.array([2.45, 2.45, 2.45])
        expected = ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)
        np.testing.assert_allclose(mx_fresnel_conductor(np.array([1.0]), n, k)[0], expected, rtol=1e-12)  # ~10
        # roundings, the difference n - 1 of condition <= 4: 40 u64 = 4e-15

    def test_grazing_is_one_and_clamped(self):
        n, k = np.full(3, 0.2), np.full(3, 3.0)
        # Grazing (and clamped to it): 1 to a few roundings (tightened from the
        # default rtol=1e-7).
        np.testing.assert_allclose(mx_fresnel_conductor(np.array([0.0, -0.5]), n, k), 1.0, rtol=F64_FEW_OPS)


class TestF82Tint:
    def test_anchors(self):
        F0, tint = np.array([0.9, 0.6, 0.4]), np.array([0.8, 0.9, 1.0])
        mu = np.array([1.0, F82_COS_THETA, 0.0])
        F = f82_tint(mu, F0, tint)
        np.testing.assert_allclose(F[0], F0, atol=1e-15)  # mu = 1: the
        # correction terms vanish; a few roundings of F0 <= 1 (4 u64 = 4.4e-16)
        np.testing.assert_allclose(F[1], tint * schlick(F82_COS_THETA, F0), rtol=1e-12)  # the
        # F82 correction solved and evaluated back: ~20 roundings (pow) of
        # condition <= ~10: 200 u64 = 2e-14
        np.testing.assert_allclose(F[2], 1.0, atol=1e-15)  # grazing, as mu = 1

    def test_white_tint_is_schlick(self):
        F0 = np.array([0.5, 0.3, 0.1])
        np.testing.assert_allclose(f82_tint(MU, F0, np.ones(3)), schlick(MU, F0), atol=1e-15)  # a
        # white tint makes the correction exactly 0: Schlick's few roundings

    def test_schlick_shapes(self):
        assert schlick(MU, 0.04).shape == MU.shape
        assert schlick(MU, np.zeros(3)).shape == MU.shape + (3,)
        assert schlick(0.5, np.zeros(3)).shape == (3,)


class TestFits:
    def test_relative_index_recovered(self):
        n, k = np.array([0.2, 0.6, 1.1]), np.array([3.0, 2.2, 1.7])
        got_n, got_k = _fit_relative_index(MU, fresnel_conductor(MU[:, None], 1.0, n, k))
        # Not rounding: the least-squares fit's convergence (its tolerance) on
        # exact Fresnel curves; 1e-5 is the recovery claim.
        np.testing.assert_allclose(got_n, n, rtol=1e-5)
        np.testing.assert_allclose(got_k, k, rtol=1e-5)

    def test_f82_recovered(self):
        F0, tint = np.array([0.95, 0.64, 0.54]), np.array([0.85, 0.9, 0.7])
        got_F0, got_tint = _fit_f82_tint(MU, f82_tint(MU, F0, tint))
        # The fit's convergence claim as above (the tint, divided by Schlick at
        # F82, less well determined), not rounding.
        np.testing.assert_allclose(got_F0, F0, atol=1e-7)
        np.testing.assert_allclose(got_tint, tint, atol=1e-6)

    def test_joint_channels_reach_the_per_channel_optimum(self, cu_values):
        # One solve of the three channels against three: the same optimum to the solves' tolerances
        # (1e-12 on steps and cost; the conductor's n, k are less well determined: 1e-8).
        for fit, atol in ((_fit_relative_index, 1e-8), (_fit_f82_tint, 1e-9)):
            for got, want in zip(fit(MU, cu_values.target, joint=True), fit(MU, cu_values.target)):
                np.testing.assert_allclose(got, want, atol=atol)

    def test_schlick_recovered_and_clipped(self):
        F0 = np.array([0.2, 0.5, 0.9])
        np.testing.assert_allclose(_fit_schlick(MU, schlick(MU, F0)), F0, atol=1e-12)  # a linear
        # least squares in F0 of condition ~10 over EXPORT_SAMPLES sums: < 1e3 u64 = 1.1e-13
        assert np.all(_fit_schlick(MU, schlick(MU, np.array([1.2, 0.5, -0.1]))) <= 1.0)

    def test_tints_within_tool_ranges(self, cu_values):
        for values in (cu_values.F0, cu_values.F82_tint, cu_values.F0_schlick):
            assert np.all((values >= 0.0) & (values <= 1.0))


class TestColourSpaces:
    def test_white_stays_white_and_round_trip(self):
        np.testing.assert_allclose(ACEScg_to_lin_rec709(np.ones(3)), 1.0, atol=MATRIX_BOUND)
        rgb = np.random.default_rng(1).uniform(0, 1, (5, 3))
        np.testing.assert_allclose(lin_rec709_to_ACEScg(ACEScg_to_lin_rec709(rgb)), rgb, atol=MATRIX_BOUND)

    def test_target_is_the_reference_in_rec709(self, cu_values):
        np.testing.assert_allclose(lin_rec709_to_ACEScg(cu_values.target), cu_values.target_ACEScg, atol=MATRIX_BOUND)

    def test_formats_share_one_target_per_material_and_space(self, cu_values):
        # Another format of the same n, k and eta_i reuses the seen target and the naive fits
        # (read-only); another working space reuses the seen target only.
        again = export_values(library_material("Cu"), 1.5, tools=("gltf",))
        for name in ("seen_ACEScg", "target_ACEScg", "target", "n_rel", "F82_tint"):
            assert getattr(again, name) is getattr(cu_values, name) and not getattr(again, name).flags.writeable
        other = export_values(library_material("Cu"), 1.5, tools=("gltf",), working_space="acescg")
        assert other.seen_ACEScg is cu_values.seen_ACEScg and other.target is not cu_values.target
        np.testing.assert_array_equal(other.target, cu_values.target_ACEScg)


class TestFidelity:
    def test_every_target_finite_and_ordered(self, cu_values):
        scores = {t: export_fidelity(cu_values, t) for t in TOOL_MODELS}
        for s in scores.values():
            assert np.isfinite(s["delta_E_mean"]) and s["delta_E_max"] >= s["delta_E_mean"] >= 0
        # The exact conductor at the fitted relative index beats Schlick by far
        # (product figures of docs/exports.md, not precision bounds).
        assert scores["mtlx"]["delta_E_mean"] < 0.1 < scores["gltf"]["delta_E_mean"]
        assert scores["mtlx"] == scores["blender-conductor"]
        assert scores["openpbr"] == scores["blender"]

    def test_refit_in_rec709_beats_pasting_acescg_values(self, cu_values):
        # The air-fitted ACEScg index pasted unchanged into a Rec.709 tool.
        n, k = rgb_nk(library_material("Cu"))
        pasted = export_fidelity(ExportValues(**{**cu_values.__dict__, "n_rel": n / 1.5, "k_rel": k / 1.5}), "mtlx")
        assert export_fidelity(cu_values, "mtlx")["delta_E_mean"] < pasted["delta_E_mean"] / 10

    def test_unknown_target(self, cu_values):
        with pytest.raises(ValueError, match="`target` must be one of"):
            tool_curve(cu_values, "usd")


class TestInputs:
    @pytest.mark.slow  # 1.8-2.5 s in a --durations run since the conductor exports' view-dependent fit
    def test_rgb_conductor_mapping(self):
        values = export_values({"name": "X", "source": "s", "n": [0.3, 0.5, 1.2], "k": [3, 2.5, 2]}, 1.5)
        assert values.name == "X" and values.origin.startswith("rgb-conductor")
        # A per-channel conductor in ACEScg primaries is not one in Rec.709's:
        # the refit loses a little, far less than Schlick.
        mtlx = export_fidelity(values, "mtlx")["delta_E_mean"]
        assert mtlx < 0.3 and mtlx < export_fidelity(values, "gltf")["delta_E_mean"] / 3

    @pytest.mark.parametrize(
        "eta_i, rule",
        [
            (0.8, "`eta_i` must lie in [1, 3], got 0.8"),
            (3.5, "`eta_i` must lie in [1, 3], got 3.5"),
            (float("nan"), "`eta_i` must lie in [1, 3], got nan"),
            ("x", "`eta_i` must be a number, got 'x'"),
        ],
    )
    def test_bad_eta_i(self, eta_i, rule):
        with pytest.raises(ValueError) as info:
            export_material(library_material("Cu"), "mtlx", eta_i)
        assert str(info.value).startswith(rule)

    def test_bad_format_roughness_and_input(self, cu_values):
        with pytest.raises(ValueError, match="`format` must be one of mtlx, openpbr, blender, gltf, glb, got 'usd'"):
            export_material(cu_values, "usd", 1.5)
        with pytest.raises(ValueError, match=r"`roughness` must be a number in \[0, 1\], got 1.5"):
            export_values(library_material("Cu"), 1.5, roughness=1.5)
        with pytest.raises(ValueError, match=r"`coat_roughness` must be a number in \[0, 1\], got -0.1"):
            export_values(library_material("Cu"), 1.5, coat_roughness=-0.1)
        with pytest.raises(ValueError, match="`fit_or_nk` must be a SpectralNK"):
            export_values([1, 2, 3], 1.5)
        with pytest.raises(ValueError, match="`eta_i` must be the values' own 1.5"):
            export_material(cu_values, "mtlx", 2.0)

    def test_provenance(self, cu_values):
        info = cu_values.provenance("kind", export_fidelity(cu_values, "mtlx"))
        assert info["material"] == "Cu" and info["eta_i"] == 1.5 and info["model_kind"] == "kind"
        assert "Johnson" in info["source"] and "\n" not in info["source"]
        assert info["generator"] == f"coated-fresnel {project_version()}" != "coated-fresnel unknown"
        assert info["delta_E_2000_seen"].startswith("mean ")
