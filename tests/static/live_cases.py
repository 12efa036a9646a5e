"""
The server's live step on a few edits, as JSON for the page's solver test
(tests/static/js/live_solve.test.mjs runs ``python -m tests.static.live_cases``).

For each case: the live problem exactly as :func:`fitting.fits.curves.fit_curves`
builds it with :data:`fitting.fits.curves.LIVE_SETTINGS` (the blended target,
its samples and weights, the domain and degree, the start: the float16 fit
on screen), the first solve's coefficients
(:func:`fitting.fits.solver.fit_coefficients` with the live step's arguments)
and the whole live step's float16 coefficients, ``best_effort`` and whether
it escalated (its first solve outside [0, 1] on the scoring grid or unproven
between its points).
"""

from __future__ import annotations

import json
import sys

import numpy as np

from fitting.fits.curves import LIVE_SETTINGS, fit_curves
from fitting.fits.curves_base import curve_base_from_nk, edited_target
from fitting.fits.curves_input import check_curves
from fitting.fits.curves_range import outside_range, proven_in_range
from fitting.fits.curves_score import angle_mu, check_grid
from fitting.fits.solver import fit_coefficients
from fitting.models.pack import to_float16
from fitting.optics.catalogue import catalogue_material

THETA = np.arange(0.0, 91.0, 2.0)  # the editor's angles (static/editor/state.js SAMPLES)


def _bump(theta, centre, width=9.0):
    return np.clip(1.0 - np.abs(theta - centre) / width, 0.0, 1.0) ** 2


# (material, edited eta_i, channel gains of a bump at an angle): gentle and extreme edits.
CASES = [
    ("Au", 1.5, 60.0, (1.03, 1.0, 0.98)),
    ("Cu", 1.5, 36.0, (0.95, 1.02, 1.0)),
    ("Ag", 1.25, 70.0, (1.0, 0.97, 1.04)),
    ("Al", 2.0, 20.0, (0.9, 0.9, 1.1)),
    ("Au", 1.5, 78.0, (0.6, 1.4, 1.6)),
    ("Cr", 1.0, 50.0, (1.5, 0.6, 1.3)),
    # Pulled past what the model follows: the first solve leaves [0, 1] and the step escalates.
    ("Au", 1.5, 60.0, (1.0, 0.4, 1.0)),
    ("Au", 1.5, 60.0, (1.0, 0.15, 1.0)),
]


def live_case(material: str, eta: float, centre: float, gains) -> dict:
    settings = LIVE_SETTINGS
    base = curve_base_from_nk(catalogue_material(material), (1.0, 2.5))
    lo, hi = base.eta_i_range
    mu_edit = angle_mu(THETA)
    reference = base.rgb(mu_edit, eta)
    bump = _bump(THETA, centre)[:, None]
    rgb = np.clip(reference * (1.0 + bump * (np.array(gains) - 1.0)), 0.0, 1.0)
    curves = check_curves([{"eta_i": eta, "angle_deg": THETA.tolist(), "rgb": rgb.tolist()}])
    # The live problem as fit_curves builds it with a base.
    mu_row = angle_mu(np.linspace(0.0, 90.0, settings.mu_samples))
    rows = np.linspace(lo, hi, settings.eta_samples)
    rows = rows[np.abs(rows - eta) > 1e-6]
    rows = np.sort(np.concatenate([rows, [eta]]))
    E, M = np.meshgrid(rows, mu_row, indexing="ij")
    mu, eta_s = M.ravel(), E.ravel()
    target = edited_target(base, curves, mu, eta_s, settings.blend_width)
    weights = np.full(mu.size, settings.edit_weight)
    # The fit on screen: the unedited base, fitted (float16).
    plain = base.rgb(mu, eta_s)
    start = to_float16(
        fit_coefficients(plain, mu, eta_s, (lo, hi), 2, "de2000", 40, False, irls_rounds=0).coefficients
    ).astype(np.float64)
    CM, CE = check_grid((lo, hi), *settings.check_samples)
    first = fit_coefficients(
        target,
        mu,
        eta_s,
        (lo, hi),
        2,
        settings.objective,
        settings.max_nfev,
        False,
        weights=weights,
        irls_rounds=0,
        range_check=(CM.ravel(), CE.ravel(), settings.range_weight),
        start=start,
    )
    live = fit_curves(curves, base, settings=settings, start=start)
    first16 = to_float16(first.coefficients)
    escalated = bool(
        outside_range(first16, (lo, hi)).any() or not proven_in_range(first16, (lo, hi), max_cells=settings.proof_cells)
    )
    return {
        "name": f"{material} at {eta:g}, bump at {centre:g} deg x {list(gains)}",
        "target": target.tolist(),
        "mu": mu.tolist(),
        "eta": eta_s.tolist(),
        "weights": weights.tolist(),
        "range": [lo, hi],
        "degree": 2,
        "start": start.ravel().tolist(),
        "edit": {"eta_i": eta, "angle_deg": THETA.tolist(), "rgb": rgb.tolist()},
        "base_rows": {f"{e:.6f}": base.rgb(mu_row, e).tolist() for e in [*rows, eta]},
        "mu_row": mu_row.tolist(),
        "first": {"x": first.coefficients.ravel().tolist(), "nfev": int(first.nfev)},
        "live": {
            "coefficients16": live.coefficients_float16.astype(np.float64).ravel().tolist(),
            "best_effort": bool(live.best_effort),
            "escalated": escalated,
        },
    }


def main() -> None:
    json.dump([live_case(*case) for case in CASES], sys.stdout)


if __name__ == "__main__":
    main()
