"""The proven range of the coated-conductor model (fitting/models/range_bound.py, issue 21)."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.range_bound import RANGE_SLACK, certify_range, quadratic_range

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
