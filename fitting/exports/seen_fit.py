"""
Export values fitted to what the user sees
==========================================

Each export's free values fitted so that the tool's layered result
(:mod:`fitting.exports.tool_layering`) follows the physical coated metal seen
from air (:func:`fitting.colour.seen.seen_ACEScg`) over the view angles
:data:`fitting.colour.seen.SEEN_ANGLES_DEG` (0 to 83 degrees), perceptually:
the residuals are the Delta E 2000 at each angle (tool result in the
export's working space, back to linear ACEScg, against the target), minimised by scipy's
``least_squares`` (``trf``) inside the tool's limits (every colour in
[0, 1], a conductor's n in [0.001, 20] and k in [0, 50]).

The start is the issue's estimate: each channel's base fitted to the base
that would give the target exactly under the tool's layering (the floor's
base, :func:`floor_base`).

The least squares run on the three components of each angle's Delta E
(a vector whose length is the Delta E: the same sum of squares, smooth
where a Delta E is 0) with their Jacobian: exact through CIEDE2000, Lab and
the change of primaries, times the layering's derivative in each unknown
(:mod:`fitting.exports.seen_jacobian`). Gauss-Newton's model of the
components holds where that of the Delta E alone does not: the solves reach
their optimum in 5 to 40 evaluations, where forward differences on the
Delta E stopped at their cap of 100 (60) short of it.

-   :func:`fit_channel_conductor`, :func:`fit_channel_f82`,
    :func:`fit_channel_schlick`: per-channel least squares of a base
    Fresnel to a curve (also the naive fits under the coat;
    :mod:`fitting.exports.channel_fit`, re-exported).
-   :func:`layer_only`: the tool's layering over a free base response.
-   :func:`floor_base`, :func:`tool_floor`: the best base response per angle
    in [0, 1] and its Delta E (the tool's floor: a perfect base under its layering).
-   :func:`fit_tool_values`: the fit.
-   :func:`fit_view_dependent_index`: the conductor exports' n and k made
    affine in 1 - cos theta (twelve values), from the constant fit.
-   :func:`seen_delta_E`: Delta E 2000 per angle of an export's values.
"""

from __future__ import annotations

import numpy as np

from ..colour.delta_e import delta_E_map
from ..optics.fresnel import fresnel_dielectric
from .channel_fit import fit_channel_conductor, fit_channel_f82, fit_channel_schlick, least_squares
from .colour_space import DEFAULT_WORKING_SPACE, ACEScg_to_working, working_to_ACEScg
from .gltf_fallback import GLTF_COAT_FACTOR, mean_refined_base_colour
from .seen_jacobian import DeltaEComponents, delta_E_jacobian
from .tool_layering import K_BOUNDS, N_BOUNDS, TOOLS, materialx_layer, three_clearcoat, tool_seen

__all__ = [
    "N_BOUNDS",
    "K_BOUNDS",
    "fit_channel_conductor",
    "fit_channel_f82",
    "fit_channel_schlick",
    "gltf_clearcoat_factor",
    "layer_only",
    "floor_base",
    "tool_floor",
    "fit_tool_values",
    "fit_view_dependent_index",
    "seen_delta_E",
    "seen_fidelity",
]

VIEW_DEPENDENT_MAX_NFEV = 60  # a cap: the solves stop by their tolerances in about 25-40
_SLOPE_ZERO = 1e-6
MEAN_OBJECTIVE = False  # RMS: measured no better on the mean for W, CuZn, and a larger max


def layer_only(tool: str, mu, eta: float, base, coat: bool = True, clearcoat: float = 1.0) -> np.ndarray:
    """
    The tool's coat over a base whose response is ``base`` (S, 3), linear
    Rec.709 (OpenPBR's darkening taken at that base as its albedo).
    """
    base = np.asarray(base, dtype=np.float64)
    if not coat:
        return base
    if tool == "mtlx":
        return materialx_layer(mu, eta, base)
    if tool == "openpbr":
        K = 1.0 - (1.0 - ((eta - 1.0) / (eta + 1.0)) ** 2) / (eta * eta)
        return materialx_layer(mu, eta, base * (1.0 - K) / (1.0 - base * K))
    if tool in ("blender", "blender-conductor"):
        F = fresnel_dielectric(mu, 1.0, eta)[:, None]
        return F + (1.0 - F) * base
    if tool == "gltf":
        coat_a, scale = _gltf_layer_terms(mu, clearcoat)
        return coat_a + scale * base
    raise ValueError(f"`tool` must be one of {', '.join(TOOLS)}, got {tool!r}")


def _gltf_layer_terms(mu, clearcoat: float) -> tuple[np.ndarray, np.ndarray]:
    """three's coat over a base response r as ``c + s r`` (S, 3): (c, s)."""
    # three's layering is affine in the base: a + b base.
    a = three_clearcoat(mu, np.zeros(3), clearcoat)
    b = three_clearcoat(mu, np.ones(3), clearcoat) - a
    zero = three_clearcoat(mu, np.zeros(3), coat=False)
    one = three_clearcoat(mu, np.ones(3), coat=False)
    # Express through the base's own response r = zero + (one - zero) F0.
    coat_a = a - b * zero / np.maximum(one - zero, 1e-12)
    return coat_a, b / np.maximum(one - zero, 1e-12)


def floor_base(
    tool: str,
    mu,
    eta: float,
    target_ACEScg,
    coat: bool = True,
    clearcoat: float = 1.0,
    space: str = DEFAULT_WORKING_SPACE,
) -> np.ndarray:
    """
    The base response in [0, 1] per angle and channel of the working space
    ``space`` whose layered result is nearest the target (each channel's
    layering is increasing in its base: bisection, 50 halvings, to 1e-15).
    """
    target = ACEScg_to_working(target_ACEScg, space)
    lo, hi = np.zeros_like(target), np.ones_like(target)
    # glTF's layering is affine in the base: its two terms once, not four layerings per halving.
    affine = _gltf_layer_terms(mu, clearcoat) if tool == "gltf" and coat else None
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        layered = layer_only(tool, mu, eta, mid, coat, clearcoat) if affine is None else affine[0] + affine[1] * mid
        above = layered > target
        hi, lo = np.where(above, mid, hi), np.where(above, lo, mid)
    return 0.5 * (lo + hi)


def tool_floor(
    tool: str, mu, eta: float, target_ACEScg, coat: bool = True, space: str = DEFAULT_WORKING_SPACE
) -> np.ndarray:
    """
    Delta E 2000 per angle of :func:`floor_base` under the tool's layering
    (glTF's at the clear coat factor the export's fit starts from).
    """
    clearcoat = GLTF_COAT_FACTOR if tool == "gltf" and coat else 1.0
    base = floor_base(tool, mu, eta, target_ACEScg, coat, clearcoat, space)
    return delta_E_map(target_ACEScg, working_to_ACEScg(layer_only(tool, mu, eta, base, coat, clearcoat), space))


def seen_delta_E(
    tool: str, values: dict, mu, eta: float, target_ACEScg, space: str = DEFAULT_WORKING_SPACE
) -> np.ndarray:
    """
    Delta E 2000 per angle of the tool's result for ``values`` (colours and
    n, k per channel of the working space ``space``) against the target.
    """
    return delta_E_map(target_ACEScg, working_to_ACEScg(tool_seen(tool, values, mu, eta), space))


def gltf_clearcoat_factor(mu, eta: float) -> float:
    """
    three.js's ``clearcoat`` whose own reflection (F0 0.04, weighted by the
    factor) is nearest the physical coat's reflection at ``eta`` in least
    squares over ``mu``, in [0, 1] (1 for eta_i 1.33 to 2): the start of the
    glTF fit with the factor free (``keep_coat=False``: a comparison; the
    export writes the coat's own factor, 1).
    """
    mu = np.asarray(mu, dtype=np.float64)
    coat = three_clearcoat(mu, np.zeros(3), 1.0)[:, 0] - three_clearcoat(mu, np.zeros(3), coat=False)[:, 0]
    R01 = fresnel_dielectric(mu, 1.0, eta)
    return float(np.clip(np.dot(coat, R01) / np.dot(coat, coat), 0.0, 1.0))


def _pack(tool: str, x: np.ndarray, coat: bool, clearcoat: float = 1.0) -> dict:
    a, b = TOOLS[tool]
    values = {a: x[:3], "coat": coat}
    if tool == "gltf":
        values[b] = (float(x[3]) if x.size > 3 else clearcoat) if coat else 0.0
    else:
        values[b] = x[3:6]
    return values


def _start_and_bounds(tool: str, mu, base: np.ndarray, coat: bool):
    if tool in ("mtlx", "blender-conductor"):
        n, k = fit_channel_conductor(mu, base)
        return np.r_[n, k], [N_BOUNDS[0]] * 3 + [K_BOUNDS[0]] * 3, [N_BOUNDS[1]] * 3 + [K_BOUNDS[1]] * 3
    if tool in ("openpbr", "blender"):
        F0, tint = fit_channel_f82(mu, base)
        return np.r_[F0, tint], [0.0] * 6, [1.0] * 6
    # three's base response is F0 fab.x + fab.y plus its multiple scattering:
    # nearly affine in F0, so Schlick's closed form on the response is a start.
    F0 = fit_channel_schlick(mu, base)
    if coat:
        # clearcoatFactor free too, from the coat-reflection match.
        return np.r_[F0, 1.0], [0.0] * 4, [1.0] * 4
    return F0, [0.0] * 3, [1.0] * 3


def _residuals(
    tool: str, values: dict, mu, eta: float, target_ACEScg, space: str = DEFAULT_WORKING_SPACE
) -> np.ndarray:
    dE = seen_delta_E(tool, values, mu, eta, target_ACEScg, space)
    # sqrt: the sum of squares is then the sum of Delta E, so the fit
    # minimises the mean Delta E over the angles (what is scored), not
    # its RMS; the 1e-6 keeps the derivative finite where Delta E is 0.
    return np.sqrt(dE + 1e-6) if MEAN_OBJECTIVE else dE


def _solve(
    tool: str,
    pack,
    residuals,
    x0,
    lo,
    hi,
    mu,
    eta: float,
    target_ACEScg,
    max_nfev: int,
    space: str = DEFAULT_WORKING_SPACE,
):
    """
    scipy's bounded ``trf`` on the sum of squared Delta E from ``x0``
    (``x_scale="jac"``, xtol 1e-8, ftol 1e-6, gtol 1e-8), with exact
    Jacobians (:mod:`fitting.exports.seen_jacobian`): on the Delta E's
    components (:class:`~fitting.exports.seen_jacobian.DeltaEComponents`),
    else on ``residuals`` (``MEAN_OBJECTIVE``); the values are in the
    working space ``space``.
    """
    if MEAN_OBJECTIVE:
        fun, jac = residuals, (lambda x: delta_E_jacobian(tool, pack, x, lo, hi, mu, eta, target_ACEScg, True, space))
    else:
        problem = DeltaEComponents(tool, pack, lo, hi, mu, eta, target_ACEScg, space)
        fun, jac = problem.fun, problem.jac
    return least_squares(
        fun,
        x0,
        jac=jac,
        bounds=(lo, hi),
        method="trf",
        x_scale="jac",
        xtol=1e-8,
        ftol=1e-6,
        gtol=1e-8,
        max_nfev=max_nfev,
    )


def fit_view_dependent_index(
    tool: str, mu, eta: float, target_ACEScg, constant: dict, space: str = DEFAULT_WORKING_SPACE
) -> dict:
    """
    The conductor values of ``tool`` (``mtlx``, ``blender-conductor``) with
    each channel's n and k affine in the facing 1 - cos theta: ``ior``,
    ``ior_per_facing``, ``extinction``, ``extinction_per_facing`` (3,) each,
    and ``coat`` (:func:`fitting.exports.tool_layering.conductor_index`).
    Fitted by the objective of :func:`fit_tool_values` from ``constant``
    (its constant fit, slopes 0), as the values at facing 0 and 1, each in
    the bounds (so every angle's n, k is: linear in between), at most
    :data:`VIEW_DEPENDENT_MAX_NFEV` evaluations. Kept only where it lowers
    the objective; else ``constant`` with slopes 0.
    """
    mu = np.asarray(mu, dtype=np.float64)
    flat = {**constant, "ior_per_facing": np.zeros(3), "extinction_per_facing": np.zeros(3)}
    lo = np.r_[[N_BOUNDS[0]] * 6, [K_BOUNDS[0]] * 6]
    hi = np.r_[[N_BOUNDS[1]] * 6, [K_BOUNDS[1]] * 6]

    def slope(d):
        return np.where(np.abs(d) < _SLOPE_ZERO, 0.0, d)  # both ends on a bound: 0, not 1e-9

    def pack(x):
        return {
            "ior": x[0:3],
            "ior_per_facing": slope(x[3:6] - x[0:3]),
            "extinction": x[6:9],
            "extinction_per_facing": slope(x[9:12] - x[6:9]),
            "coat": constant["coat"],
        }

    def residuals(x):
        return _residuals(tool, pack(x), mu, eta, target_ACEScg, space)

    n, k = (np.asarray(constant[key], dtype=np.float64) for key in ("ior", "extinction"))
    x0 = np.clip(np.r_[n, n, k, k], lo + 1e-9, hi - 1e-9)
    fit = _solve(tool, pack, residuals, x0, lo, hi, mu, eta, target_ACEScg, VIEW_DEPENDENT_MAX_NFEV, space)
    if np.sum(residuals(fit.x) ** 2) < np.sum(_residuals(tool, flat, mu, eta, target_ACEScg, space) ** 2):
        return pack(np.asarray(fit.x, dtype=np.float64))
    return flat


def fit_tool_values(
    tool: str,
    mu,
    eta: float,
    target_ACEScg,
    coat: bool = True,
    view_dependent: bool = True,
    space: str = DEFAULT_WORKING_SPACE,
    roughness: float = 0.0,
    rough_target_ACEScg=None,
    keep_coat: bool = True,
) -> dict:
    """
    The export values of ``tool`` (keys :data:`fitting.exports.tool_layering.TOOLS`,
    and ``coat``) whose layered result is nearest the seen target
    (``target_ACEScg`` at view cosines ``mu``) in Delta E 2000. For the
    conductor tools (``mtlx``, ``blender-conductor``) with ``view_dependent``,
    the index affine in the facing (:func:`fit_view_dependent_index`) from
    the constant fit; without it the constant fit alone. Colours and n, k
    per channel are those of the working space ``space``
    (:data:`fitting.exports.colour_space.WORKING_SPACES`).

    glTF's fit with a metal ``roughness`` above 0 and its target there
    (``rough_target_ACEScg``, :func:`fitting.exports.gltf_fallback.rough_seen_ACEScg`)
    follows what three draws at that roughness (the material as the viewer
    shows it; started from the smooth fit's floor). With ``keep_coat`` its
    ``clearcoatFactor`` is the coat's,
    :data:`fitting.exports.gltf_fallback.GLTF_COAT_FACTOR` (1), and the base
    colour alone is fitted, by least squares then to the least mean Delta E
    over the angles (:func:`fitting.exports.gltf_fallback.mean_refined_base_colour`)
    (``False``: the factor fitted too, in [0, 1], by least squares alone, as
    the export once wrote it; for comparison).
    """
    if tool not in TOOLS:
        raise ValueError(f"`tool` must be one of {', '.join(TOOLS)}, got {tool!r}")
    mu = np.asarray(mu, dtype=np.float64)
    fixed = tool == "gltf" and coat and keep_coat
    clearcoat = GLTF_COAT_FACTOR if fixed else gltf_clearcoat_factor(mu, eta) if tool == "gltf" and coat else 1.0
    base = floor_base(tool, mu, eta, target_ACEScg, coat, clearcoat, space)
    x0, lo, hi = _start_and_bounds(tool, mu, base, coat)
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    if fixed:
        x0, lo, hi = np.asarray(x0)[:3], lo[:3], hi[:3]
    x0 = np.clip(x0, lo + 1e-9, hi - 1e-9)
    target, rough = np.asarray(target_ACEScg, dtype=np.float64), None
    if tool == "gltf" and roughness > 0.0 and rough_target_ACEScg is not None:
        target, rough = np.asarray(rough_target_ACEScg, dtype=np.float64), float(roughness)

    def pack(x):
        values = _pack(tool, x, coat, clearcoat)
        return values if rough is None else {**values, "roughness": rough}

    def residuals(x):
        return _residuals(tool, pack(x), mu, eta, target, space)

    fit = _solve(tool, pack, residuals, x0, lo, hi, mu, eta, target, 100, space)
    best = fit.x if fit.cost <= 0.5 * np.sum(residuals(x0) ** 2) else x0
    values = _pack(tool, np.asarray(best, dtype=np.float64), coat, clearcoat)
    if tool == "gltf" and keep_coat:
        # The export's base colour: the least squares' refined to the least mean Delta E (what is scored).
        values["base_color"] = mean_refined_base_colour(
            values["base_color"], mu, eta, target, rough or 0.0, clearcoat, coat, space
        )
    if view_dependent and tool in ("mtlx", "blender-conductor"):
        return fit_view_dependent_index(tool, mu, eta, target_ACEScg, values, space)
    return values


def seen_fidelity(values, tool: str) -> dict:
    """
    Delta E 2000 of an export's seen values (``values.tools[tool]``, an
    :class:`fitting.exports.values.ExportValues`) against the coated metal
    seen from air, over ``values.view_cos``: ``{"delta_E_mean", "delta_E_max"}``.
    """
    if tool not in values.tools:
        raise ValueError(f"`tool` must be one of the fitted {', '.join(values.tools)}, got {tool!r}")
    dE = seen_delta_E(tool, values.tools[tool], values.view_cos, values.eta_i, values.seen_ACEScg, values.working_space)
    return {"delta_E_mean": float(dE.mean()), "delta_E_max": float(dE.max())}
