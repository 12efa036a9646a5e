"""
fitting.fits.curves: the float16 bits of a few refits, pinned.

A regression check, not a claim of accuracy: the constants are what
``fit_curves`` gave for these cases (the same under numpy's baseline kernels
and OpenBLAS's Prescott and Haswell core types), so a change that moves any
of them is seen. A change meant to move them bumps ``CURVES_FORMAT``
in service/jobs/curves.py (stored curve fits are keyed by it) and captures
the new bits here. Cases: no base (the range constraint, no candidates), a
live step near the fit on screen and one pulled past what the model follows
(its in-range answer), the rgb-conductor kind, and a full refit under the
worst-case guard.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.fits.curves import LIVE_SETTINGS, fit_curves
from fitting.fits.curves_base import curve_base_from_nk
from fitting.fits.curves_input import RGBCurve
from fitting.fits.material import fit_material
from fitting.models.coated_conductor import coated_conductor_model
from fitting.optics.library import library_material

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

ANGLE = np.linspace(0.0, 90.0, 46)
MU = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))
KNOWN = np.array(
    [
        [[0.90, -0.08, 0.03], [0.74, -0.17, 0.10], [0.42, -0.36, 0.22]],
        [[0.20, 0.05, 0.00], [0.15, 0.03, 0.01], [0.10, 0.02, 0.00]],
        [[6.00, 1.00, 0.00], [5.00, 0.50, 0.00], [4.00, 0.50, 0.00]],
    ]
)

PINNED = {  # float16 coefficients as little-endian bytes (hex), objective kept, best_effort
    "no base": ("2d3bb0aad639ecac5936f5b06c32ab2aa030ea28972de023ff45a03cf544e2388743a838", "de2000", False),
    "live, gentle": (
        "2d3bb0ac6125ee39a0b1cd2ea1369bb52b33efb4073494b548bae01aa0b2ebadfec0b639aa4da6d1494ed9481ccc904896403b3880b5",
        "de2000",
        False,
    ),
    "live, past the model": (
        "323bf1add028f039a2b1e82ea8369eb563339a2e06baae3304b28cbdab3847b02ec1e33a644635c8a94412449dc29e3e35420fbdbf39",
        "de2000",
        True,
    ),
    "rgb-conductor": ("b737873bf93c9b410541e240", "de2000", False),
    # The guard holds the refit under every optimum of an auditor's starts that is a reflectance:
    # here the angle grid's from the paper candidate (mean 1.716, the lowest residual's leaves
    # [0, 1]), which the kept twin of the in-range paper fit (1.721) lost to; the kept fit is
    # that optimum's twin, polished: 1.709 there, 1.816 on the cos theta grid (above that
    # auditor's 1.671, the max 15.14 at grazing the same for every fit). The minimax over both
    # auditors holds both here but is not kept: it moves gold's rows far from the edit (eta_i
    # 2.5: max 5.6 against 3.3), see FAR_TOLERANCE.
    "guarded": (
        "443bcdb9c939f239d1b11e2fa5368cb517332a3deec3d24083a9cdbf133c3cacadc1273c1547d3cde94c66431fc0c739cb4126b9a933",
        "rgb",
        False,
    ),
}


@pytest.fixture(scope="module")
def gold():
    return curve_base_from_nk(library_material("Au"))


def green_pulled(base, value, step=1.0, angle=60.0):
    """Gold's green curve at eta_i 1.5 pulled a fraction ``step`` of the way to ``value`` at ``angle``."""
    rgb = base.rgb(MU, 1.5).copy()
    w = np.exp(-0.5 * ((ANGLE - angle) / 9.0) ** 2) * (1 - (ANGLE / 90) ** 6)
    w /= w.max()
    i = int(np.argmin(np.abs(ANGLE - angle)))
    rgb[:, 1] += step * (value - rgb[i, 1]) * w
    return [{"eta_i": 1.5, "cos_theta": MU.tolist(), "rgb": np.clip(rgb, 0.0, 1.0).tolist()}]


def check(result, case):
    bits, objective, best_effort = PINNED[case]
    assert result.packed.coefficients.dtype == np.float16
    assert result.packed.coefficients.tobytes().hex() == bits
    assert (result.metrics["objective"], result.metrics["best_effort"]) == (objective, best_effort)


def test_without_a_base():
    curves = [RGBCurve(e, MU, coated_conductor_model(MU, e, KNOWN, (1.0, 2.5))) for e in (1.2, 2.2)]
    check(fit_curves(curves), "no base")


def test_live_steps(gold):
    start = fit_material(library_material("Au")).coefficients_float16.astype(np.float64)
    check(fit_curves(green_pulled(gold, 0.5, 0.2), gold, settings=LIVE_SETTINGS, start=start), "live, gentle")
    check(fit_curves(green_pulled(gold, 0.10), gold, settings=LIVE_SETTINGS, start=start), "live, past the model")


def test_rgb_conductor():
    copper = curve_base_from_nk(library_material("Cu"))
    rgb = np.clip(copper.rgb(MU, 1.5) * np.array([1.0, 0.9, 1.05]), 0.0, 1.0)
    check(fit_curves([RGBCurve(1.5, MU, rgb)], copper, model="rgb-conductor"), "rgb-conductor")


@pytest.mark.slow  # a full refit with the guard's audits: 4.1 s (load average 8) in a --durations=0 run
def test_guarded_refit(gold):
    edit = gold.rgb(MU, 1.5).copy()
    edit[:, 0] *= 0.8
    check(fit_curves([RGBCurve(1.5, MU, edit)], gold), "guarded")
