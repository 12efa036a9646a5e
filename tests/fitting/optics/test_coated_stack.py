"""
The physical air / coat / metal stack (fitting.optics.coated_stack) against
the exact Fresnel kernels, closed forms and Mitsuba 3 (``scalar_spectral``),
and the seen target in ACEScg (fitting.colour.seen) against the project's
spectral reference.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.colour.reference import reference_ACEScg
from fitting.colour.seen import seen_ACEScg
from fitting.optics.coated_stack import (
    coated_stack,
    coated_stack_from_metal,
    fresnel_conductor_sp,
    fresnel_dielectric_sp,
    refracted_cos,
)
from fitting.optics.fresnel import fresnel_conductor, fresnel_dielectric
from fitting.optics.library import library_material
from precision import F64_FEW_OPS, F64_RGB_BOUND

MU = np.linspace(0.0, 1.0, 41)


@pytest.mark.numeric
def test_polarisations_average_to_the_unpolarised_kernels():
    for eta, n, k in ((1.5, 0.2, 3.0), (1.33, 1.4, 0.0), (2.0, 2.5, 0.7)):
        Rs, Rp = fresnel_conductor_sp(MU, eta, n, k)
        # Same complex arithmetic, a few operations: F64_FEW_OPS.
        np.testing.assert_allclose(0.5 * (Rs + Rp), fresnel_conductor(MU, eta, n, k), atol=F64_FEW_OPS)
        Rs, Rp = fresnel_dielectric_sp(MU, eta)
        np.testing.assert_allclose(0.5 * (Rs + Rp), fresnel_dielectric(MU, 1.0, eta), atol=F64_FEW_OPS)
        assert np.all(Rp <= Rs + F64_FEW_OPS)  # p below s for a dielectric, Brewster where Rp = 0


@pytest.mark.numeric
def test_normal_incidence_closed_form():
    # At mu = 1: R01 = ((eta-1)/(eta+1))^2, R12 = |(n+ik-eta)/(n+ik+eta)|^2 for both.
    eta, n, k = 1.5, 0.3, 2.5
    R01 = ((eta - 1) / (eta + 1)) ** 2
    R12 = abs((n + 1j * k - eta) / (n + 1j * k + eta)) ** 2
    expected = R01 + (1 - R01) ** 2 * R12 / (1 - R01 * R12)
    assert coated_stack(1.0, eta, n, k) == pytest.approx(expected, abs=F64_FEW_OPS)


@pytest.mark.numeric
def test_no_coat_is_the_bare_metal_and_limits():
    np.testing.assert_allclose(coated_stack(MU, 1.0, 0.2, 3.0), fresnel_conductor(MU, 1.0, 0.2, 3.0), atol=F64_FEW_OPS)
    np.testing.assert_allclose(refracted_cos(MU, 1.0), MU, atol=F64_FEW_OPS)
    # Grazing in air: the coat reflects everything.
    assert coated_stack(0.0, 1.5, 0.2, 3.0) == pytest.approx(1.0)
    # A perfect mirror under any coat stays a perfect mirror (energy conserved).
    np.testing.assert_allclose(coated_stack(MU, 1.7, 1e-6, 1e8), 1.0, atol=1e-6)
    # The unpolarised-metal variant agrees at normal incidence, where s = p.
    metal = lambda mu_c: fresnel_conductor(mu_c, 1.5, 0.2, 3.0)  # noqa: E731
    assert coated_stack_from_metal(1.0, 1.5, metal) == pytest.approx(coated_stack(1.0, 1.5, 0.2, 3.0), abs=F64_FEW_OPS)


@pytest.mark.numeric
def test_seen_at_eta_1_is_the_reference_in_air():
    mu = np.cos(np.radians(np.arange(0.0, 90.0, 7.0)))
    for name in ("Au", "Cu", "Cr", "Al"):
        nk = library_material(name)
        # Two float64 paths of the same sum over 471 nodes: F64_RGB_BOUND.
        np.testing.assert_allclose(seen_ACEScg(nk, mu, 1.0), reference_ACEScg(nk, mu, 1.0), atol=F64_RGB_BOUND)


def test_seen_refuses_bad_eta():
    with pytest.raises(ValueError, match="eta_i"):
        seen_ACEScg(library_material("Au"), 0.5, 0.9)


# Mitsuba 3 (``scalar_spectral_polarized``: the scalar spectral variant that
# carries Stokes vectors, so that s and p stay apart through both interfaces
# as in the model; plain ``scalar_spectral`` averages them at each interface):
# a dielectric rectangle (the coat's top interface, int_ior eta)
# 1e-3 above a conductor rectangle of relative index (n + ik)/eta, 200 units
# wide, seen by an orthographic camera at theta under a constant white sky;
# the path tracer follows every bounce (max_depth 64, no Russian roulette
# before depth 1000). n, k constant over wavelength, so each pixel is R times
# the sky's RGB: the ratio of the channel sums to the sky's is R.
MITSUBA_CASES = [(1.5, 0.2, 3.0), (1.33, 1.5, 1.0), (2.0, 2.5, 0.5)]
MITSUBA_ANGLES = (45.0, 80.0)
MITSUBA_SPP = 16384
MITSUBA_PIXELS = 4


def _mitsuba_scene(mi, theta, eta, n, k):
    direction = np.array([np.sin(np.radians(theta)), 0.0, np.cos(np.radians(theta))])
    T = mi.ScalarTransform4f()
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 64, "rr_depth": 1000},
        "sensor": {
            "type": "orthographic",
            "to_world": T.look_at(origin=(5 * direction).tolist(), target=[0, 0, 0], up=[0, 1, 0])
            @ T.scale([0.01, 0.01, 1.0]),
            "film": {
                "type": "hdrfilm",
                "width": MITSUBA_PIXELS,
                "height": MITSUBA_PIXELS,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": MITSUBA_SPP},
        },
        "sky": {"type": "constant", "radiance": {"type": "spectrum", "value": 1.0}},
    }
    if theta is not None and n is not None:
        scene["metal"] = {
            "type": "rectangle",
            "to_world": T.translate([0, 0, -1e-3]) @ T.scale(100.0),
            "bsdf": {
                "type": "conductor",
                "eta": {"type": "spectrum", "value": n / eta},
                "k": {"type": "spectrum", "value": k / eta},
            },
        }
        scene["coat"] = {
            "type": "rectangle",
            "to_world": T.scale(100.0),
            "bsdf": {"type": "dielectric", "int_ior": eta, "ext_ior": 1.0},
        }
    return mi.load_dict(scene)


@pytest.fixture(scope="module")
def mitsuba_renders():
    import mitsuba as mi

    mi.set_variant("scalar_spectral_polarized")
    sky = np.array(mi.render(_mitsuba_scene(mi, 0.0, 1.0, None, None)), dtype=np.float64)
    out = {}
    for case in MITSUBA_CASES:
        for theta in MITSUBA_ANGLES:
            out[case, theta] = np.array(mi.render(_mitsuba_scene(mi, theta, *case)), dtype=np.float64)
    out[MITSUBA_CASES[0], 0.0] = np.array(mi.render(_mitsuba_scene(mi, 0.0, *MITSUBA_CASES[0])))
    return sky, out


def _unpolarised_interfaces(mu, eta, n, k):
    """The bounce sum with each interface's unpolarised reflectance (what the
    model is not): R01 + (1 - R01)^2 R12 / (1 - R01 R12)."""
    R01 = fresnel_dielectric(mu, 1.0, eta)
    R12 = fresnel_conductor(refracted_cos(mu, eta), eta, n, k)
    return R01 + (1 - R01) ** 2 * R12 / (1 - R01 * R12)


@pytest.mark.slow  # 8 renders of 16 pixels x 16384 samples, ~12 s
@pytest.mark.numeric
def test_stack_agrees_with_mitsuba_within_its_noise(mitsuba_renders):
    sky, renders = mitsuba_renders
    sky_px = sky.sum(axis=-1).ravel()
    worst = 0.0
    for (case, theta), image in renders.items():
        px = image.sum(axis=-1).ravel()
        ratio = px.sum() / sky_px.sum()
        # Noise of the ratio from the pixels' spread (each pixel an
        # independent estimate): standard error of both means, combined.
        sigma = ratio * np.hypot(
            px.std(ddof=1) / px.sum() * np.sqrt(px.size), sky_px.std(ddof=1) / sky_px.sum() * np.sqrt(sky_px.size)
        )
        expected = float(coated_stack(np.cos(np.radians(theta)), *case))
        # 5 standard errors: a false failure once in 1.7 million.
        assert abs(ratio - expected) <= 5.0 * sigma, (case, theta, ratio, expected, sigma)
        worst = max(worst, abs(ratio - expected))
        if theta == 45.0 and case == MITSUBA_CASES[1]:
            # Here the polarisations differ enough that averaging them at
            # each interface is 6 standard errors away: the render tells.
            assert abs(ratio - float(_unpolarised_interfaces(np.cos(np.radians(theta)), *case))) > 5.0 * sigma
    # And the bounce sum matters at this noise: without it (first bounce
    # only) the stack would be off by far more than the worst difference.
    eta, n, k = MITSUBA_CASES[0]
    single = fresnel_dielectric(1.0, 1.0, eta) + (1 - fresnel_dielectric(1.0, 1.0, eta)) ** 2 * fresnel_conductor(
        1.0, eta, n, k
    )
    assert abs(float(coated_stack(1.0, eta, n, k)) - float(single)) > 3 * worst
