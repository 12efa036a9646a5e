"""
The rgb-conductor's albedo table (``rgb_albedo_table.frag``) in moderngl
against numpy:
row 0 the GGX lobe of the exact per-channel conductor Fresnel
(``cf_rgb_conductor_albedo``) against :func:`fitting.shading.ibl.directional_albedo`
of :func:`fitting.models.rgb_conductor.rgb_fresnel_conductor`, its mirror
the Fresnel itself; row 1 zero; row 2 the coat's lobe as albedo_table.frag's.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_albedo_tables import MU, NODES, TOLERANCE, _render, thread  # noqa: F401 (fixture)

from fitting.fits.kinds import fit_model
from fitting.models.rgb_conductor import rgb_fresnel_conductor
from fitting.optics.fresnel import fresnel_dielectric
from fitting.optics.library import library_material
from fitting.shading.ibl import default_lut, directional_albedo, split_sum_schlick
from preview_shaders.shading import upload_lut

pytestmark = [pytest.mark.gl, pytest.mark.slow]


@pytest.fixture(scope="module")
def nk_rgb():
    C = fit_model(library_material("Cu"), (1.0, 2.5), "rgb-conductor").packed.coefficients.astype(np.float64)
    return C[0], C[1]


def _table(thread, n, k, eta_i, roughness, coat_roughness):
    lut = default_lut()
    uniforms = {
        "u_resolution": (float(NODES), 3.0),
        "u_eta_i": eta_i,
        "u_roughness": roughness,
        "u_coat_roughness": coat_roughness,
        "cf_n": tuple(n),
        "cf_k": tuple(k),
        "u_samples": 2048,
        "cf_alpha_range": lut.alpha_range,
    }
    return thread.call(_render, "rgb_albedo_table.frag", 3, uniforms, {"cf_lut": lambda state: upload_lut(state, lut)})


@pytest.mark.parametrize("eta_i, roughness, coat_roughness", [(1.5, 0.45, 0.2), (2.3, 0.9, 0.0), (1.0, 0.1, 0.3)])
def test_rows_are_numpy(thread, nk_rgb, eta_i, roughness, coat_roughness):
    n, k = nk_rgb
    got = _table(thread, n, k, eta_i, roughness, coat_roughness)
    expected = directional_albedo(MU, roughness, lambda VdotH: rgb_fresnel_conductor(VdotH, eta_i, n, k))
    np.testing.assert_allclose(got[0], expected, atol=TOLERANCE)
    np.testing.assert_array_equal(got[1], 0.0)
    F0c = ((eta_i - 1.0) / (eta_i + 1.0)) ** 2
    if coat_roughness == 0:
        coat = np.repeat(fresnel_dielectric(MU, 1.0, eta_i)[:, None], 3, axis=1)
    else:
        coat = split_sum_schlick(MU, coat_roughness, np.full(3, F0c)) if eta_i > 1 else np.zeros((NODES, 3))
    np.testing.assert_allclose(got[2], coat, atol=TOLERANCE)


def test_mirror_is_the_fresnel(thread, nk_rgb):
    n, k = nk_rgb
    got = _table(thread, n, k, 1.7, 0.0, 0.0)
    np.testing.assert_allclose(got[0], rgb_fresnel_conductor(MU, 1.7, n, k), atol=TOLERANCE)
