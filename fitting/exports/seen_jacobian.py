"""
Jacobians of the seen fits
==========================

The derivatives :mod:`fitting.exports.seen_fit` solves with, for the
tool's layered result (:func:`fitting.exports.tool_layering.tool_seen`,
linear Rec.709) against a target in linear ACEScg, per view angle:

-   :func:`tool_derivative`: the layered result and its derivative in each
    unknown. The layerings are closed-form (Fresnel terms, Schlick / F82,
    products and sums) with clamps at the tools' limits, differenced here
    centrally (step 1e-5 max(1, |x|), one-sided at a bound) with every
    unknown of one colour channel moved in one point: a channel's result
    depends on its own values alone (glTF's clear coat factor, a fourth
    unknown, moves all three), so a Jacobian costs two layerings per three
    unknowns, in one vectorised call.
-   :func:`delta_E_jacobian`: the (S, n) Jacobian of the Delta E 2000 per
    angle: its exact gradient in the colour
    (:func:`fitting.colour.delta_e.delta_E_2000_gradient` through Lab and
    the linear change of primaries) times :func:`tool_derivative`.
-   :class:`DeltaEComponents`: the residuals the fits minimise, the three
    components of each angle's Delta E
    (:func:`fitting.colour.delta_e.delta_E_2000_components`: the same sum
    of squares), and their (3 S, n) Jacobian.
-   :func:`stacked`: export values of several points as one set.
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab, ACEScg_to_Lab_and_jacobian
from ..colour.delta_e import delta_E_2000_components, delta_E_2000_gradient
from .colour_space import DEFAULT_WORKING_SPACE, working_to_ACEScg
from .tool_layering import tool_seen

__all__ = ["STEP", "stacked", "tool_derivative", "delta_E_jacobian", "DeltaEComponents"]

STEP = 1e-5
"""The layering's difference step, relative to max(1, |x|)."""


def stacked(values: list[dict], samples: int) -> dict:
    """
    Export values of P points as one set for P x ``samples`` view angles
    (the angles tiled P times): each per-channel value (3,) repeated to
    (P S, 3), each number to (P S,); ``coat`` (the same for every point) as is.
    """
    out: dict = {}
    for key, first in values[0].items():
        if isinstance(first, (bool, np.bool_)):
            out[key] = first
        else:
            column = np.asarray([v[key] for v in values], dtype=np.float64)
            out[key] = np.repeat(column, samples, axis=0)
    return out


def tool_derivative(tool: str, pack, x, lo, hi, mu, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """
    The layered result of ``tool`` at ``pack(x)`` (S, 3) and its derivative
    in each unknown (S, 3, n), ``D[s, c, j] = d rgb_c / d x_j``; unknown j
    belongs to channel j mod 3, except glTF's fourth (all channels).
    """
    x = np.asarray(x, dtype=np.float64)
    S, n = mu.size, x.size
    groups = [list(range(g, min(g + 3, n))) for g in range(0, n, 3)]
    h = STEP * np.maximum(1.0, np.abs(x))
    points, steps = [], []
    for g in groups:
        up, down = x.copy(), x.copy()
        up[g], down[g] = np.minimum(x[g] + h[g], hi[g]), np.maximum(x[g] - h[g], lo[g])
        points += [up, down]
        steps.append(up[g] - down[g])
    P = len(points) + 1
    rgb = tool_seen(tool, stacked([pack(p) for p in points] + [pack(x)], S), np.tile(mu, P), eta)
    rgb = rgb.reshape(P, S, 3)
    D = np.zeros((S, 3, n))
    for i, (g, step) in enumerate(zip(groups, steps)):
        d = rgb[2 * i] - rgb[2 * i + 1]
        if len(g) == 1 and tool == "gltf":
            D[:, :, g[0]] = d / step[0]
            continue
        for c, j in enumerate(g):
            D[:, c, j] = d[:, c] / step[c]
    return rgb[-1], D


def _to_ACEScg(space: str = DEFAULT_WORKING_SPACE) -> np.ndarray:
    return working_to_ACEScg(np.eye(3), space).T  # ACEScg = this @ rgb of the working space (a linear map)


def delta_E_jacobian(
    tool: str,
    pack,
    x,
    lo,
    hi,
    mu,
    eta: float,
    target_ACEScg,
    square_root: bool = False,
    space: str = DEFAULT_WORKING_SPACE,
) -> np.ndarray:
    """
    The (S, n) Jacobian of the Delta E 2000 per angle of ``pack(x)`` (values
    in the working space ``space``) against ``target_ACEScg`` (of its
    ``sqrt(Delta E + 1e-6)`` with ``square_root``).
    """
    rgb, D = tool_derivative(tool, pack, x, lo, hi, mu, eta)
    M = _to_ACEScg(space)
    Lab, dLab = ACEScg_to_Lab_and_jacobian(rgb @ M.T)
    dE, grad = delta_E_2000_gradient(ACEScg_to_Lab(target_ACEScg), Lab)
    g_rgb = np.einsum("si,sij->sj", grad, dLab) @ M  # d Delta E / d rgb, (S, 3)
    if square_root:
        g_rgb = g_rgb / (2.0 * np.sqrt(dE + 1e-6))[:, None]
    return np.einsum("sc,scj->sj", g_rgb, D)


class DeltaEComponents:
    """
    The least-squares problem of a seen fit on the components of each
    angle's Delta E 2000: ``fun(x)`` (3 S,), whose sum of squares is that of
    the Delta E, and ``jac(x)`` (3 S, n).
    """

    def __init__(
        self, tool: str, pack, lo, hi, mu, eta: float, target_ACEScg, space: str = DEFAULT_WORKING_SPACE
    ) -> None:
        self.tool, self.pack, self.lo, self.hi, self.mu, self.eta = tool, pack, lo, hi, mu, eta
        self.target_Lab = ACEScg_to_Lab(target_ACEScg)
        self.M = _to_ACEScg(space)  # the values are in the working space ``space``

    def fun(self, x) -> np.ndarray:
        Lab = ACEScg_to_Lab(tool_seen(self.tool, self.pack(x), self.mu, self.eta) @ self.M.T)
        v, dv = delta_E_2000_components(self.target_Lab, Lab)
        self._last = (np.array(x, dtype=np.float64), dv)  # scipy asks for J where it just asked for f
        return v.ravel()

    def jac(self, x) -> np.ndarray:
        rgb, D = tool_derivative(self.tool, self.pack, x, self.lo, self.hi, self.mu, self.eta)
        Lab, dLab = ACEScg_to_Lab_and_jacobian(rgb @ self.M.T)
        last = getattr(self, "_last", None)
        if last is not None and np.array_equal(last[0], x):
            dv = last[1]
        else:
            dv = delta_E_2000_components(self.target_Lab, Lab)[1]
        dv = dv @ dLab @ self.M  # (S, 3, 3 rgb)
        return np.einsum("sic,scj->sij", dv, D).reshape(-1, np.size(x))
