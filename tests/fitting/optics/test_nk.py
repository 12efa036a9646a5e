"""fitting.optics.nk: SpectralNK validation, resampling, coverage."""

import numpy as np
import pytest

from fitting.optics.nk import SpectralNK, resample_nk, visible_coverage

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

WL = [400.0, 500.0, 600.0]


class TestSpectralNK:
    def test_valid(self):
        nk = SpectralNK(WL, [0.5, 0.6, 0.7], [2.0, 2.5, 3.0], name="x")
        assert nk.wavelength_range_nm == (400.0, 600.0)
        with pytest.raises(ValueError):
            nk.n[0] = 3.0  # read-only

    @pytest.mark.parametrize(
        "kwargs, message",
        [
            (
                dict(wavelength_nm=[500.0, 400.0, 600.0]),
                r"`wavelength_nm` must be strictly increasing, got 400 after 500 at index 1",
            ),
            (dict(wavelength_nm=[400.0, 400.0, 600.0]), r"`wavelength_nm` must be strictly increasing"),
            (dict(wavelength_nm=[400.0, np.inf, 600.0]), r"`wavelength_nm` must be finite, got inf at index 1"),
            (dict(wavelength_nm=[-1.0, 500.0, 600.0]), r"`wavelength_nm` must be > 0"),
            (dict(n=[0.5, 0.0, 0.7]), r"`n` must be > 0, got 0 at index 1"),
            (dict(n=[0.5, -1.0, 0.7]), r"`n` must be > 0, got -1 at index 1"),
            (dict(n=[0.5, np.nan, 0.7]), r"`n` must be finite, got nan at index 1"),
            (dict(k=[0.5, -0.1, 0.7]), r"`k` must be >= 0, got -0.1 at index 1"),
            (dict(k=[0.5, 0.7]), r"`k` must have one value per wavelength \(3\), got 2"),
            (dict(wavelength_nm=[400.0], n=[1.0], k=[1.0]), r"at least 2 samples, got 1"),
            (dict(wavelength_nm=[[400.0, 500.0]]), r"one-dimensional"),
            (dict(n=["a", "b", "c"]), r"`n` must be a sequence of numbers"),
            (dict(name=""), r"`name` must be a non-empty string"),
        ],
    )
    def test_each_rule(self, kwargs, message):
        args = dict(wavelength_nm=WL, n=[0.5, 0.6, 0.7], k=[2.0, 2.5, 3.0], name="x")
        args.update(kwargs)
        with pytest.raises(ValueError, match=message):
            SpectralNK(**args)

    def test_resample_holds_ends_and_reports_coverage(self):
        nk = SpectralNK([380.0, 800.0], [1.0, 2.0], [0.0, 1.0], name="x")
        out = resample_nk(nk, np.array([360.0, 380.0, 590.0, 830.0]), min_coverage=0.8)
        # Linear interpolation at a node or a midpoint: <= 3 roundings of
        # values <= 2; the coverage a ratio of sums of node spacings. Both
        # within 16 u64 (tightened from the defaults rtol=1e-7 and rel=1e-6).
        np.testing.assert_allclose(out.n, [1.0, 1.0, 1.5, 2.0], rtol=16 * 2.0**-53)
        assert out.coverage == pytest.approx(420 / 470, rel=16 * 2.0**-53)
        assert visible_coverage((100.0, 2000.0)) == 1.0

    def test_resample_refuses_low_coverage(self):
        nk = SpectralNK([500.0, 600.0], [1.0, 2.0], [0.0, 1.0], name="x")
        with pytest.raises(ValueError, match=r"cover at least 90% .* cover 21.3%"):
            resample_nk(nk, np.array([360.0, 830.0]))
        with pytest.raises(ValueError, match="`min_coverage` must lie in"):
            resample_nk(nk, np.array([360.0, 830.0]), min_coverage=1.5)
