"""Metals given by F0 and F82 tint: the inversion to n, k, and the remap under a coat."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.colour.delta_e import delta_E_map
from fitting.colour.seen import SEEN_ANGLES_DEG
from fitting.exports.colour_space import lin_rec709_to_ACEScg
from fitting.exports.seen_fit import layer_only
from fitting.exports.tool_fresnel import f82_tint
from fitting.optics.coated_stack import coated_stack
from fitting.optics.edge_tint import (
    F82_COS_THETA,
    F0_F82_from_nk,
    F0_F82_under_coat,
    gulbrandsen_nk,
    nk_from_F0_F82,
)
from fitting.optics.fresnel import fresnel_conductor

# Gold, copper, chromium-like per-channel indices (R, G, B).
N = np.array([0.18, 0.55, 1.45])
K = np.array([3.4, 2.4, 1.8])


class TestNkFromF0F82:
    def test_round_trip(self):
        F0, tint = F0_F82_from_nk(N, K)
        index = nk_from_F0_F82(F0, tint)
        np.testing.assert_allclose(index.n, N, rtol=1e-8)
        np.testing.assert_allclose(index.k, K, rtol=1e-8)
        assert index.reachable.all() and np.max(np.abs(index.F82_error)) < 1e-12

    def test_both_anchors_hold(self):
        F0, tint = np.array([0.95, 0.64, 0.54]), np.array([0.9, 0.95, 1.0])
        index = nk_from_F0_F82(F0, tint)
        np.testing.assert_allclose(fresnel_conductor(1.0, 1.0, index.n, index.k), F0, atol=1e-12)
        schlick82 = F0 + (1.0 - F0) * (1.0 - F82_COS_THETA) ** 5
        np.testing.assert_allclose(
            fresnel_conductor(F82_COS_THETA, 1.0, index.n, index.k), tint * schlick82, atol=1e-10
        )

    def test_out_of_reach_is_reported(self):
        # A dielectric-like F0 with a strong edge dip: no conductor has it.
        index = nk_from_F0_F82([0.04], [0.1])
        assert not index.reachable[0] and index.F82_error[0] > 0.0
        assert np.isfinite(index.n).all() and np.isfinite(index.k).all()

    @pytest.mark.parametrize(
        "F0, tint, words",
        [
            ([0.5, np.nan, 0.5], [1, 1, 1], "`F0` must lie in [0, 1]"),
            ([0.5, 1.2, 0.5], [1, 1, 1], "`F0` must lie in [0, 1]"),
            ([0.5, 0.5, 0.5], [1, 1], "`F82_tint` must have one value per channel"),
            ([[0.5]], [1], "`F0` must be a list of numbers"),
            ([0.5], [np.inf], "`F82_tint` must lie in [0, 1]"),
        ],
    )
    def test_bad_input(self, F0, tint, words):
        with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("]", r"\]")):
            nk_from_F0_F82(F0, tint)


class TestGulbrandsen:
    def test_keeps_F0(self):
        r, g = np.array([0.95, 0.64, 0.54]), np.array([0.3, 0.6, 0.9])
        n, k = gulbrandsen_nk(r, g)
        np.testing.assert_allclose(fresnel_conductor(1.0, 1.0, n, k), r, atol=1e-12)

    def test_edge_tint_one_is_the_largest_n_zero_the_smallest(self):
        # g 0: n = (1 + sqrt r)/(1 - sqrt r), k 0; g 1: n = (1 - r)/(1 + r) (his limits).
        n0, k0 = gulbrandsen_nk([0.25], [0.0])
        n1, _ = gulbrandsen_nk([0.25], [1.0])
        assert n0[0] == pytest.approx(3.0) and k0[0] == pytest.approx(0.0, abs=1e-12)
        assert n1[0] == pytest.approx(0.6)


class TestUnderCoat:
    def test_no_coat_is_the_input(self):
        F0, tint = F0_F82_from_nk(N, K)
        out = F0_F82_under_coat(F0, tint, 1.0)
        np.testing.assert_array_equal(out[0], F0)
        np.testing.assert_array_equal(out[1], tint)

    def test_matches_the_stack_at_normal_incidence(self):
        F0, tint = F0_F82_from_nk(N, K)
        F0_c, _ = F0_F82_under_coat(F0, tint, 1.5)
        seen = coated_stack(np.array([[1.0]]), 1.5, N, K)[0]
        coat = ((1.5 - 1.0) / (1.5 + 1.0)) ** 2
        np.testing.assert_allclose(coat + (1.0 - coat) * F0_c, seen, atol=1e-12)

    def test_closer_than_the_metal_in_air(self):
        # Seen from air under a 1.5 coat: the renderer's layering of the remapped
        # base against the physical stack, beside the base left as in air.
        F0, tint = F0_F82_from_nk(N, K)
        view = np.cos(np.radians(SEEN_ANGLES_DEG))
        seen = lin_rec709_to_ACEScg(coated_stack(view[:, None], 1.5, N, K))

        def error(F0_b, tint_b):
            layered = layer_only("blender", view, 1.5, f82_tint(view, F0_b, tint_b))
            return float(delta_E_map(seen, lin_rec709_to_ACEScg(layered)).mean())

        remapped, in_air = error(*F0_F82_under_coat(F0, tint, 1.5)), error(F0, tint)
        assert remapped < 0.5 < in_air

    def test_bad_eta_i(self):
        with pytest.raises(ValueError, match="`eta_i` must lie in"):
            F0_F82_under_coat([0.5], [1.0], 3.5)
