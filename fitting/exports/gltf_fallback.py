"""
The glTF fallback on a rough metal, and the coat it keeps
=========================================================

A viewer without ``EXT_materials_coated_conductor`` draws the glTF export's
fallback: three.js's ``MeshPhysicalMaterial`` (metallic base of the
``baseColorFactor`` under its GGX at the material's ``roughnessFactor``,
``KHR_materials_clearcoat`` over it,
:func:`fitting.exports.tool_layering.three_clearcoat`). The glTF fit
(:func:`fitting.exports.seen_fit.fit_tool_values`) follows what the user sees
at roughness 0 **and** at the material's roughness, with a smooth coat:

-   :func:`rough_seen_ACEScg`: the coated metal seen from air at a metal
    roughness r under a smooth coat, for image-based light (a white sky):
    the seen target at roughness 0 (the spectral stack,
    :func:`fitting.colour.seen.seen_ACEScg`) plus the change that roughness
    makes to the light through the coat,
    :math:`S_r(\\mu) - S_0(\\mu)` of :func:`fitting.shading.coated_layer.seen_base`
    (the metal's GGX lobe at the in-coat cosine through the coat, with its
    bounces and total internal reflection), evaluated on the metal's own
    curve under the coat (the export's target, linear ACEScg, per channel).
    The coat's own reflection is the same at every metal roughness, so it
    cancels in the change. At r = 0 it is the seen target exactly. The
    change is taken at :data:`ROUGH_NODES` view cosines evenly spaced from
    the export's most grazing one to 1 and interpolated linearly in the
    cosine (measured against every angle's own: at most 0.12 Delta E 2000 on
    Cu, Ag, W at eta_i 1.33 and 2, roughness 0.3; a sixth of the time).
-   :data:`GLTF_COAT_FACTOR`: the ``clearcoatFactor`` the export writes
    wherever there is a coat (eta_i > 1): 1, the coat's weight, which
    ``EXT_materials_coated_conductor`` composes with (the coat's factor,
    roughness and index are glTF's, not the extension's). The fit is then of
    the base colour alone, and a coated metal reads as coated in a viewer
    without the plugin: its factor is above 0.5 wherever the physical coat's
    own reflectance at normal incidence, :func:`coat_F0`, is at least
    :data:`VISIBLE_COAT_F0` (2 %, eta_i >= 1.33), and everywhere else too.
-   :func:`gltf_seen_delta_E`: Delta E 2000 per angle of glTF values drawn
    by three at a metal roughness, against :func:`rough_seen_ACEScg`.
-   :func:`mean_refined_base_colour`: the base colour that minimises the
    **mean** Delta E over the view angles (what is scored), from the least
    squares' (which minimise their sum of squares): scipy's ``L-BFGS-B`` in
    [0, 1] with the exact gradient (:func:`fitting.exports.seen_jacobian.delta_E_jacobian`).
-   :func:`three_physical`: the whole of what three's ``MeshPhysicalMaterial``
    can draw of a flat surface under a uniform white sky, every glTF value
    that bears on it free: base colour, ``metallicFactor``, ``roughnessFactor``,
    ``KHR_materials_specular`` (factor, colour) with ``KHR_materials_ior``,
    ``KHR_materials_clearcoat`` (factor, roughness).
-   :func:`viewer_optimum`: the least mean Delta E :func:`three_physical`
    reaches against a target (several starts): what no glTF fallback drawn
    by three can beat, whatever it writes.
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab, ACEScg_to_Lab_and_jacobian
from ..colour.delta_e import delta_E_2000_gradient, delta_E_map
from ..shading.coated_layer import seen_base
from .colour_space import DEFAULT_WORKING_SPACE, working_to_ACEScg
from .seen_jacobian import delta_E_jacobian
from .tool_fresnel import schlick
from .tool_layering import THREE_CLEARCOAT_F0, THREE_MIN_ROUGHNESS, three_clearcoat, three_dfg

__all__ = [
    "ROUGH_NODES",
    "VISIBLE_COAT_F0",
    "GLTF_COAT_FACTOR",
    "VIEWER_VALUES",
    "coat_F0",
    "rough_seen_ACEScg",
    "gltf_seen_delta_E",
    "mean_refined_base_colour",
    "three_physical",
    "viewer_optimum",
]

VISIBLE_COAT_F0 = 0.02
"""The coat's own reflectance at normal incidence from which the coat is visible (eta_i about 1.33)."""
ROUGH_NODES = 16
"""View cosines at which :func:`rough_seen_ACEScg` evaluates the rough lobe."""
GLTF_COAT_FACTOR = 1.0
"""The ``clearcoatFactor`` of a coat: its weight, composed with the extension (not fitted)."""


def minimize(*args, **kwargs):
    """scipy's ``minimize``, imported on first use (as :func:`fitting.exports.channel_fit.least_squares`)."""
    from scipy.optimize import minimize as solve

    return solve(*args, **kwargs)


def coat_F0(eta: float) -> float:
    """The coat's own reflectance at normal incidence from air, ((eta - 1)/(eta + 1))^2."""
    return ((float(eta) - 1.0) / (float(eta) + 1.0)) ** 2


def _curve(cos_model, model_ACEScg):
    """The metal's curve under the coat as a Fresnel function of the in-coat cosine, (..., 3)."""
    mu = np.asarray(cos_model, dtype=np.float64)
    order = np.argsort(mu)
    mu, T = mu[order], np.asarray(model_ACEScg, dtype=np.float64)[order]

    def fresnel(c):
        c = np.asarray(c, dtype=np.float64)
        return np.stack([np.interp(c, mu, T[:, ch]) for ch in range(3)], axis=-1)

    return fresnel


def rough_seen_ACEScg(
    view_cos, eta: float, seen_ACEScg, cos_model, model_ACEScg, roughness: float, rough_nodes: int | None = ROUGH_NODES
) -> np.ndarray:
    """
    The coated metal seen from air at view cosines ``view_cos`` (S,) with a
    metal of perceptual ``roughness`` under a smooth coat of index ``eta``,
    linear ACEScg (S, 3): ``seen_ACEScg`` (the smooth stack at those
    cosines) plus :math:`S_r - S_0` of the metal's curve under the coat
    (``model_ACEScg`` at in-coat cosines ``cos_model``), at least 0;
    ``rough_nodes`` view cosines interpolated (``None``: at every one).
    """
    seen = np.asarray(seen_ACEScg, dtype=np.float64)
    if roughness <= 0.0 or eta <= 1.0:
        return seen
    view = np.asarray(view_cos, dtype=np.float64)
    fresnel = _curve(cos_model, model_ACEScg)
    nodes = view if rough_nodes is None else np.linspace(float(view.min()), 1.0, int(rough_nodes))
    change = seen_base(nodes, eta, float(roughness), fresnel) - seen_base(nodes, eta, 0.0, fresnel)
    if rough_nodes is not None:
        change = np.stack([np.interp(view, nodes, change[:, ch]) for ch in range(3)], axis=-1)
    return np.maximum(seen + change, 0.0)


def gltf_seen_delta_E(
    values: dict, view_cos, eta: float, target_ACEScg, roughness: float = 0.0, space: str = DEFAULT_WORKING_SPACE
) -> np.ndarray:
    """
    Delta E 2000 per angle of the glTF ``values`` (``base_color``,
    ``clearcoat``, ``coat``, in the working space ``space``) drawn by three
    at metal ``roughness`` with a smooth coat, against ``target_ACEScg``
    (:func:`rough_seen_ACEScg` at that roughness).
    """
    rgb = three_clearcoat(
        view_cos,
        values["base_color"],
        values.get("clearcoat", 1.0),
        bool(values.get("coat", eta > 1.0)),
        roughness=roughness,
    )
    return delta_E_map(target_ACEScg, working_to_ACEScg(rgb, space))


def mean_refined_base_colour(
    base_color,
    view_cos,
    eta: float,
    target_ACEScg,
    roughness: float = 0.0,
    clearcoat: float = GLTF_COAT_FACTOR,
    coat: bool = True,
    space: str = DEFAULT_WORKING_SPACE,
) -> np.ndarray:
    """
    The base colour in [0, 1] (working space ``space``) nearest the target
    in the mean Delta E 2000 over ``view_cos``, drawn by three at metal
    ``roughness`` under ``clearcoat``: scipy's ``L-BFGS-B`` from
    ``base_color`` (the least-squares fit) with the exact gradient; kept
    only where it lowers the mean.
    """
    view = np.asarray(view_cos, dtype=np.float64)
    target = np.asarray(target_ACEScg, dtype=np.float64)
    lo, hi = np.zeros(3), np.ones(3)
    x0 = np.clip(np.asarray(base_color, dtype=np.float64), lo, hi)

    def pack(x):
        return {"base_color": x, "clearcoat": clearcoat if coat else 0.0, "coat": coat, "roughness": roughness}

    def mean_and_gradient(x):
        values = pack(x)
        dE = gltf_seen_delta_E(values, view, eta, target, roughness, space)
        gradient = delta_E_jacobian("gltf", pack, x, lo, hi, view, eta, target, False, space).mean(axis=0)
        return float(dE.mean()), gradient

    start = mean_and_gradient(x0)[0]
    fit = minimize(
        mean_and_gradient,
        x0,
        jac=True,
        method="L-BFGS-B",
        bounds=list(zip(lo, hi)),
        options={"ftol": 1e-6, "gtol": 1e-5, "maxiter": 100},
    )
    return np.asarray(fit.x, dtype=np.float64) if fit.fun < start else x0


VIEWER_VALUES = {
    # name: (size, lower bound, upper bound)
    "base_color": (3, 0.0, 1.0),
    "metallic": (1, 0.0, 1.0),
    "specular_f0": (3, 0.0, 1.0),
    "specular": (1, 0.0, 1.0),
    "roughness": (1, 0.0, 1.0),
    "clearcoat": (1, 0.0, 1.0),
    "clearcoat_roughness": (1, 0.0, 1.0),
}
"""
The glTF values :func:`three_physical` takes, in order, with their ranges:
``baseColorFactor``; ``metallicFactor``; the dielectric F0 per channel,
``min(((ior - 1)/(ior + 1))^2 specularColorFactor, 1)`` (``KHR_materials_ior``
and ``KHR_materials_specular``, which reach every value in [0, 1]);
``specularFactor``; ``roughnessFactor``; ``clearcoatFactor``;
``clearcoatRoughnessFactor``.
"""


def _multiple_scattering(fab: np.ndarray, F0, F90) -> np.ndarray:
    """three's ``computeMultiscattering``: single plus multiple scattering, (S, 3)."""
    single = F0 * fab[:, :1] + F90 * fab[:, 1:]
    Ems = 1.0 - fab.sum(axis=1, keepdims=True)
    Favg = F0 + (1.0 - F0) * 0.047619
    return single + single * Favg / (1.0 - Ems * Favg) * Ems


def three_physical(
    view_cos,
    base_color,
    metallic=1.0,
    specular_f0=(0.04, 0.04, 0.04),
    specular=1.0,
    roughness=0.0,
    clearcoat=1.0,
    clearcoat_roughness=0.0,
) -> np.ndarray:
    """
    three.js r187's ``MeshPhysicalMaterial`` under a uniform white sky of
    radiance 1, a flat surface (:data:`VIEWER_VALUES`), linear Rec.709
    (S, 3): the dielectric part (F0 ``specular_f0`` times ``specular``;
    Lambert of the base colour under what its specular leaves) and the
    metallic part (F0 ``base_color``), both at F90 ``mix(specular, 1,
    metallic)`` with their multiple scattering, mixed by ``metallic``
    (``RE_IndirectSpecular_Physical``), under the clear coat
    (``outgoingLight (1 - c Fcc) + c coat``). Each value one number (a colour
    (3,)) or one per view angle ((S,), a colour (S, 3)). At ``metallic`` 1
    it is :func:`fitting.exports.tool_layering.three_clearcoat`.
    """
    mu = np.clip(np.asarray(view_cos, dtype=np.float64), 0.0, 1.0)

    def column(v):
        v = np.asarray(v, dtype=np.float64)
        return v[:, None] if v.ndim == 1 else v

    colour, f0 = np.asarray(base_color, dtype=np.float64), np.asarray(specular_f0, dtype=np.float64)
    m, si, cc = column(metallic), column(specular), column(clearcoat)
    fab = three_dfg(mu, np.maximum(roughness, THREE_MIN_ROUGHNESS))
    F90 = m + (1.0 - m) * si
    dielectric = _multiple_scattering(fab, f0 * si, F90)
    metal = _multiple_scattering(fab, colour, F90)
    base = m * metal + (1.0 - m) * (dielectric + colour * (1.0 - dielectric))
    fcc = three_dfg(mu, np.maximum(clearcoat_roughness, THREE_MIN_ROUGHNESS))
    Fcc = schlick(mu, THREE_CLEARCOAT_F0)[:, None]
    return base * (1.0 - cc * Fcc) + cc * (THREE_CLEARCOAT_F0 * fcc[:, :1] + fcc[:, 1:])


def _viewer_values(x: np.ndarray) -> dict:
    out, i = {}, 0
    for name, (size, _, _) in VIEWER_VALUES.items():
        out[name] = x[i : i + size].copy() if size == 3 else float(x[i])
        i += size
    return out


def _viewer_mean_and_gradient(x: np.ndarray, view: np.ndarray, target_Lab: np.ndarray, M: np.ndarray):
    """The mean Delta E of :func:`three_physical` at ``x`` and its gradient: exact through Delta E and Lab,
    central differences (step 1e-5, one-sided at a bound) of the layering, every value in one call."""
    n, S = x.size, view.size
    h = 1e-5
    points = [x]
    for j in range(n):
        up, down = x.copy(), x.copy()
        up[j], down[j] = min(x[j] + h, 1.0), max(x[j] - h, 0.0)
        points += [up, down]
    P = len(points)
    values = [_viewer_values(p) for p in points]
    rows = {name: np.repeat(np.stack([value[name] for value in values]), S, axis=0) for name in VIEWER_VALUES}
    rgb = three_physical(np.tile(view, P), **rows).reshape(P, S, 3)
    steps = np.array([points[1 + 2 * j][j] - points[2 + 2 * j][j] for j in range(n)])
    D = (rgb[1::2] - rgb[2::2]) / steps[:, None, None]  # (n, S, 3)
    Lab, dLab = ACEScg_to_Lab_and_jacobian(rgb[0] @ M.T)
    dE, grad = delta_E_2000_gradient(target_Lab, Lab)
    g_rgb = np.einsum("si,sij->sj", grad, dLab) @ M
    return float(dE.mean()), np.einsum("sc,nsc->n", g_rgb, D) / S


def viewer_optimum(
    view_cos,
    target_ACEScg,
    base_color,
    roughness: float,
    space: str = DEFAULT_WORKING_SPACE,
    starts: int = 4,
    fixed: dict | None = None,
    also_from: tuple = (),
) -> tuple[dict, np.ndarray]:
    """
    The values of :func:`three_physical` (each of :data:`VIEWER_VALUES`
    free in its range, but those in ``fixed``: name -> (lower, upper)
    bounds, one number each) with the least mean Delta E 2000 against
    ``target_ACEScg`` over ``view_cos``, and that Delta E per angle: scipy's
    ``L-BFGS-B`` from ``starts`` points: the metallic fallback
    (``base_color`` at ``roughness``, coat whole), a dielectric of that
    colour, a blend, then points drawn from a fixed seed; and from each
    values dict of ``also_from`` (another optimum's, say).
    """
    view = np.asarray(view_cos, dtype=np.float64)
    target_Lab = ACEScg_to_Lab(np.asarray(target_ACEScg, dtype=np.float64))
    M = working_to_ACEScg(np.eye(3), space).T
    fixed = fixed or {}
    bounds = [fixed.get(name, (lo, hi)) for name, (size, lo, hi) in VIEWER_VALUES.items() for _ in range(size)]
    lo, hi = np.array(bounds).T
    colour = np.clip(np.asarray(base_color, dtype=np.float64), 0.0, 1.0)
    rng = np.random.default_rng(0)
    firsts = [
        np.r_[colour, 1.0, 0.04, 0.04, 0.04, 1.0, roughness, 1.0, 0.0],
        np.r_[0.1 * colour, 0.0, colour, 1.0, roughness, 1.0, 0.0],
        np.r_[colour, 0.5, colour, 0.8, roughness, 0.75, 0.0],
    ]
    chosen = [firsts[k] if k < len(firsts) else rng.uniform(0.0, 1.0, lo.size) for k in range(max(int(starts), 1))]
    chosen += [np.concatenate([np.atleast_1d(values[name]) for name in VIEWER_VALUES]) for values in also_from]
    fits = [
        minimize(
            _viewer_mean_and_gradient,
            np.clip(x0, lo, hi),
            args=(view, target_Lab, M),
            jac=True,
            method="L-BFGS-B",
            bounds=bounds,
            options={"ftol": 1e-8, "gtol": 1e-6, "maxiter": 300},
        )
        for x0 in chosen
    ]
    best = min(fits, key=lambda fit: fit.fun)
    values = _viewer_values(np.clip(best.x, lo, hi))
    rgb = three_physical(view, **values)
    return values, delta_E_map(target_ACEScg, working_to_ACEScg(rgb, space))
