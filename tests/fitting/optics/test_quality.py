"""Data quality: gaps inside the visible range, and models that leave [0, 1]."""

from __future__ import annotations

import numpy as np
import pytest

from fitting import fit_material, library_material
from fitting.fits.kinds import fit_model
from fitting.optics.nk import SpectralNK
from fitting.optics.quality import DEFAULT_MAX_GAP_NM, check_gaps, visible_gaps


def au_without(mask_fn, name):
    au = library_material("Au")
    keep = mask_fn(au.wavelength_nm)
    return SpectralNK(au.wavelength_nm[keep], au.n[keep], au.k[keep], name=name, source="Au thinned")


def test_gaps_are_measured_inside_the_visible_range_only():
    assert visible_gaps([300.0, 400.0, 800.0, 900.0])[0] == (400.0, 800.0)
    assert visible_gaps([300.0, 900.0]) == [(360.0, 830.0)]
    assert visible_gaps([200.0, 300.0]) == []


def test_every_library_conductor_passes_the_default():
    from fitting import LIBRARY_NAMES

    for name in LIBRARY_NAMES:
        assert check_gaps(library_material(name)) == []


def test_gappy_au_is_refused_naming_the_gap():
    gappy = au_without(lambda w: (w <= 471.5) | (w >= 659.0), "Au gappy")
    with pytest.raises(ValueError, match=r"between 471\.4 and 659\.5 nm \(188\.1 nm\)"):
        fit_material(gappy)
    with pytest.raises(ValueError, match="max_gap_nm"):
        fit_model(gappy, model="rgb-conductor")


def test_relaxed_gap_fits_with_a_warning_in_result_and_pack():
    gappy = au_without(lambda w: (w <= 471.5) | (w >= 659.0), "Au gappy")
    result = fit_material(gappy, max_gap_nm=200.0)
    (warning,) = [w for w in result.quality["warnings"] if w.startswith("sparse data")]
    assert "471.4 and 659.5" in warning
    assert "warning: sparse data" in result.packed.source and result.packed.source.startswith("Au thinned")
    assert "sparse data" in result.summary()["quality"]["warnings"][0]


def test_three_wavelengths_are_refused():
    au = library_material("Au")
    w = np.array([360.0, 595.0, 830.0])
    sparse = SpectralNK(w, np.interp(w, au.wavelength_nm, au.n), np.interp(w, au.wavelength_nm, au.k), name="Au 3")
    with pytest.raises(ValueError, match=r"between 360 and 595 nm"):
        fit_material(sparse)


def test_max_gap_setting_is_checked():
    with pytest.raises(ValueError, match="max_gap_nm"):
        fit_material(library_material("Au"), max_gap_nm=0)
    assert DEFAULT_MAX_GAP_NM == 120.0


@pytest.mark.slow  # the guard's constrained refits of a non-metal: 3-8 s on 2 shared cores
@pytest.mark.parametrize("n, k", [(1.5, 0.0), (2.0, 0.02)])
def test_a_model_leaving_the_range_says_so(n, k):
    wl = np.arange(300.0, 900.0, 5.0)
    nk = SpectralNK(wl, np.full(wl.size, n), np.full(wl.size, k), name="dielectric")
    result = fit_material(nk)
    assert result.quality["range"]["in_range"] is False
    assert any("leaves [0, 1]" in w for w in result.quality["warnings"])
    assert "leaves [0, 1]" in result.packed.source
