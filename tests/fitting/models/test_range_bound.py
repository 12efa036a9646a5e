"""The proven range of the coated-conductor model (fitting/models/range_bound.py)."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.range_bound import RANGE_SLACK, _centred_enclosure, certify_range, quadratic_range

DOMAIN = (1.0, 2.5)


def dense(C, n=100):
    """The model on an n x n grid (10^4 points for n = 100) over the domain."""
    E, M = np.meshgrid(np.linspace(*DOMAIN, n), np.linspace(0.0, 1.0, n), indexing="ij")
    return coated_conductor_model(M, E, C, DOMAIN)


def coefficients(F0, a, alpha):
    C = np.zeros((3, 3, 3))
    C[0, :, :] = F0
    C[1, :, :] = a
    C[2, :, :] = alpha
    return C


def test_quadratic_range_is_exact_against_sampling():
    rng = np.random.default_rng(3)
    c = rng.normal(size=(200, 3))
    t0, t1 = np.sort(rng.uniform(size=(2, 200)), axis=0)
    lo, hi = quadratic_range(c, t0, t1)
    t = t0[:, None] + (t1 - t0)[:, None] * np.linspace(0, 1, 2001)[None]
    v = c[:, :1] + c[:, 1:2] * t + c[:, 2:] * t * t
    # Sampling never leaves the exact range (1e-12: float64 rounding of a 3-term sum).
    assert np.all(v.min(axis=1) >= lo - 1e-12) and np.all(v.max(axis=1) <= hi + 1e-12)
    # ... and comes within the sampling step's effect (|c| < 5, step 5e-4 at most: |dv| <= 1e-2 * ...).
    assert np.all(lo >= v.min(axis=1) - 5e-3) and np.all(hi <= v.max(axis=1) + 5e-3)


def test_schlick_like_model_is_proven():
    C = coefficients([0.9, 0.0, 0.0], [0.3, 0.0, 0.0], [5.0, 0.0, 0.0])
    cert = certify_range(C, DOMAIN)
    assert cert.in_range is True
    F = dense(C)
    assert cert.lower <= F.min() and cert.upper >= F.max()


def test_excursion_between_grid_points_is_refuted():
    # A strong negative a with a large exponent: a bump above 1 just off grazing
    # incidence, between the points of a 100-point grid in cos theta.
    C = coefficients([0.95, 0.0, 0.0], [-2.0, 0.0, 0.0], [400.0, 0.0, 0.0])
    F = dense(C)
    assert F.max() <= 1.0 + RANGE_SLACK  # the dense grid misses it...
    cert = certify_range(C, DOMAIN)
    assert cert.in_range is False  # ...the proof does not
    mu, eta, channel, value = cert.worst
    assert value > 1.0 + RANGE_SLACK
    assert coated_conductor_model(mu, eta, C, DOMAIN)[channel] == pytest.approx(value, abs=1e-15)


def test_alpha_below_one_and_single_eta_domain():
    C = coefficients([0.5, 0.0, 0.0], [0.4, 0.0, 0.0], [0.3, 0.0, 0.0])
    cert = certify_range(C[:, :, :1], (1.5, 1.5))
    assert cert.in_range is True
    assert cert.lower >= -RANGE_SLACK


def test_negative_model_is_refuted():
    C = coefficients([0.05, 0.0, 0.0], [0.8, 0.0, 0.0], [2.0, 0.0, 0.0])
    cert = certify_range(C, DOMAIN)
    assert cert.in_range is False and cert.worst[3] < 0.0


def test_centred_form_encloses_the_model_on_every_cell():
    # The mean-value enclosure alone (before it is intersected with the first
    # form): random coefficients (alpha below 1 and the clamp at ALPHA_MIN
    # included) and random cells, the model sampled densely inside each cell.
    rng = np.random.default_rng(7)
    for _ in range(40):
        C = np.zeros((3, 3, 3))
        C[0] = rng.uniform(-0.3, 1.2, (3, 3)) * [[1.0, 0.5, 0.3]]
        C[1] = rng.normal(0.0, 1.5, (3, 3))
        C[2] = rng.uniform(-1.0, 12.0, (3, 3)) * [[1.0, 0.5, 0.5]]
        x0 = rng.uniform(0.0, 0.99, 20)
        x1 = np.minimum(1.0, x0 + rng.uniform(1e-3, 0.2, 20))
        t0 = rng.uniform(0.0, 0.9, 20)
        t1 = np.minimum(1.0, t0 + rng.uniform(1e-3, 0.3, 20))
        centre = coated_conductor_model(
            1.0 - 0.5 * (x0 + x1), DOMAIN[0] + (DOMAIN[1] - DOMAIN[0]) * 0.5 * (t0 + t1), C, DOMAIN
        )
        lo, hi = _centred_enclosure(C, x0, x1, t0, t1, centre)
        for i in range(20):
            X, T = np.meshgrid(np.linspace(x0[i], x1[i], 31), np.linspace(t0[i], t1[i], 11))
            F = coated_conductor_model(1.0 - X.ravel(), DOMAIN[0] + (DOMAIN[1] - DOMAIN[0]) * T.ravel(), C, DOMAIN)
            # 1e-12: ROUNDING_SLACK, the float64 rounding the enclosure allows for.
            assert np.all(F.min(axis=0) >= lo[i] - 1e-12) and np.all(F.max(axis=0) <= hi[i] + 1e-12)


def test_a_fit_touching_one_inside_the_domain_is_proven_in_few_cells():
    # The green channel of the degenerate base's refit, which
    # touches 1 inside the domain: the first-order form alone took 93,304
    # cells (0.2 s); with the centred form 1,456.
    C = np.array(
        [
            [[0.5, 0.0, 0.0], [0.0003001689910888672, 1.865234375, -1.712890625], [0.5, 0.0, 0.0]],
            [[0.0, 0.0, 0.0], [0.0823974609375, -0.499267578125, -2.734375], [0.0, 0.0, 0.0]],
            [[0.0, 0.0, 0.0], [3.033203125, -6.33984375, 4.48046875], [0.0, 0.0, 0.0]],
        ]
    )
    cert = certify_range(C, DOMAIN)
    assert cert.in_range is True and cert.cells < 5_000
    F = dense(C)
    assert cert.lower <= F.min() and cert.upper >= F.max() and F.max() > 1.0 - 1e-3
