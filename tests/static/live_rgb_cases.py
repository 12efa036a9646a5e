"""
The server's live step of the rgb-conductor kind on a few edits, as JSON for
the page's solver test (tests/static/js/live_rgb_conductor.test.mjs runs
``python -m tests.static.live_rgb_cases``).

For each case: the live problem exactly as :func:`fitting.fits.curves.fit_curves`
builds it for that kind with :data:`fitting.fits.curves.LIVE_SETTINGS`
(:func:`fitting.fits.curves_problem.curve_problem`: the blended target, its
samples and weights), the edit and the base's rows (for the page's target),
the solve's float64 n, k and the live step's float16 n, k, and the model's
exact Fresnel at a few points with its derivatives (for the page's Fresnel).
"""

from __future__ import annotations

import json
import sys

import numpy as np

from fitting.fits.curves import LIVE_SETTINGS, fit_curves
from fitting.fits.curves_base import curve_base_from_nk
from fitting.fits.curves_input import check_curves
from fitting.fits.curves_problem import curve_problem
from fitting.fits.curves_score import angle_mu
from fitting.fits.curves_steps import bounded_fit
from fitting.fits.kinds import fit_kind
from fitting.models.kinds import MODEL_KINDS
from fitting.optics.catalogue import catalogue_material
from fitting.optics.fresnel import fresnel_conductor_derivatives

from .live_cases import THETA, _bump

MODEL = next(name for name in MODEL_KINDS if fit_kind(name).bounded)  # the kind that is a reflectance by construction

CASES = [
    ("Au", 1.5, 60.0, (1.03, 1.0, 0.98)),
    ("Cu", 1.25, 36.0, (0.95, 1.02, 1.0)),
    ("Al", 2.0, 20.0, (0.9, 0.9, 1.1)),
    ("Cr", 1.0, 50.0, (1.5, 0.6, 1.3)),
    ("Ag", 1.5, 78.0, (0.6, 1.4, 1.6)),
]


def live_case(material: str, eta: float, centre: float, gains) -> dict:
    settings = LIVE_SETTINGS
    base = curve_base_from_nk(catalogue_material(material), (1.0, 2.5))
    lo, hi = base.eta_i_range
    reference = base.rgb(angle_mu(THETA), eta)
    rgb = np.clip(reference * (1.0 + _bump(THETA, centre)[:, None] * (np.array(gains) - 1.0)), 0.0, 1.0)
    curves = check_curves([{"eta_i": eta, "angle_deg": THETA.tolist(), "rgb": rgb.tolist()}])
    problem = curve_problem(curves, base, None, "live", settings, MODEL)
    solve = bounded_fit(problem)  # the server's own step for this kind (curves_steps)
    live = fit_curves(curves, base, settings=settings, model=MODEL)
    mu_row = angle_mu(np.linspace(0.0, 90.0, settings.mu_samples))
    rows = sorted({*np.linspace(lo, hi, settings.eta_samples).tolist(), eta})
    return {
        "name": f"{material} at {eta:g}, bump at {centre:g} deg x {list(gains)}",
        "target": problem.target.tolist(),
        "mu": problem.mu.tolist(),
        "eta": problem.eta.tolist(),
        "weights": None if problem.weights is None else np.asarray(problem.weights).tolist(),
        "range": [lo, hi],
        "edit": {"eta_i": eta, "angle_deg": THETA.tolist(), "rgb": rgb.tolist()},
        "base_rows": {f"{e:.6f}": base.rgb(mu_row, e).tolist() for e in rows},
        "x": solve.coefficients.ravel().tolist(),
        "live": {
            "coefficients16": live.coefficients_float16.astype(np.float64).ravel().tolist(),
            "best_effort": bool(live.best_effort),
        },
    }


def fresnel_points() -> list[dict]:
    """The exact Fresnel and its n, k derivatives at points of a conductor, a dielectric (TIR) and grazing."""
    points = [
        (0.8, 1.5, 0.2, 3.4),
        (0.3, 1.0, 1.1, 2.2),
        (0.05, 2.5, 2.0, 0.0),
        (0.6, 2.0, 1.2, 0.0),
        (0.0, 1.3, 0.5, 4.0),
        (1.0, 1.0, 1.0, 0.0),
    ]
    out = []
    for mu, eta_i, n, k in points:
        R, dn, dk = fresnel_conductor_derivatives(mu, eta_i, n, k)
        out.append({"at": [mu, eta_i, n, k], "R": float(R), "dn": float(dn), "dk": float(dk)})
    return out


def main() -> None:
    json.dump({"cases": [live_case(*case) for case in CASES], "fresnel": fresnel_points()}, sys.stdout)


if __name__ == "__main__":
    main()
