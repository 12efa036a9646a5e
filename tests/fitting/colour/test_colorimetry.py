"""fitting.colour (colorimetry, delta_e): against colour-science."""

import numpy as np
import pytest

from fitting.colour.colorimetry import (
    ACES_WHITE_XY,
    ACEScg_to_Lab,
    ACEScg_to_Lab_and_jacobian,
    ACEScg_to_Lab_jacobian,
    ACEScg_to_XYZ,
    spectral_to_ACEScg_weights,
)
from fitting.colour.delta_e import delta_E_2000
from fitting.colour.reference import spectral_grid, spectral_weights

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

U64 = 2.0**-53  # float64 unit roundoff
# A weighted sum over at most 471 nodes (sum|w| <= 1.147): at most
# L u64 sum|w| = 6e-14 whatever order numpy's SIMD or the BLAS kernel sums
# in. 1e-12 is that with a 16x margin. Measured: 5.6e-16 (white), 1.7e-16
# (linear spectrum).
WEIGHT_SUM_BOUND = 1e-12
# Lab against colour-science's Lab of the same XYZ: L = 116 f(Y) - 16,
# a* = 500 (f(X) - f(Y)), b* = 200 (...), each f a cube root (numpy's cbrt
# or power: <= 4 ulps, SIMD or not) after ~10 roundings: at most
# 500 * 2 * 16 u64 = 1.8e-12. Tightened from 1e-9 (no derivation) to 1e-11,
# the bound with a 5x margin. Measured: 2.1e-14.
LAB_BOUND = 1e-11


class TestColorimetry:
    def test_stored_constants_are_colour_sciences(self):
        """
        The weights and matrix a fit reads from the package are colour-science's, to the rounding of
        their own computation on this CPU's BLAS kernels (the stored ones were written on another).
        Each weight is the XYZ-to-ACEScg matrix times CAT02
        times the CIE weights (two chained products of 3 terms: at most 6 roundings, each of a term at
        most 3 max|M| * 3 max|CAT| * max|W_XYZ|), then divided by its row's sum (1 in ACEScg's white).
        """
        import colour

        from fitting.colour.colorimetry import _stored, colour_science_constants
        from fitting.domain import VISIBLE_RANGE_NM

        weights, RGB_to_XYZ = colour_science_constants()
        stored_weights, stored_matrix = _stored()
        # ACEScg's matrix is made from its primaries and white by a 3 x 3 inversion and product
        # (condition number under 4): within 64 roundings of its largest entry.
        eps = np.finfo(np.float64).eps
        np.testing.assert_allclose(stored_matrix, RGB_to_XYZ, rtol=0, atol=64 * eps * np.abs(RGB_to_XYZ).max())
        shape = colour.SpectralShape(VISIBLE_RANGE_NM[0], VISIBLE_RANGE_NM[1], 1)
        cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape).values
        W_XYZ = cmfs.T / cmfs[:, 1].sum()  # the CIE weights' size (the illuminant is within 2x of flat)
        acescg = colour.RGB_COLOURSPACES["ACEScg"]
        cat = colour.adaptation.matrix_chromatic_adaptation_VonKries(
            W_XYZ.sum(axis=1), acescg.matrix_RGB_to_XYZ @ np.ones(3), transform="CAT02"
        )
        term = 3 * np.abs(acescg.matrix_XYZ_to_RGB).max() * 3 * np.abs(cat).max() * 2 * np.abs(W_XYZ).max()
        bound = 6 * eps * term
        assert np.abs(stored_weights - weights).max() <= bound, (np.abs(stored_weights - weights).max(), bound)

    def test_white_maps_to_one(self):
        nodes, W = spectral_weights(1.0)
        np.testing.assert_allclose(W @ np.ones(nodes.size), 1.0, atol=WEIGHT_SUM_BOUND)
        nodes5, W5 = spectral_weights(5.0)
        np.testing.assert_allclose(W5 @ np.ones(nodes5.size), 1.0, atol=WEIGHT_SUM_BOUND)

    def test_against_colour_sd_to_XYZ(self):
        import colour

        nodes = spectral_grid(1.0)
        reflectance = 0.2 + 0.6 * np.exp(-(((nodes - 600.0) / 60.0) ** 2))
        sd = colour.SpectralDistribution(dict(zip(nodes, reflectance)))
        cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
        illuminant = colour.sd_CIE_illuminant_D_series(ACES_WHITE_XY)
        XYZ = colour.sd_to_XYZ(sd, cmfs, illuminant, method="Integration") / 100.0
        # Same white on both sides: adapt colour's XYZ to ACEScg, normalise by white.
        W = spectral_weights(1.0)[1]
        white_XYZ = (
            colour.sd_to_XYZ(
                colour.SpectralDistribution(dict(zip(nodes, np.ones_like(nodes)))),
                cmfs,
                illuminant,
                method="Integration",
            )
            / 100.0
        )
        RGB_colour = colour.XYZ_to_RGB(
            XYZ,
            colour.RGB_COLOURSPACES["ACEScg"],
            illuminant=colour.XYZ_to_xy(white_XYZ),
            chromatic_adaptation_transform="CAT02",
        )
        RGB_white = colour.XYZ_to_RGB(
            white_XYZ,
            colour.RGB_COLOURSPACES["ACEScg"],
            illuminant=colour.XYZ_to_xy(white_XYZ),
            chromatic_adaptation_transform="CAT02",
        )
        # Not a rounding bound: colour-science interpolates the CMFS and the
        # illuminant its own way and adapts with CAT02 in XYZ, this module
        # works from its own tables; 2e-3 is how close two implementations of
        # the same colorimetry agree (a modelling figure), far above rounding.
        np.testing.assert_allclose(W @ reflectance, RGB_colour / RGB_white, rtol=2e-3)

    def test_coarse_weights_exact_for_linear_spectra(self):
        fine, W1 = spectral_weights(1.0)
        coarse, W10 = spectral_weights(10.0)
        line = lambda x: 0.1 + 0.8 * (x - 360.0) / 470.0  # noqa: E731
        np.testing.assert_allclose(W10 @ line(coarse), W1 @ line(fine), atol=WEIGHT_SUM_BOUND)

    def test_weights_refuse_wrong_span(self):
        with pytest.raises(ValueError, match="must span 360-830"):
            spectral_to_ACEScg_weights(np.linspace(380, 780, 41))

    def test_lab_matches_colour(self):
        import colour

        rgb = np.array([[0.9, 0.6, 0.3], [1.0, 1.0, 1.0], [-0.01, 0.2, 0.1], [0.0, 0.0, 0.0]])
        expected = colour.XYZ_to_Lab(ACEScg_to_XYZ(rgb), ACES_WHITE_XY)
        np.testing.assert_allclose(ACEScg_to_Lab(rgb), expected, atol=LAB_BOUND)
        np.testing.assert_allclose(ACEScg_to_Lab([1.0, 1.0, 1.0]), [100.0, 0.0, 0.0], atol=LAB_BOUND)

    def test_lab_jacobian_matches_finite_differences(self):
        rng = np.random.default_rng(1)
        rgb = rng.uniform(0.02, 1.0, size=(20, 3))
        J = ACEScg_to_Lab_jacobian(rgb)
        h = 1e-7
        for j in range(3):
            step = np.zeros(3)
            step[j] = h
            numeric = (ACEScg_to_Lab(rgb + step) - ACEScg_to_Lab(rgb - step)) / (2 * h)
            # Central difference, h = 1e-7: truncation h^2 |f'''| / 6 <= 1e-14 *
            # |J| (cube root at t >= 0.02) and rounding u64 |Lab| / h =
            # 1.1e-16 * 100 / 1e-7 = 1.1e-7 absolute; 1e-5 (+ 1e-5 relative)
            # is that with a 90x margin. Measured: 4.2e-7 absolute.
            np.testing.assert_allclose(J[:, :, j], numeric, rtol=1e-5, atol=1e-5)

    def test_lab_and_jacobian_in_one_pass(self):
        # The one-pass form scales by the white before the product ((M / Xn) RGB,
        # not (M RGB) / Xn): a few roundings of XYZ apart, so Lab within
        # LAB_BOUND; its derivative 1 / (3 t^(2/3)) from the same cube root, a
        # few roundings relative: 1e-12 relative. Includes the linear segment
        # (dark and negative values) and black.
        rng = np.random.default_rng(3)
        rgb = np.concatenate([rng.uniform(-0.02, 1.0, size=(50, 3)), [[0.0, 0.0, 0.0], [1e-4, 2e-4, 0.0]]])
        Lab, J = ACEScg_to_Lab_and_jacobian(rgb)
        np.testing.assert_allclose(Lab, ACEScg_to_Lab(rgb), atol=LAB_BOUND)
        np.testing.assert_allclose(J, ACEScg_to_Lab_jacobian(rgb), rtol=1e-12, atol=1e-12)

    def test_delta_E_2000_published_pair(self):
        # Sharma, Wu & Dalal (2005), Table 1, pair 1: 2.0425, printed to 4
        # decimals: the exact value lies within 5e-5 of it (see SHARMA_ATOL in
        # test_delta_e); 1e-4 is one unit of the last printed place.
        assert delta_E_2000([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485]) == pytest.approx(2.0425, abs=1e-4)


@pytest.mark.slow  # a fresh interpreter
def test_colour_science_loads_its_plotting_only_on_use():
    # Every server, worker and CLI process imports colour-science; its
    # plotting package (matplotlib with it) waits until something uses it,
    # and then is the real package.
    import subprocess
    import sys

    script = (
        "import sys\n"
        "from fitting.colour.colorimetry import colour_science\n"
        "import service.main\n"
        "colour = colour_science()\n"
        "assert colour is sys.modules['colour'] and colour_science() is colour\n"
        "assert 'matplotlib' not in sys.modules, sorted(m for m in sys.modules if 'matplotlib' in m)[:5]\n"
        "assert callable(colour.plotting.plot_single_colour_swatch)\n"
        "assert 'matplotlib' in sys.modules\n"
        "print('ok')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=__file__.rsplit("/tests/", 1)[0],
    )
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-2000:]
