"""
The metal under a smooth coat with the bounces (fitting/shading/coated_layer.py):
the mirror's limit is the air-coat-metal stack, the coat's hemispherical
reflectance from inside has its closed form, the escape fraction of a
near-mirror lobe is the coat's transmission at the view angle, and a rough
lobe is darker through the coat than the mirror's series claims.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.optics.coated_stack import coated_stack_from_metal, refracted_cos
from fitting.optics.fresnel import fresnel_dielectric
from fitting.shading.coated_layer import (
    escape_fraction,
    hemispherical_albedo,
    internal_reflectance,
    seen_base,
    through_coat,
)

pytestmark = pytest.mark.numeric

MU = np.linspace(0.05, 1.0, 12)


def gold_like(c):
    """A bright coloured metal's Fresnel (Schlick at gold-like F0), (..., 3)."""
    F0 = np.array([0.95, 0.7, 0.3])
    return F0 + (1.0 - F0) * (1.0 - np.asarray(c)[..., None]) ** 5


@pytest.mark.parametrize("eta", [1.0, 1.33, 1.5, 2.0])
def test_mirror_is_the_stack(eta):
    """At roughness 0 the base plus the coat's own reflection is coated_stack_from_metal."""
    stack = coated_stack_from_metal(MU, eta, gold_like)
    base = seen_base(MU, eta, 0.0, gold_like)
    np.testing.assert_allclose(fresnel_dielectric(MU, 1.0, eta)[:, None] + base, stack, rtol=0, atol=1e-12)


@pytest.mark.parametrize("eta", [1.33, 1.5, 2.0])
def test_internal_reflectance_closed_form(eta):
    """r_bar = 1 - (1 - r_ext) / eta^2 (the same interface seen from outside, cosine weighted)."""
    c = np.linspace(0.0, 1.0, 20001)
    r_ext = 2.0 * np.trapezoid(fresnel_dielectric(c, 1.0, eta) * c, c)
    # 16 midpoints in cos^2 across the critical angle's kink: a few thousandths.
    assert internal_reflectance(eta) == pytest.approx(1.0 - (1.0 - r_ext) / eta**2, abs=5e-3)
    assert internal_reflectance(1.0) == 0.0


def test_escape_fraction_limits():
    """A near-mirror lobe leaves with the coat's transmission at the view angle; q lies in [0, 1]."""
    eta = 1.5
    mu_t = refracted_cos(MU, eta)
    q = escape_fraction(mu_t, 0.01, gold_like, eta)
    # Away from grazing, where the smallest roughness still spreads the lobe across the coat's steep R.
    away = MU > 0.2
    np.testing.assert_allclose(q[away], 1.0 - fresnel_dielectric(MU[away], 1.0, eta)[:, None] * np.ones(3), atol=2e-3)
    rough = escape_fraction(mu_t, 0.6, gold_like, eta)
    assert np.all((rough >= 0.0) & (rough <= 1.0))
    assert np.all(rough[away] < q[away])  # a wide lobe leaves partly beyond the critical angle
    assert np.all(hemispherical_albedo(0.6, gold_like) < 1.0)


def test_rough_is_darker_than_the_series():
    """
    At roughness 0.6 the layer keeps less light than the mirror's series
    with the rough albedo (the lobe's share beyond the critical angle is
    reflected back and absorbed a little at each bounce), and the blend
    changes nothing at roughness 0.
    """
    eta, r = 1.5, 0.6
    layer = seen_base(MU, eta, r, gold_like)
    E = np.ones((MU.size, 3)) * 0.8
    series = through_coat(E, np.ones_like(E), np.zeros(3), 0.0, MU, eta, 0.0)
    kept = through_coat(E, np.full_like(E, 0.5), np.full(3, 0.8), internal_reflectance(eta), MU, eta, r)
    away = MU > 0.2  # at grazing the coat reflects most of the mirror's light, a spread lobe leaves better
    assert np.all(kept[away] < series[away])
    assert np.all(np.isfinite(layer)) and np.all(layer > 0.0)
