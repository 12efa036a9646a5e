"""
The minimax over both auditors
==============================

When no candidate of a curve refit holds both auditors
(:mod:`fitting.fits.curves_audit`: the paper's method fitted with angles
evenly and with cos theta evenly; each one's fit can lose on the other's
grid), the guard (:mod:`fitting.fits.curves_guard`) fits both measures at
once:

-   :func:`minimax_fit`: the fit of least largest excess over either
    auditor's mean or max (true Delta E 2000 at the samples nearest their
    cap, on both full grids), by SLSQP on the coefficients and the level
    (a level at or under 1 holds both), then the least mean under both.
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab, ACEScg_to_Lab_deferred
from ..colour.delta_e import delta_E_2000
from ..models.coated_conductor import coated_conductor_model, model_jacobian
from ..models.pack import to_float16
from ..numerics import scipy_optimize
from .curves_audit import AUDIT_GRIDS, AUDIT_SAMPLES, AuditGrid
from .curves_score import check_grid
from .objective import Problem, coefficient_bounds, delta_E_gradients
from .worst_case import MAX_MARGIN
from ..numerics.plain import union

__all__ = ["CHECK_SAMPLES", "MINIMAX_SAMPLES", "MINIMAX_LEVEL", "minimax_fit"]

CHECK_SAMPLES = (19, 7)
"""Where the constrained refits keep the model in [0, 1]: the refit's default check grid."""

MINIMAX_SAMPLES = 30
"""The samples of the means of the minimax fit (:func:`minimax_fit`): this many angles evenly times as many
eta_i, and as many cos theta evenly times as many eta_i (first-order Delta E, scaled to the true one)."""

MINIMAX_LEVEL = 0.99
"""The level of the minimax fit's second solve: the least mean with every figure this far under its floor."""

_MINIMAX_STEPS = 40  # SLSQP iterations of one solve (28 unknowns)
_MINIMAX_ROUNDS = 3  # minimax solves while a true figure on the full grids is above its floor; then the least mean
_MINIMAX_ROWS = 200  # rows a solve adds: the samples of largest Delta E relative to their cap
_MINIMAX_LATTICE = 10  # every tenth angle and eta_i of an auditor's grid is a row from the first solve
_MINIMAX_MEAN_WEIGHT = 0.05  # the means' share of the minimax objective beside the largest excess


def _lattice(full) -> np.ndarray:
    """The indices of every :data:`_MINIMAX_LATTICE`-th angle and eta_i of the auditors' grids, concatenated."""
    out = []
    for g in full:
        index = np.arange(g.M.size)
        out.append(
            ((index % AUDIT_SAMPLES) % _MINIMAX_LATTICE == 0) & ((index // AUDIT_SAMPLES) % _MINIMAX_LATTICE == 0)
        )
    return np.flatnonzero(np.concatenate(out))


def minimax_fit(base, curves, blend_width, full: list, start, floor: dict, aim: dict, degree: int):
    """
    Yield ``(C, C16)`` of the minimax fits over both auditors at once, then
    of the least mean under both. The minimax: the largest of each
    measure's mean Delta E 2000 over ``floor``'s mean and of every
    sample's over ``floor``'s max (plus :data:`_MINIMAX_MEAN_WEIGHT` times
    the means over their floors), minimised from ``start`` by SLSQP on the
    coefficients (scaled alike) and that level t, with the model in
    [0, 1] at the check grid: t <= 1 holds both auditors on both figures.
    Once a minimax fit holds them (true CIEDE2000 on ``full``, the
    auditors' :class:`fitting.fits.curves_audit.AuditGrid`), the mean
    summed over the measures is minimised from it with t held at
    :data:`MINIMAX_LEVEL`, each figure over ``aim``'s (the max less
    :data:`fitting.fits.worst_case.MAX_MARGIN`) where the minimax fit is
    under it, else over ``floor``'s. The max rows are true Delta E 2000 at samples
    of ``full`` (a lattice and those nearest their cap, kept from solve to
    solve); the means are first-order (the de2000 objective's) on
    :data:`MINIMAX_SAMPLES` a side, scaled to the true ones where a solve
    starts. A minimax solve starts again from the last, with the rows
    where it left the max, while it does not hold, at most
    :data:`_MINIMAX_ROUNDS` times.
    """
    grids = [AuditGrid(base, curves, blend_width, by, MINIMAX_SAMPLES) for by in AUDIT_GRIDS]
    share = np.split(np.arange(sum(g.M.size for g in grids)), np.cumsum([g.M.size for g in grids])[:-1])
    means = Problem(
        np.concatenate([g.T for g in grids]),
        np.concatenate([g.M for g in grids]),
        np.concatenate([g.E for g in grids]),
        base.eta_i_range,
        degree,
        "de2000",
    )
    CM, CE = (v.ravel() for v in check_grid(base.eta_i_range, *CHECK_SAMPLES))
    lower, upper = coefficient_bounds(degree)
    n, shape = lower.size, (3, 3, degree + 1)
    mean_floor = np.maximum([floor[g.by].mean for g in full], 1e-9)
    max_floor = np.maximum([floor[g.by].max for g in full], 1e-9)
    all_M, all_E = np.concatenate([g.M for g in full]), np.concatenate([g.E for g in full])
    all_Lab, sizes = np.concatenate([g.Lab for g in full]), [g.M.size for g in full]
    optimize, threadpools = scipy_optimize()
    kept = _lattice(full)

    def figures(x):
        """The true Delta E 2000 on each full grid of ``x`` rounded to float16, and whether they hold."""
        true = [g.delta_E(to_float16(x.reshape(shape))) for g in full]
        held = all(t.mean() <= m and t.max() <= c for t, m, c in zip(true, mean_floor, max_floor))
        return true, held

    def solve(x, true, least_mean: bool, mean_floor=mean_floor, max_floor=max_floor):
        nonlocal kept
        all_cap = np.repeat(max_floor, sizes)
        relative = np.concatenate(true) / all_cap
        top = np.argsort(-relative)[:_MINIMAX_ROWS]
        kept = union(kept, top[relative[top] > 0.5 * relative.max()])
        M, E, Lab, cap = all_M[kept], all_E[kept], all_Lab[kept], all_cap[kept]
        r = means.residuals_deferred(x)[0]
        dE = np.sqrt(np.sum(r * r, axis=1))
        mean_scale = np.array([t.mean() / max(dE[s].mean(), 1e-12) for t, s in zip(true, share)]) / mean_floor

        def peaks(x):
            return delta_E_2000(Lab, ACEScg_to_Lab(coated_conductor_model(M, E, x.reshape(shape), base.eta_i_range)))

        def peaks_jac(x, f):
            """The gradient of the true Delta E 2000 at the rows (``f`` at ``x``): in Lab by differences, then exact."""
            F, Jm = model_jacobian(M, E, x.reshape(shape), base.eta_i_range)  # Jm[k, c, p, j]
            model_Lab, lab_jacobian = ACEScg_to_Lab_deferred(F)
            dLab = np.stack([(delta_E_2000(Lab, model_Lab + 1e-6 * e) - f) / 1e-6 for e in np.eye(3)], axis=-1)
            dF = np.einsum("ko,koc->kc", dLab, lab_jacobian())
            return np.einsum("kc,kcpj->kpcj", dF, Jm).reshape(f.size, n)

        def values(x, jacobian=True):
            """Each row's Delta E over its cap and each measure's mean over its floor; with their gradients."""
            r, jac = means.residuals_deferred(x)
            dE = np.sqrt(np.sum(r * r, axis=1))
            m = np.array([dE[s].mean() for s in share]) * mean_scale
            f = peaks(x)
            if not jacobian:
                return f / cap, None, m, None
            D = delta_E_gradients(r, jac())
            Dm = np.array([D[s].mean(axis=0) for s in share]) * mean_scale[:, None]
            return f / cap, peaks_jac(x, f) / cap[:, None], m, Dm

        f, Df, m, Dm = values(x)
        scale = np.sqrt(np.mean(np.vstack([Df, Dm]) ** 2, axis=0)) + 1e-12  # u = x * scale: each moves f alike
        weight = 1.0 if least_mean else _MINIMAX_MEAN_WEIGHT
        last: dict = {}

        def at(z, jacobian=False):
            if last.get("key") != z.tobytes() or (jacobian and last["v"][1] is None):
                last.update(key=z.tobytes(), v=values(z[:n] / scale, jacobian))
            return last["v"]

        def objective(z):
            return (0.0 if least_mean else z[n]) + weight * at(z)[2].sum()

        def objective_jac(z):
            return np.append(weight * at(z, True)[3].sum(axis=0) / scale, 0.0 if least_mean else 1.0)

        def levels(z):
            f, _, m, _ = at(z)
            return z[n] - np.concatenate([f, m])

        def levels_jac(z):
            _, Df, _, Dm = at(z, True)
            return np.hstack([-np.vstack([Df, Dm]) / scale, np.ones((f.size + m.size, 1))])

        constraints = [{"type": "ineq", "fun": levels, "jac": levels_jac}]
        inside = _inside_constraint(CM, CE, x.reshape(shape), base.eta_i_range, scale)
        if inside is not None:
            constraints.append(inside)
        level = max(f.max(), m.max())
        with threadpools.limit(limits=1, user_api="blas"):
            result = optimize.minimize(
                objective,
                np.append(x * scale, min(level, MINIMAX_LEVEL) if least_mean else level),
                jac=objective_jac,
                method="SLSQP",
                bounds=[(lo * s_, hi * s_) for lo, hi, s_ in zip(lower, upper, scale)]
                + [(0.0, MINIMAX_LEVEL if least_mean else None)],
                constraints=constraints,
                options={"maxiter": _MINIMAX_STEPS, "ftol": 1e-7},
            )
        if not np.all(np.isfinite(result.x)):
            return None, np.inf
        x = result.x[:n] / scale
        f, _, m, _ = values(x, False)
        return x, max(f.max(), m.max())

    x = np.clip(np.ravel(start), lower, upper)
    true, held = figures(x)
    for _ in range(_MINIMAX_ROUNDS):
        x, level = solve(x, true, False)
        if x is None:
            return
        yield x.reshape(shape), to_float16(x.reshape(shape))
        true, held = figures(x)
        if held or level > 1.0:  # held, or not even at the rows: solving again would not hold either
            break
    if not held:
        return
    mean_aim = np.array([aim[g.by].mean for g in full])
    max_aim = np.array([aim[g.by].max for g in full]) * (1.0 - MAX_MARGIN)
    means_now, maxes_now = np.array([t.mean() for t in true]), np.array([t.max() for t in true])
    x, _ = solve(
        x,
        true,
        True,
        np.where(means_now <= mean_aim, np.maximum(mean_aim, 1e-9), mean_floor),
        np.where(maxes_now <= max_aim, np.maximum(max_aim, 1e-9), max_floor),
    )
    if x is not None:
        yield x.reshape(shape), to_float16(x.reshape(shape))


def _inside_constraint(mu, eta, C, eta_i_range, scale):
    """
    SLSQP's inequality keeping the model in [0, 1] at (``mu``, ``eta``), on
    the unknowns ``z`` (coefficients times ``scale``, then the level): a
    row for each point and channel within 0.05 of an end at ``C`` (grazing
    incidence left out: the model is 1 there whatever the fit); None when none is.
    """
    n = C.size
    F0 = coated_conductor_model(mu, eta, C, eta_i_range)
    k, c = np.nonzero(((F0 < 0.05) | (F0 > 0.95)) & (mu[:, None] > 0.0))
    if not k.size:
        return None
    high = F0[k, c] > 0.5
    sign, offset = np.where(high, -1.0, 1.0), np.where(high, 1.0, 0.0)

    def fun(z):
        return sign * coated_conductor_model(mu, eta, (z[:n] / scale).reshape(C.shape), eta_i_range)[k, c] + offset

    def jac(z):
        _, Jm = model_jacobian(mu, eta, (z[:n] / scale).reshape(C.shape), eta_i_range)
        J = np.zeros((k.size,) + C.shape)
        J[np.arange(k.size), :, c, :] = sign[:, None, None] * Jm[k, c]
        return np.hstack([J.reshape(k.size, n) / scale, np.zeros((k.size, 1))])

    return {"type": "ineq", "fun": fun, "jac": jac}
