"""fitting.fits.quantise: float16 coefficients."""

import numpy as np
import pytest

from fitting.colour.reference import reference_ACEScg
from fitting.domain import DEFAULT_ETA_I_RANGE
from fitting.fits.objective import Problem
from fitting.fits.quantise import compensations, quantise_coefficients
from fitting.fits.settings import fit_grid
from fitting.fits.solver import fit_coefficients
from fitting.models.pack import PackedMaterial, decode_pack, encode_pack
from fitting.optics.library import library_material

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


@pytest.fixture(scope="module", params=["Nb", "Cu"])
def real_problem(request):
    """
    A real fit and exactly the problem it solved: the weighted ``lab``
    objective on the Gauss grid of a library conductor (no reweighting
    rounds, so the last problem of the solver is this one).
    """
    nk = library_material(request.param)
    mu, eta, weights = fit_grid(DEFAULT_ETA_I_RANGE)
    target = reference_ACEScg(nk, mu, eta, 5.0)
    result = fit_coefficients(target, mu, eta, DEFAULT_ETA_I_RANGE, objective="lab", weights=weights)
    problem = Problem(target, mu, eta, DEFAULT_ETA_I_RANGE, 2, "lab", weights)
    return result, problem


def _cost(problem, C) -> float:
    return float(np.sum(problem.residuals(np.asarray(C, dtype=np.float64).ravel()) ** 2))


class TestQuantisation:
    def test_float16_never_worse_than_rounding(self, real_problem):
        result, problem = real_problem
        rounded = result.coefficients.astype(np.float16)
        assert result.coefficients_float16.dtype == np.float16
        # Strict: the quantiser keeps nearest rounding unless it does better.
        assert _cost(problem, result.coefficients_float16) <= _cost(problem, rounded)

    def test_quantiser_on_the_public_problem(self, real_problem):
        result, problem = real_problem
        again = quantise_coefficients(problem, result.coefficients)
        np.testing.assert_array_equal(again, result.coefficients_float16)
        # What the fit reports as its float16 cost is the cost of what it ships.
        assert result.cost_float16 == pytest.approx(0.5 * _cost(problem, again), rel=1e-12)  # one cost,
        # two summation orders of ~1e3 squared residuals: 1e3 u64 = 1.1e-13

    def test_quantised_coefficients_are_shipped_bit_for_bit(self, real_problem):
        result, _ = real_problem
        C16 = result.coefficients_float16
        # Within a few float16 steps of the optimum, not anywhere on the lattice.
        step = np.spacing(np.abs(result.coefficients).astype(np.float16)).astype(np.float64)
        assert np.all(np.abs(C16.astype(np.float64) - result.coefficients) <= 64 * step)
        packed = decode_pack(encode_pack([PackedMaterial("q", C16, DEFAULT_ETA_I_RANGE)]))[0]
        assert packed.coefficients.tobytes() == C16.tobytes()


class TestCompensations:
    def test_each_row_re_solves_the_free_coordinates(self):
        """One factorisation gives, row by row, what a solve over the still-free coordinates gives."""
        rng = np.random.default_rng(7)
        J = rng.standard_normal((60, 12)) * np.logspace(-2, 2, 12)
        H = J.T @ J
        scale = np.sqrt(np.diag(H))
        Hs = H / np.outer(scale, scale) + 1e-12 * np.eye(12)
        order = np.argsort(-np.diag(H))
        moves = compensations(Hs, order)
        for k, i in enumerate(order):
            free = order[k + 1 :]
            assert moves[k, k] == pytest.approx(1.0, abs=1e-12)
            if free.size:
                expected = -np.linalg.solve(Hs[np.ix_(free, free)], Hs[free, i])
                # Two factorisations of Hs (condition up to ~1e4 here, its columns
                # spanning 1e-2..1e2 before scaling): 1e4 * u64 << 1e-9.
                np.testing.assert_allclose(moves[k, k + 1 :], expected, rtol=1e-9, atol=1e-11)
