"""
The cos theta table of the spectral reference in the preview
(:func:`preview_shaders.preview.reference_table`) against the reference
integrated at every pixel.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting import LIBRARY_NAMES, SpectralNK, library_material
from fitting.colour.reference import reference_ACEScg, reference_ACEScg_grid
from preview_shaders.preview import (
    REFERENCE_TABLE_TOLERANCE,
    reference_image,
    reference_table,
    sphere_cos_theta,
)

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

# The distinct cos theta of a 256 px sphere, as float32 like the GL geometry.
_COS, _MASK = sphere_cos_theta(256)
MU = np.unique(_COS[_MASK].astype(np.float32).astype(np.float64))


class TestReferenceTable:
    @pytest.mark.parametrize("name", LIBRARY_NAMES)
    def test_every_conductor_within_float32_rounding(self, name):
        nk = library_material(name)
        for eta_i in (1.0, 1.5, 3.0):
            exact = reference_ACEScg_grid(nk, MU, [eta_i])[0]
            table = reference_table(nk, eta_i)
            # A spline, not the exact fallback, and below float32 rounding of 1.
            assert hasattr(table, "c")
            assert np.max(np.abs(table(MU) - exact)) < REFERENCE_TABLE_TOLERANCE

    def test_dielectric_past_its_critical_angle_falls_back_to_exact(self):
        wl = np.linspace(300.0, 900.0, 61)
        glass = SpectralNK(wl, 1.5 + 0.01 * (wl - 600.0) / 300.0, np.zeros(61), name="glass")
        table = reference_table(glass, 2.5)  # total internal reflection below some cos theta
        assert not hasattr(table, "c")
        np.testing.assert_array_equal(table(MU), reference_ACEScg_grid(glass, MU, [2.5])[0])

    def test_image_matches_the_per_pixel_reference(self):
        nk = library_material("Cu")
        cos_theta, mask = sphere_cos_theta(96)
        cos_theta = cos_theta.astype(np.float32)
        radiance = np.random.default_rng(3).uniform(0.2, 2.0, (96, 96, 4)).astype(np.float32)
        fast = reference_image(nk, cos_theta, mask, radiance, 1.7)
        slow = reference_image(nk, cos_theta, mask, radiance, 1.7, per_pixel=True)
        assert fast.dtype == slow.dtype == np.float32
        # float32 tolerance: a few units in the last place of values up to 2.
        np.testing.assert_allclose(fast, slow, rtol=0, atol=4 * np.finfo(np.float32).eps)
        np.testing.assert_array_equal(fast[~mask], radiance[~mask][:, :3])
        direct = reference_ACEScg(nk, cos_theta[mask].astype(np.float64), 1.7)
        # The table's REFERENCE_TABLE_TOLERANCE (1e-7) times radiance <= ~4 plus
        # the float32 product (u32 of values <= ~4): 6.4e-7 < 1e-6.
        np.testing.assert_allclose(fast[mask], direct * radiance[mask][:, :3], rtol=0, atol=1e-6)
