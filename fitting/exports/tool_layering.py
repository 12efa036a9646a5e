"""
How each tool layers its coat over its base
===========================================

numpy mirrors of what each target tool renders for a smooth coated metal
(roughness 0) under a uniform white environment of radiance 1, at
:math:`\\mu = \\cos\\theta` of the **view direction in air**: none of them
refracts the view into the coat; each evaluates its base at the view angle
and scales it by what its coat lets through. Values and results are linear
Rec.709 (the tools' working space), shape (S, 3).

-   :func:`mx_ggx_dir_albedo`: MaterialX's analytic GGX directional albedo
    terms (A, B) (``mx_ggx_dir_albedo_analytic``), which its ``dielectric_bsdf``
    uses for the coat's throughput and every BSDF for energy compensation.
-   :func:`materialx_layer`: ``layer`` of a ``dielectric_bsdf`` coat
    (``scatter_mode`` R) over a base response, as MaterialX's GLSL generator
    implements it for environment light: coat ``F_d(mu) c_d`` plus base times
    ``1 - (F0 A + B) c_d``, with ``c`` the energy compensation
    ``1 + F (1 - E_ss) / E_ss``.
-   :func:`mtlx_conductor`: ``conductor_bsdf`` (exact Fresnel in air) under it.
-   :func:`openpbr_metal`: ``open_pbr_surface``, metallic base (F82 tint),
    coat of ``coat_ior`` with ``coat_darkening`` (the base scaled by
    :math:`(1 - K)/(1 - E K)`, :math:`K = 1 - (1 - F_0)/\\eta^2`,
    E the base colour), as its MaterialX node graph builds it.
-   :func:`cycles_principled`: Blender Cycles' Principled BSDF, metallic
    (F82 tint), with its coat: base scaled by 1 minus the coat's albedo,
    at roughness 0 the exact dielectric Fresnel.
-   :func:`cycles_conductor_mix`: the Blender export's second output: a
    Metallic BSDF (Physical Conductor) and a white Glossy BSDF mixed by a
    Fresnel node of the coat index.
-   :func:`three_clearcoat`: three.js ``MeshPhysicalMaterial``, metalness 1,
    with ``clearcoat`` (F0 0.04, Schlick; the DFG table three ships,
    ``DFGLUTData.js``, at three's least roughness 0.045, and its
    multiple-scattering term), as glTF's ``KHR_materials_clearcoat`` renders.
-   :data:`TOOLS`: the tools and what each mirror takes.
-   :func:`view_dependent`, :func:`conductor_index`: whether a conductor
    export's index varies with the view angle, and its n and k at each view
    angle: per channel ``ior + ior_per_facing (1 - mu)`` (likewise
    ``extinction``), at least the lower bound of :data:`N_BOUNDS` /
    :data:`K_BOUNDS`, as the exports' node graphs compute them (constant
    where the ``*_per_facing`` slopes are absent or 0).

``coat=False`` (an export at eta_i 1, which has no coat) gives each tool's
bare base.

References
----------
MaterialX 1.39 ``pbrlib/genglsl`` (``mx_dielectric_bsdf.glsl``,
``mx_layer_bsdf.glsl``, ``mx_microfacet_specular.glsl``); ``bxdf/open_pbr_surface.mtlx``.
Turquin, E. (2019). Practical multiple scattering compensation for microfacet models.
Fdez-Agüera, C. J. (2019). A Multiple-Scattering Microfacet Model for
Real-Time Image-based Lighting. JCGT 8(1).
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

import numpy as np

from ..optics.fresnel import fresnel_dielectric
from .tool_fresnel import f82_tint, mx_fresnel_conductor, schlick

__all__ = [
    "TOOLS",
    "N_BOUNDS",
    "K_BOUNDS",
    "view_dependent",
    "conductor_index",
    "THREE_MIN_ROUGHNESS",
    "THREE_CLEARCOAT_F0",
    "mx_ggx_dir_albedo",
    "materialx_layer",
    "mtlx_conductor",
    "openpbr_metal",
    "cycles_principled",
    "cycles_conductor_mix",
    "three_dfg",
    "three_clearcoat",
    "tool_seen",
]

_MX_EPS = 1e-8  # MaterialX's M_FLOAT_EPS: the least alpha and NdotV
THREE_MIN_ROUGHNESS = 0.045
"""three.js raises every roughness to this (``lights_physical_fragment``)."""
THREE_CLEARCOAT_F0 = 0.04
"""three.js's clear coat F0 (index 1.5), fixed."""

_DFG_PATH = (
    Path(__file__).resolve().parents[2]
    / "scripts"
    / "three"
    / "node_modules"
    / "three"
    / "src"
    / "renderers"
    / "shaders"
    / "DFGLUTData.js"
)

TOOLS = {
    "mtlx": ("ior", "extinction"),
    "blender-conductor": ("ior", "extinction"),
    "openpbr": ("base_color", "specular_color"),
    "blender": ("base_color", "specular_tint"),
    "gltf": ("base_color", "clearcoat"),
}
"""Tool -> the free values its export fits (linear Rec.709)."""

# Per-channel relative index bounds: n > 0 as for any conductor; above every
# library conductor divided by eta_i >= 1 (n < 5, k < 12 in 360-830 nm).
N_BOUNDS = (1.0e-3, 20.0)
K_BOUNDS = (0.0, 50.0)


def _mu(cos_theta) -> np.ndarray:
    return np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)


def _per_angles(fn):
    """
    ``fn``'s arrays kept (read-only) for the values of its arguments (an
    array by its bytes): the terms that depend on the view cosines and the
    coat alone, the same on every evaluation of a fit. The last 64 kept.
    """
    cache: dict = {}

    @functools.wraps(fn)
    def kept(*args):
        key = tuple((a.shape, a.tobytes()) if isinstance(a, np.ndarray) else a for a in args)
        hit = cache.get(key)
        if hit is None:
            hit = fn(*args)
            for array in hit:
                array.setflags(write=False)
            if len(cache) >= 64:
                cache.pop(next(iter(cache)))
            cache[key] = hit
        return hit

    return kept


def _key(x) -> np.ndarray | float:
    """A number as a float, an array as float64: one cache key per value."""
    x = np.asarray(x, dtype=np.float64)
    return x if x.ndim else float(x)


def mx_ggx_dir_albedo(cos_theta, alpha: float = _MX_EPS) -> tuple[np.ndarray, np.ndarray]:
    """
    (A, B) of ``mx_ggx_dir_albedo_analytic`` (directional albedo F0 A + F90 B),
    shape (S,), with MaterialX's clamps (NdotV and alpha at least 1e-8).
    """
    return _mx_albedo(np.clip(_mu(cos_theta), _MX_EPS, 1.0), max(float(alpha), _MX_EPS))


@_per_angles
def _mx_albedo(x: np.ndarray, y: float) -> tuple[np.ndarray, np.ndarray]:
    x2, y2 = x * x, y * y
    c = np.array(
        [
            [0.1003, 0.9345, 1.0, 1.0],
            [-0.6303, -2.323, -1.765, 0.2281],
            [9.748, 2.229, 8.263, 15.94],
            [-2.038, -3.748, 11.53, -55.83],
            [29.34, 1.424, 28.96, 13.08],
            [-8.245, -0.7684, -7.507, 41.26],
            [-26.44, 1.436, -36.11, 54.9],
            [19.99, 0.2913, 15.86, 300.2],
            [-5.448, 0.6286, 33.37, -285.1],
        ]
    )
    terms = np.stack(
        [np.ones_like(x), x, np.full_like(x, y), x * y, x2, np.full_like(x, y2), x2 * y, x * y2, x2 * y2], axis=-1
    )
    r = terms @ c
    AB = np.clip(r[:, :2] / r[:, 2:], 0.0, 1.0)
    return AB[:, 0], AB[:, 1]


def _mx_comp(F: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    Ess = (A + B)[:, None] if F.ndim == 2 else A + B
    return 1.0 + F * (1.0 - Ess) / Ess


def materialx_layer(cos_theta, eta: float, base: np.ndarray, coat: bool = True) -> np.ndarray:
    """
    MaterialX ``layer(top=dielectric_bsdf(ior=eta, R), base)`` for environment
    light at roughness 0: ``base`` is the base's response (S, 3).
    """
    base = np.asarray(base, dtype=np.float64)
    if not coat:
        return base
    reflected, throughput = _mx_layer_terms(np.clip(_mu(cos_theta), _MX_EPS, 1.0), float(eta))
    return reflected[:, None] + throughput[:, None] * base


@_per_angles
def _mx_layer_terms(mu: np.ndarray, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`materialx_layer`'s coat reflection and throughput (S,): its result is affine in the base."""
    A, B = mx_ggx_dir_albedo(mu)
    F = fresnel_dielectric(mu, 1.0, eta)
    comp = _mx_comp(F, A, B)
    F0 = ((eta - 1.0) / (eta + 1.0)) ** 2
    throughput = 1.0 - (F0 * A + B) * comp
    return F * comp, throughput


def mtlx_conductor(cos_theta, eta: float, ior, extinction, coat: bool = True) -> np.ndarray:
    """The ``mtlx`` export: ``conductor_bsdf(ior, extinction)`` under :func:`materialx_layer`."""
    mu = np.clip(_mu(cos_theta), _MX_EPS, 1.0)
    A, B = mx_ggx_dir_albedo(mu)
    F = mx_fresnel_conductor(mu, ior, extinction)
    return materialx_layer(mu, eta, F * _mx_comp(F, A, B), coat)


def openpbr_metal(
    cos_theta, eta: float, base_color, specular_color, coat: bool = True, coat_darkening: float = 1.0
) -> np.ndarray:
    """The ``openpbr`` export: metallic ``open_pbr_surface``, roughness 0, coat ``eta``."""
    mu = np.clip(_mu(cos_theta), _MX_EPS, 1.0)
    base_color = np.asarray(base_color, dtype=np.float64)
    A, B = mx_ggx_dir_albedo(mu)
    F = f82_tint(mu, base_color, specular_color)
    metal = F * _mx_comp(F, A, B)
    if not coat:
        return metal
    K = 1.0 - (1.0 - ((eta - 1.0) / (eta + 1.0)) ** 2) / (eta * eta)
    darkening = (1.0 - K) / (1.0 - base_color * K)
    metal = metal * (1.0 + coat_darkening * (darkening - 1.0))
    return materialx_layer(mu, eta, metal, coat)


def _cycles_coat(mu, eta: float, metal, coat: bool) -> np.ndarray:
    """Cycles' coat over ``metal`` at roughness 0 (both Blender outputs): a white mirror mixed in by the coat's exact Fresnel."""
    if not coat:
        return metal
    F = _coat_fresnel(mu, float(eta))[0][:, None]
    return F + (1.0 - F) * metal


@_per_angles
def _coat_fresnel(mu: np.ndarray, eta: float) -> tuple[np.ndarray]:
    return (fresnel_dielectric(mu, 1.0, eta),)


def cycles_principled(cos_theta, eta: float, base_color, specular_tint, coat: bool = True) -> np.ndarray:
    """The ``blender`` export's Principled BSDF (Metallic 1, F82 tint), roughness 0."""
    mu = _mu(cos_theta)
    return _cycles_coat(mu, eta, f82_tint(mu, base_color, specular_tint), coat)


def cycles_conductor_mix(cos_theta, eta: float, ior, extinction, coat: bool = True) -> np.ndarray:
    """The ``blender`` export's second output: Mix(Fresnel(eta); Metallic, white Glossy)."""
    mu = _mu(cos_theta)
    return _cycles_coat(mu, eta, mx_fresnel_conductor(mu, ior, extinction), coat)


@functools.cache
def _dfg_table() -> np.ndarray:
    if not _DFG_PATH.exists():
        raise FileNotFoundError(f"three.js is not installed ({_DFG_PATH}): run scripts/bootstrap")
    text = _DFG_PATH.read_text()
    body = text[text.index("Uint16Array") : text.index("] )")]
    halves = np.array([int(h, 16) for h in re.findall(r"0x([0-9a-fA-F]{4})", body)], dtype=np.uint16)
    table = halves.view(np.float16).astype(np.float64).reshape(16, 16, 2)  # [dotNV, roughness, (scale, bias)]
    table.setflags(write=False)
    return table


def three_dfg(cos_theta, roughness) -> np.ndarray:
    """
    three's ``texture2D(dfgLUT, vec2(roughness, dotNV)).rg``: bilinear, clamped
    to edge, (S, 2); ``roughness`` one number or one per view angle (S,).
    """
    return _three_dfg(_mu(cos_theta), _key(roughness))[0]


@_per_angles
def _three_dfg(mu: np.ndarray, roughness) -> tuple[np.ndarray]:
    table = _dfg_table()
    size = table.shape[0]

    def axis(t):
        p = np.clip(np.asarray(t, dtype=np.float64) * size - 0.5, 0.0, size - 1.0)
        i0 = np.minimum(np.floor(p).astype(int), size - 2)
        return i0, p - i0

    v0, fv = axis(mu)
    u0, fu = axis(np.broadcast_to(np.asarray(roughness, dtype=np.float64), fv.shape))
    t00, t01 = table[v0, u0], table[v0, u0 + 1]
    t10, t11 = table[v0 + 1, u0], table[v0 + 1, u0 + 1]
    fu, fv = fu[:, None], fv[:, None]
    return ((t00 * (1 - fu) + t01 * fu) * (1 - fv) + (t10 * (1 - fu) + t11 * fu) * fv,)


def three_clearcoat(
    cos_theta, base_color, clearcoat: float = 1.0, coat: bool = True, roughness=0.0, clearcoat_roughness: float = 0.0
) -> np.ndarray:
    """
    The glTF export in three.js: ``MeshPhysicalMaterial`` with metalness 1 and
    ``color`` ``base_color``, environment light only, flat geometry (three adds
    the screen-space change of the normal to every roughness; 0 on a plane).
    ``clearcoat`` and the metal's ``roughness`` are one number each, or one
    per view angle (S,).
    """
    mu = _mu(cos_theta)
    F0 = np.asarray(base_color, dtype=np.float64)
    fab = three_dfg(mu, np.maximum(roughness, THREE_MIN_ROUGHNESS))
    FssEss = F0 * fab[:, :1] + fab[:, 1:]
    Ems = 1.0 - fab.sum(axis=1, keepdims=True)
    Favg = F0 + (1.0 - F0) * 0.047619
    base = FssEss + FssEss * Favg / (1.0 - Ems * Favg) * Ems
    if not coat:
        return base
    cc = np.clip(np.asarray(clearcoat, dtype=np.float64), 0.0, 1.0)
    if cc.ndim:
        cc = cc[:, None]  # a factor per view angle, (S,): one per row
    Fcc, coat_specular = _three_coat_terms(mu, _key(max(clearcoat_roughness, THREE_MIN_ROUGHNESS)))
    return base * (1.0 - cc * Fcc) + cc * coat_specular


@_per_angles
def _three_coat_terms(mu: np.ndarray, clearcoat_roughness: float) -> tuple[np.ndarray, np.ndarray]:
    """three's clear coat: its Schlick Fresnel (S, 1) and its specular (S, 1)."""
    fcc = three_dfg(mu, clearcoat_roughness)
    return schlick(mu, THREE_CLEARCOAT_F0)[:, None], THREE_CLEARCOAT_F0 * fcc[:, :1] + fcc[:, 1:]


def view_dependent(values: dict) -> bool:
    """Whether a conductor export's ``values`` carry a non-zero ``ior_per_facing`` or ``extinction_per_facing``."""
    return any(np.any(values.get(key, 0.0)) for key in ("ior_per_facing", "extinction_per_facing"))


def conductor_index(values: dict, cos_theta) -> tuple[np.ndarray, np.ndarray]:
    """
    The conductor's (n, k) for ``values`` (``ior``, ``extinction`` and,
    optionally, ``ior_per_facing``, ``extinction_per_facing``, per channel)
    at view cosines ``cos_theta``: ``max(ior + ior_per_facing (1 - mu), N_BOUNDS[0])``
    and likewise k, (S, 3) each, as the exports' graphs compute them
    (MaterialX: 1 + N.V clamped to [0, 1]; Blender: Layer Weight's Facing at
    blend 0.5); the constants alone, (3,), without slopes.
    """
    n, k = (np.asarray(values[key], dtype=np.float64) for key in ("ior", "extinction"))
    if not view_dependent(values):
        return n, k
    n_slope, k_slope = (
        np.asarray(values.get(key, 0.0), dtype=np.float64) for key in ("ior_per_facing", "extinction_per_facing")
    )
    facing = (1.0 - _mu(cos_theta))[..., None]
    return np.maximum(n + n_slope * facing, N_BOUNDS[0]), np.maximum(k + k_slope * facing, K_BOUNDS[0])


def tool_seen(tool: str, values: dict, cos_theta, eta: float) -> np.ndarray:
    """
    The mirror of ``tool`` (a key of :data:`TOOLS`) for an export's ``values``
    (the keys :data:`TOOLS` names, and ``coat``: whether the export has one)
    at view cosines ``cos_theta``, (S, 3) linear Rec.709; glTF's may carry
    the metal's ``roughness`` (one number or one per view angle; else 0).
    """
    coat = bool(values.get("coat", eta > 1.0))
    if tool == "mtlx":
        return mtlx_conductor(cos_theta, eta, *conductor_index(values, cos_theta), coat)
    if tool == "blender-conductor":
        return cycles_conductor_mix(cos_theta, eta, *conductor_index(values, cos_theta), coat)
    if tool == "openpbr":
        return openpbr_metal(
            cos_theta, eta, values["base_color"], values["specular_color"], coat, values.get("coat_darkening", 1.0)
        )
    if tool == "blender":
        return cycles_principled(cos_theta, eta, values["base_color"], values["specular_tint"], coat)
    if tool == "gltf":
        return three_clearcoat(
            cos_theta, values["base_color"], values.get("clearcoat", 1.0), coat, values.get("roughness", 0.0)
        )
    raise ValueError(f"`tool` must be one of {', '.join(TOOLS)}, got {tool!r}")
