"""Data quality: n, k outside the physical range refused, isolated outliers named with their wavelength."""

from __future__ import annotations

import numpy as np
import pytest

from fitting import LIBRARY_NAMES, library_material
from fitting.optics.nk import MAX_NK, SpectralNK, check_nk_range, resample_nk
from fitting.optics.quality import find_outliers, outlier_warnings

W = np.arange(350.0, 851.0, 10.0)


def metal(n_at=None, k_at=None, at=550.0, n=None, k=None):
    n1 = np.linspace(0.4, 0.8, W.size) if n is None else np.full(W.size, n)
    k1 = np.linspace(2.0, 4.5, W.size) if k is None else np.full(W.size, k)
    i = int(np.argmin(np.abs(W - at)))
    if n_at is not None:
        n1[i] = n_at
    if k_at is not None:
        k1[i] = k_at
    return SpectralNK(W, n1, k1, name="metal")


class TestRange:
    @pytest.mark.parametrize("field, value", [("k", 1e20), ("k", 1e200), ("n", 1e6), ("n", MAX_NK * 1.001)])
    def test_one_sample_above_the_range_is_refused_by_name_and_wavelength(self, field, value):
        nk = metal(**{f"{field}_at": value})
        with pytest.raises(ValueError, match=rf"`{field}` must be at most 1000 inside 360-830 nm .* at 550 nm"):
            resample_nk(nk, np.arange(360.0, 831.0))

    def test_the_limit_itself_and_values_the_fit_does_not_use_pass(self):
        check_nk_range(metal(n=MAX_NK, k=MAX_NK))
        far = SpectralNK(np.append(W, 2000.0), np.append(metal().n, 1e200), np.append(metal().k, 1.0))
        check_nk_range(far)  # 2000 nm: neither inside 360-830 nm nor the nearest beyond
        nearest = SpectralNK(W[W != 360.0], metal(n_at=1e200, at=350.0).n[W != 360.0], metal().k[W != 360.0])
        with pytest.raises(ValueError, match="at 350 nm"):  # the nearest sample beyond 360 nm is used
            check_nk_range(nearest)

    def test_every_library_conductor_is_inside(self):
        for name in LIBRARY_NAMES:
            check_nk_range(library_material(name))


class TestOutliers:
    @pytest.mark.parametrize("field, value", [("n", 50.0), ("n", 1e-6), ("k", 300.0), ("k", 1e-6)])
    def test_a_single_sample_spike_is_named(self, field, value):
        (found,) = find_outliers(metal(**{f"{field}_at": value}))
        assert found["field"] == field and found["wavelength_nm"] == 550.0 and found["decades"] > 1.0
        (warning,) = outlier_warnings(metal(**{f"{field}_at": value}))
        assert warning.startswith(f"outlier: {field} = {value:.4g} at 550 nm")

    def test_a_spike_at_an_end_is_named(self):
        spiked = metal(k_at=400.0, at=360.0)
        (found,) = find_outliers(SpectralNK(W[1:], spiked.n[1:], spiked.k[1:]))  # the data start at 360 nm
        assert found["wavelength_nm"] == 360.0

    def test_smooth_data_and_the_library_have_none(self):
        assert find_outliers(metal()) == []
        # a steep but consistent edge (a factor 3 per sample) is no outlier
        assert find_outliers(SpectralNK(W, np.geomspace(0.01, 1e3, W.size), np.full(W.size, 3.0))) == []
        for name in LIBRARY_NAMES:
            assert find_outliers(library_material(name)) == [], name
