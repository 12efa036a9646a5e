"""
The range of the coated-conductor model, proven
===============================================

A grid check says where a model was looked at, not what it does between
the points. This module bounds the model of
:mod:`fitting.models.coated_conductor` over its whole domain,
:math:`\\mu \\in [0, 1]` times :math:`t \\in [0, 1]` (the normalised
coating index), by interval arithmetic with branch and bound.

Per channel, with :math:`x = 1 - \\mu`,

.. math::

    F = \\underbrace{F_0 (1 - x^5) + x^5}_{h(F_0,\\, x^5)}
        - a\\, \\underbrace{(1 - x)\\, x^{\\alpha}}_{g(x, \\alpha)},

with :math:`F_0, a, \\alpha` quadratics in *t* (alpha clamped to
``ALPHA_MIN``). On a cell :math:`[x_0, x_1] \\times [t_0, t_1]`:

-   a quadratic's exact range is its values at the cell's ends and at its
    vertex when inside (:func:`quadratic_range`);
-   :math:`h` is bilinear in :math:`(F_0, x^5)`, so its range is attained
    at the four corners of the box of their ranges;
-   :math:`g \\ge 0` grows with :math:`1 - x` and, for :math:`x < 1`,
    shrinks as :math:`\\alpha` grows, so
    :math:`g \\in [(1 - x_1) x_0^{\\alpha_1},\\ (1 - x_0) x_1^{\\alpha_0}]`;
-   :math:`a g` is an interval product, and
    :math:`F \\in [h_{lo} - (ag)_{hi},\\ h_{hi} - (ag)_{lo}]`;
-   near grazing incidence, where :math:`F \\to 1`, the upper bound is
    also taken from :math:`F - 1 = (1 - x)\\,q`, :math:`q = (F_0 - 1)
    (1 + x + x^2 + x^3 + x^4) - a x^\\alpha`, whose enclosure keeps the
    factor :math:`1 - x` exact.

These enclosures are rigorous for every point of the cell (no derivative
bound is needed, so the unbounded slope of :math:`x^\\alpha` at
:math:`x = 0` for :math:`\\alpha < 1` is no obstacle); they are loose only
by the dependency between :math:`h` and :math:`ag`, which shrinks with the
cell, linearly. Where a fit touches 1 inside the domain (the worst-case
guard's constrained fits sit at 1 + 1e-4) that takes tens of thousands of
cells, so each cell's enclosure is also taken in the centred (mean-value)
form and the two intersected (:func:`_centred_enclosure`):
:math:`F \\in F(x_c, t_c) \\pm (h_x \\max|\\partial_x F| + h_t
\\max|\\partial_t F|)` over the cell of half-widths :math:`h_x, h_t`, with

.. math::

    \\partial_x F = 5x^4 (1 - F_0) + a\\,x^{\\alpha}
        - a\\,\\alpha\\,(1 - x)\\,x^{\\alpha - 1},\\qquad
    \\partial_t F = F_0' (1 - x^5) - (1 - x)\\,x^{\\alpha}
        \\left(a' + a\\,\\alpha' \\ln x\\right),

each enclosed by interval arithmetic over the cell (:math:`x^\\beta` is
monotone in :math:`x` and in :math:`\\beta` on :math:`(0, 1]`, so its
range is at the cell's corners; :math:`\\alpha'` is widened to include 0
where the clamp at ``ALPHA_MIN`` may act: the model is Lipschitz there and
the mean-value bound holds with that generalised derivative). Its width
shrinks with the square of the cell where the gradient vanishes, as at a
touching maximum. Cells at :math:`x = 0` keep the first form alone (the
slope of :math:`x^\\alpha` is unbounded there). A cell whose enclosure lies inside
:math:`[-\\epsilon, 1 + \\epsilon]` is proven; a cell whose centre is outside
is a counterexample; every other cell is split in four, until a cell
budget. :func:`certify_range` returns the verdict with the proven bounds.
Float64 rounding of the enclosure (a few ulps of numbers at most about
:data:`fitting.models.coated_conductor.PARAMETER_LIMIT`) is covered by
:data:`ROUNDING_SLACK`.

References
----------
Moore, R. E., Kearfott, R. B., & Cloud, M. J. (2009). Introduction to
Interval Analysis. SIAM (interval extensions, branch and bound).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .coated_conductor import ALPHA_MIN, check_coefficients, coated_conductor_model

__all__ = ["RANGE_SLACK", "ROUNDING_SLACK", "RangeCertificate", "quadratic_range", "certify_range"]

RANGE_SLACK = 1.0e-4
"""How far past [0, 1] a float16 model may read and still count as inside:
the float16 rounding of a fit that touches the boundary (one float16 ulp of
F0 near 1 is 2^-11 = 4.9e-4, the rounding at most half of it, and fits keep
well under; a renderer's clamp makes 1e-4 invisible)."""

ROUNDING_SLACK = 1.0e-12
"""Allowance for float64 rounding of the interval bounds themselves."""

_START_CELLS = (32, 8)  # (x, t) cells of the first level
_MAX_CELLS = 400_000  # cells examined at most; beyond, the verdict is "unproven"
_CENTRED_AFTER = 1_024  # cells examined before the centred form is added (see certify_range)


@dataclass(frozen=True)
class RangeCertificate:
    """
    The verdict of :func:`certify_range`.

    Attributes
    ----------
    in_range
        True: proven inside [-slack, 1 + slack] everywhere; False: a point
        is outside (``worst``); None: neither within the cell budget.
    lower, upper
        Proven bounds of the model over the whole domain, every channel
        (from the enclosures of the final cells, so within the cells' width
        of the true extremes).
    worst
        ``(cos_theta, eta_i, channel, value)`` of the model value farthest
        outside [0, 1] found (the most extreme point evaluated when inside).
    cells
        Cells examined.
    """

    in_range: bool | None
    lower: float
    upper: float
    worst: tuple[float, float, int, float]
    cells: int

    def to_dict(self) -> dict:
        mu, eta, channel, value = self.worst
        return {
            "in_range": self.in_range,
            "proven_min": self.lower,
            "proven_max": self.upper,
            "worst": {"cos_theta": mu, "eta_i": eta, "channel": "RGB"[channel], "value": value},
            "cells": self.cells,
        }


def quadratic_range(c, t0, t1):
    """
    Exact range over :math:`t \\in [t_0, t_1]` of :math:`c_0 + c_1 t + c_2 t^2`
    (``c`` (..., 3) broadcast against the cells ``t0``, ``t1``).
    """
    c0, c1, c2 = c[..., 0], c[..., 1], c[..., 2]

    def value(t):
        return c0 + t * (c1 + t * c2)

    v0, v1 = value(t0), value(t1)
    lo, hi = np.minimum(v0, v1), np.maximum(v0, v1)
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(c2 != 0.0, -c1 / (2.0 * c2), np.inf)
    inside = (vertex > t0) & (vertex < t1)
    vv = value(np.where(inside, vertex, t0))
    return np.where(inside, np.minimum(lo, vv), lo), np.where(inside, np.maximum(hi, vv), hi)


def _enclosure(C, x0, x1, t0, t1):
    """(lower, upper) of each channel's model on each cell: shape (cells, 3)."""
    t0, t1 = t0[:, None], t1[:, None]
    F_lo, F_hi = quadratic_range(C[0][None], t0, t1)
    a_lo, a_hi = quadratic_range(C[1][None], t0, t1)
    al_lo, al_hi = quadratic_range(C[2][None], t0, t1)
    al_lo, al_hi = np.maximum(al_lo, ALPHA_MIN), np.maximum(al_hi, ALPHA_MIN)
    x0, x1 = x0[:, None], x1[:, None]
    p_lo, p_hi = x0**5, x1**5
    corners = np.stack([F * (1.0 - p) + p for F in (F_lo, F_hi) for p in (p_lo, p_hi)])
    h_lo, h_hi = corners.min(axis=0), corners.max(axis=0)
    g_lo = (1.0 - x1) * x0**al_hi
    g_hi = (1.0 - x0) * x1**al_lo
    products = np.stack([a * g for a in (a_lo, a_hi) for g in (g_lo, g_hi)])
    ag_lo, ag_hi = products.min(axis=0), products.max(axis=0)
    upper = h_hi - ag_lo
    # Near grazing incidence F -> 1: F - 1 = (1 - x) q with
    # q = (F0 - 1)(1 + x + x^2 + x^3 + x^4) - a x^alpha, whose enclosure
    # keeps the factor (1 - x) exact (no dependency between h and a g).
    s_lo, s_hi = 1 + x0 + x0**2 + x0**3 + x0**4, 1 + x1 + x1**2 + x1**3 + x1**4
    xa_lo, xa_hi = x0**al_hi, x1**al_lo
    fs = np.stack([(F - 1.0) * s for F in (F_lo, F_hi) for s in (s_lo, s_hi)])
    axa = np.stack([a * xa for a in (a_lo, a_hi) for xa in (xa_lo, xa_hi)])
    q_hi = fs.max(axis=0) - axa.min(axis=0)
    upper = np.minimum(upper, 1.0 + np.where(q_hi > 0.0, (1.0 - x0) * q_hi, (1.0 - x1) * q_hi))
    return h_lo - ag_hi - ROUNDING_SLACK, upper + ROUNDING_SLACK


def _product(a_lo, a_hi, b_lo, b_hi):
    """Interval product: (lo, hi) of a * b over the boxes."""
    corners = np.stack([a_lo * b_lo, a_lo * b_hi, a_hi * b_lo, a_hi * b_hi])
    return corners.min(axis=0), corners.max(axis=0)


def _power_range(x0, x1, b_lo, b_hi):
    """(lo, hi) of x ** b for x in [x0, x1] within (0, 1], b in [b_lo, b_hi]: at the corners
    (monotone in x for each b, decreasing in b for each x)."""
    corners = np.stack([x0**b_lo, x0**b_hi, x1**b_lo, x1**b_hi])
    return corners.min(axis=0), corners.max(axis=0)


def _centred_enclosure(C, x0, x1, t0, t1, centre):
    """
    (lower, upper) of each channel's model on each cell in the centred
    (mean-value) form of the module docstring, shape (cells, 3), from
    ``centre``, the model at each cell's centre (cells, 3); cells at x = 0
    get (-inf, inf).
    """
    inner = x0 > 0.0
    t0, t1 = t0[:, None], t1[:, None]
    x0, x1 = np.where(inner, x0, 0.5)[:, None], x1[:, None]
    hx, ht = 0.5 * (x1 - x0), 0.5 * (t1 - t0)
    F_lo, F_hi = quadratic_range(C[0][None], t0, t1)
    a_lo, a_hi = quadratic_range(C[1][None], t0, t1)
    al_lo, al_hi = quadratic_range(C[2][None], t0, t1)
    clamp_may_act = al_lo < ALPHA_MIN
    al_lo, al_hi = np.maximum(al_lo, ALPHA_MIN), np.maximum(al_hi, ALPHA_MIN)

    # Derivatives of the quadratics in t (linear: their ends).
    def slope(c):
        d0, d1 = c[..., 1] + 2.0 * c[..., 2] * t0, c[..., 1] + 2.0 * c[..., 2] * t1
        return np.minimum(d0, d1), np.maximum(d0, d1)

    dF_lo, dF_hi = slope(C[0][None])
    da_lo, da_hi = slope(C[1][None])
    dal_lo, dal_hi = slope(C[2][None])
    dal_lo = np.where(clamp_may_act, np.minimum(dal_lo, 0.0), dal_lo)
    dal_hi = np.where(clamp_may_act, np.maximum(dal_hi, 0.0), dal_hi)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        xa_lo, xa_hi = _power_range(x0, x1, al_lo, al_hi)  # x^alpha
        xa1_lo, xa1_hi = _power_range(x0, x1, al_lo - 1.0, al_hi - 1.0)  # x^(alpha - 1)
        x4_lo, x4_hi = x0**4, x1**4
        # d/dx: 5 x^4 (1 - F0) + a x^alpha - a alpha (1 - x) x^(alpha - 1)
        p_lo, p_hi = _product(5.0 * x4_lo, 5.0 * x4_hi, 1.0 - F_hi, 1.0 - F_lo)
        q_lo, q_hi = _product(a_lo, a_hi, xa_lo, xa_hi)
        aal_lo, aal_hi = _product(a_lo, a_hi, al_lo, al_hi)
        w_lo, w_hi = _product(1.0 - x1, 1.0 - x0, xa1_lo, xa1_hi)
        r_lo, r_hi = _product(aal_lo, aal_hi, w_lo, w_hi)
        dx_lo, dx_hi = p_lo + q_lo - r_hi, p_hi + q_hi - r_lo
        # d/dt: F0' (1 - x^5) - (1 - x) x^alpha (a' + a alpha' ln x)
        u_lo, u_hi = _product(dF_lo, dF_hi, 1.0 - x1**5, 1.0 - x0**5)
        g_lo, g_hi = _product(1.0 - x1, 1.0 - x0, xa_lo, xa_hi)
        ada_lo, ada_hi = _product(a_lo, a_hi, dal_lo, dal_hi)
        v_lo, v_hi = _product(ada_lo, ada_hi, np.log(x0), np.log(x1))
        s_lo, s_hi = _product(g_lo, g_hi, da_lo + v_lo, da_hi + v_hi)
        dt_lo, dt_hi = u_lo - s_hi, u_hi - s_lo
        radius = hx * np.maximum(np.abs(dx_lo), np.abs(dx_hi)) + ht * np.maximum(np.abs(dt_lo), np.abs(dt_hi))
    radius = np.where(np.isfinite(radius) & inner[:, None], radius, np.inf)
    return centre - radius - ROUNDING_SLACK, centre + radius + ROUNDING_SLACK


def certify_range(
    coefficients, eta_i_range, slack: float = RANGE_SLACK, max_cells: int = _MAX_CELLS
) -> RangeCertificate:
    """
    Prove (or refute) that the model of ``coefficients`` over
    ``eta_i_range`` lies in [-``slack``, 1 + ``slack``] for every
    cos theta in [0, 1] and eta_i in the domain, every channel (see the
    module docstring for the bounds used).
    """
    C = check_coefficients(coefficients)
    if C.shape[2] < 3:
        C = np.concatenate([C, np.zeros((3, 3, 3 - C.shape[2]))], axis=2)
    lo_eta, hi_eta = eta_i_range
    span = hi_eta - lo_eta

    def to_eta(t):
        return lo_eta + t * span if span > 0 else np.full_like(t, lo_eta)

    nx, nt = _START_CELLS
    if span <= 0:
        nt = 1
    xe, te = np.linspace(0.0, 1.0, nx + 1), np.linspace(0.0, 1.0, nt + 1)
    X0, T0 = np.meshgrid(xe[:-1], te[:-1], indexing="ij")
    X1, T1 = np.meshgrid(xe[1:], te[1:], indexing="ij")
    x0, x1, t0, t1 = X0.ravel(), X1.ravel(), T0.ravel(), T1.ravel()
    lower, upper = np.inf, -np.inf
    worst = (1.0, lo_eta, 0, 0.5)
    worst_excess = -np.inf
    examined = 0
    verdict: bool | None = True
    while x0.size:
        examined += x0.size
        # The model at each cell's corners and centre: counterexamples and the extremes found.
        samples = [
            (xp, tp, coated_conductor_model(1.0 - xp, to_eta(tp), C, eta_i_range))
            for xp, tp in ((x0, t0), (x1, t1), (x0, t1), (x1, t0), (0.5 * (x0 + x1), 0.5 * (t0 + t1)))
        ]
        lo, hi = _enclosure(C, x0, x1, t0, t1)
        # The centred form where the first cannot decide, once a proof has examined
        # _CENTRED_AFTER cells (it costs more per cell; most proofs end before), about
        # the centre's value just computed.
        open_ = ~np.all((lo >= -slack) & (hi <= 1.0 + slack), axis=1)
        if examined > _CENTRED_AFTER and open_.any():
            c_lo, c_hi = _centred_enclosure(C, x0[open_], x1[open_], t0[open_], t1[open_], samples[-1][2][open_])
            lo[open_], hi[open_] = np.maximum(lo[open_], c_lo), np.minimum(hi[open_], c_hi)
        for xp, tp, values in samples:
            excess = np.maximum(-values, values - 1.0)
            i = np.unravel_index(int(np.argmax(excess)), excess.shape)
            if excess[i] > worst_excess:
                worst_excess = float(excess[i])
                worst = (float(1.0 - xp[i[0]]), float(to_eta(tp)[i[0]]), int(i[1]), float(values[i]))
        if worst_excess > slack:
            verdict = False
        proven = np.all((lo >= -slack) & (hi <= 1.0 + slack), axis=1)
        lower = min(lower, float(lo[proven].min()) if proven.any() else lower)
        upper = max(upper, float(hi[proven].max()) if proven.any() else upper)
        if verdict is False:
            # Refuted: the bounds of what is left are its enclosure.
            lower, upper = min(lower, float(lo.min())), max(upper, float(hi.max()))
            break
        keep = ~proven
        if not keep.any():
            break
        if examined + 4 * int(keep.sum()) > max_cells:
            verdict = None
            lower, upper = min(lower, float(lo[keep].min())), max(upper, float(hi[keep].max()))
            break
        x0, x1, t0, t1 = x0[keep], x1[keep], t0[keep], t1[keep]
        xm, tm = 0.5 * (x0 + x1), 0.5 * (t0 + t1)
        if span <= 0:
            x0, x1 = np.concatenate([x0, xm]), np.concatenate([xm, x1])
            t0, t1 = np.concatenate([t0, t0]), np.concatenate([t1, t1])
        else:
            x0, x1, t0, t1 = (
                np.concatenate([x0, xm, x0, xm]),
                np.concatenate([xm, x1, xm, x1]),
                np.concatenate([t0, t0, tm, tm]),
                np.concatenate([tm, tm, t1, t1]),
            )
    return RangeCertificate(verdict, float(lower), float(upper), worst, examined)
