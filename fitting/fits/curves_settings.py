"""
Settings of curve refits
========================

-   :class:`CurveFitSettings`: the settings of :func:`fitting.fits.curves.fit_curves`.
-   :data:`LIVE_SETTINGS`: the editor's warm-started refit while a point is
    dragged.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..domain import check_int, check_number
from .settings import check_fit_options

__all__ = ["CurveFitSettings", "LIVE_SETTINGS"]


@dataclass(frozen=True)
class CurveFitSettings:
    """
    Settings of :func:`fit_curves`.

    Attributes
    ----------
    mu_samples
        cos theta samples per eta_i row: each curve is resampled linearly to
        this many values evenly over its own span (without a base) or at
        angles evenly over [0, 90] degrees (with a base).
    eta_samples
        Rows of the base evenly over the domain, besides the edited rows.
    objective, irls_rounds, max_nfev, quantise
        Passed to :func:`fitting.fits.solver.fit_coefficients`.
    blend_width
        Distance in eta_i over which an edit fades beyond the outermost
        edited indices (:func:`fitting.fits.curves_base.blend_weights`).
    edit_weight
        Least-squares weight of each sample of an edited row relative to a
        sample of a base row (with a base): the edited curves are what the
        artist looks at (1: the whole blended target counts evenly, as it
        is scored).
    range_weight
        Weight of the [0, 1] constraint: hinge residuals at a check grid of
        ``check_samples`` = (angles, eta_i rows) over the whole domain, made
        ten times stiffer on a finer grid (at most twice) while the float16
        fit still leaves [0, 1] on the scoring grid; 0 turns it off.
    compare_rgb
        With a base, also fit the paper's method (plain rgb least squares)
        to the whole blended target (24 x 16, every other point of
        :data:`fitting.fits.curves_score.SCORE_GRID`); kept by :mod:`fitting.fits.curves_guard`.
    max_evaluations
        Model evaluations (residuals and Jacobians) of the whole refit, over
        every solve, escalation round and candidate: its CPU bound. A solve
        gets at most its share of what is left; a round is not started with
        fewer than 10 left. A fit the budget leaves outside [0, 1] is made
        in range (:func:`fitting.fits.curves_range.in_range_fallback`), and
        the metrics say ``best_effort``.
    proof_cells
        Cells the proof of [0, 1] (:func:`fitting.models.range_bound.certify_range`)
        examines at most per fit checked; a fit it cannot prove within them
        counts as outside (and gets its in-range fallback). Most fits are
        proven in under 2,000 cells; one that touches 1 inside the domain
        took 30,000-170,000 (0.1-0.4 s) before the proofs' centred form,
        a few thousand since.
    """

    mu_samples: int = 12
    eta_samples: int = 7
    objective: str = "de2000"
    irls_rounds: int = 1
    max_nfev: int = 20
    quantise: bool = True
    blend_width: float = 0.5
    edit_weight: float = 1.0
    range_weight: float = 300.0
    check_samples: tuple[int, int] = (19, 7)
    compare_rgb: bool = True
    max_evaluations: int = 300
    proof_cells: int = 400_000

    def __post_init__(self) -> None:
        check_int("mu_samples", self.mu_samples, 4, 256)
        check_int("eta_samples", self.eta_samples, 1, 64)
        check_fit_options(self.objective, self.max_nfev, self.irls_rounds)
        check_number("blend_width", self.blend_width, 0.0)
        check_number("edit_weight", self.edit_weight, 1.0, 1000.0)
        check_number("range_weight", self.range_weight, 0.0, 1e6)
        check_int("max_evaluations", self.max_evaluations, 1, 100_000)
        check_int("proof_cells", self.proof_cells, 256, 4_000_000)
        check = self.check_samples
        if not (
            isinstance(check, tuple) and len(check) == 2 and all(isinstance(n, int) and 2 <= n <= 256 for n in check)
        ):
            raise ValueError(f"`check_samples` must be two integers in [2, 256], got {check!r}")


LIVE_SETTINGS = CurveFitSettings(
    irls_rounds=0,
    max_nfev=4,
    compare_rgb=False,
    quantise=False,
    check_samples=(10, 4),
    max_evaluations=24,
    proof_cells=4_000,
)
"""The settings of a live refit, while a curve is being dragged: one solve of
at most 4 evaluations (no reweighting round, no paper-method candidate,
float16 by rounding to nearest, the [0, 1] check grid coarser at first),
meant to start from the fit on screen (``start``), so that it follows the
pointer; the [0, 1] constraint is the same as the default's (made stiffer
on the fine grid while the fit leaves [0, 1]). A live solve that still
leaves it answers the closer to the edit of its in-range fallback and the
fit it started from (``best_effort``): it never waits for a full refit. Its
proofs of [0, 1] examine at most 4,000 cells (about 20 ms), so a fit that
touches 1 along grazing cannot hold a step for 0.4 s; a fit unproven
within them counts as outside. The
editor replaces it with a default refit when the drag ends."""
