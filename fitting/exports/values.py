"""
Export values
=============

The numbers an export carries, for one coating index eta_i, fitted in the
export's working space (:data:`fitting.exports.colour_space.WORKING_SPACES`:
by default linear Rec.709 primaries, D65 white, the default ``lin_rec709`` of
MaterialX, Blender's scene linear, glTF's linear sRGB; or linear ACEScg) to
the reflectance of the metal under the coat.

Each export carries the values fitted to what the user sees
(:mod:`fitting.exports.seen_fit`): the physical coat on the metal seen from
air (:func:`fitting.colour.seen.seen_ACEScg`) at the view angles 0 to 83
degrees, against the tool's own layering of its coat over its base
(:mod:`fitting.exports.tool_layering`), in Delta E 2000; they are
:attr:`ExportValues.tools`. The rest of this docstring is the earlier,
naive fit, kept as the baseline the seen fit is measured against (today's
values before the seen fit): the base's Fresnel fitted to the metal under the
coat at the same angle inside the coat.

The naive target curve :math:`T(\\mu)` is the spectral reference under the coat
(:func:`fitting.colour.reference.reference_ACEScg` at eta_i, 1 nm, linear ACEScg)
converted to the working space (linear Rec.709 with CAT02 adaptation: a
perfect reflector stays (1, 1, 1)), at :data:`EXPORT_SAMPLES` values of :math:`\\mu = \\cos\\theta`
in the coating, evenly over [0, 1]. For a material given only as per-channel
n, k (an ``rgb-conductor`` fit, linear ACEScg) the target is that model's
curve at eta_i, and for a fit made from edited curves the fit's own model
curve. Each value is a per-channel least-squares fit to T:

-   relative index :math:`(n_c + i k_c)` of an exact conductor in air
    (MaterialX ``conductor_bsdf``, Blender Metallic BSDF "Physical
    Conductor"): :math:`\\min \\sum_s (F(\\mu_s; n_c + i k_c) - T_c(\\mu_s))^2`;
-   F0 and F82 tint of the F82-tint model (OpenPBR ``base_color`` and
    ``specular_color``, Blender Principled ``Base Color`` and ``Specular
    Tint``), both in [0, 1];
-   F0 of Schlick's approximation (glTF ``baseColorFactor``), closed form.

-   :data:`EXPORT_SAMPLES`, :data:`ETA_I_LIMITS`
-   :class:`ExportValues`: the fitted values and their provenance.
-   :func:`export_values`: computes them (the seen target, the target under
    the coat and its naive fits computed once per measured n, k, coating
    index and working space, and kept: :data:`TARGET_CACHE_SIZE`).
-   :func:`project_version`.

References
----------
Hoffman, N. (2023). Generalization of Adobe's Fresnel Model (F82 tint).
Kutz, P., Hasan, M., & Edmondson, P. (2021). Novel aspects of the Adobe
Standard Material.
Andersson, A. et al. (2024). OpenPBR Surface Specification, metal base.
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..colour.reference import reference_ACEScg
from ..colour.seen import SEEN_ANGLES_DEG, seen_ACEScg
from ..domain import ETA_I_MAX, ETA_I_MIN, BoundedCache, check_eta_i, check_number
from ..models.pack import PackedMaterial
from ..models.rgb_conductor import rgb_fresnel_conductor
from ..optics.coated_stack import coated_stack, coated_stack_from_metal
from ..optics.nk import SpectralNK
from .colour_space import DEFAULT_WORKING_SPACE, ACEScg_to_working, check_working_space
from .naming import check_fit_id, identity
from .gltf_fallback import rough_seen_ACEScg
from .seen_fit import fit_channel_conductor, fit_channel_f82, fit_channel_schlick, fit_tool_values
from .tool_layering import TOOLS

__all__ = [
    "EXPORT_SAMPLES",
    "ETA_I_LIMITS",
    "ExportValues",
    "export_values",
    "project_version",
    "check_roughness",
    "has_coat",
]

EXPORT_SAMPLES = 100
"""Values of cos theta in the coating, evenly over [0, 1], fitted and scored."""

ETA_I_LIMITS = (ETA_I_MIN, ETA_I_MAX)
"""Accepted coating indices (the project's rule, :func:`fitting.domain.check_eta_i`)."""

TARGET_CACHE_SIZE = 64
"""How many targets of measured n, k are kept (per process): each format of a material at one
coating index fits its own tools to the same seen target, computed once (about 0.1 MB each)."""

_TARGETS = BoundedCache(TARGET_CACHE_SIZE)


def _kept(key, build) -> tuple:
    """``build()``'s arrays read-only, kept by ``key`` (``None``: not kept)."""

    def frozen():
        out = tuple(np.asarray(a, dtype=np.float64) for a in build())
        for a in out:
            a.setflags(write=False)
        return out

    return frozen() if key is None else _TARGETS.get(key, frozen)


def _nk_key(nk: SpectralNK) -> str:
    """A digest of measured n, k (what their targets depend on)."""
    digest = hashlib.blake2b(digest_size=16)
    for a in (nk.wavelength_nm, nk.n, nk.k):
        digest.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
    return digest.hexdigest()


@functools.cache
def project_version() -> str:
    """This project's version: the installed ``coated-fresnel``, else pyproject.toml's."""
    # Imported here: importlib.metadata (with email and zipfile) costs ~20 ms of every start.
    import importlib.metadata
    import tomllib

    try:
        return importlib.metadata.version("coated-fresnel")
    except importlib.metadata.PackageNotFoundError:
        pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
        try:
            return str(tomllib.loads(pyproject.read_text())["project"]["version"])
        except (OSError, KeyError, tomllib.TOMLDecodeError):
            return "unknown"


def check_roughness(name: str, value) -> float:
    """A perceptual roughness in [0, 1], else ``ValueError`` naming ``name``."""
    return check_number(name, value, 0.0, 1.0)


@dataclass(frozen=True)
class ExportValues:
    """
    What an export is made of, all colours (and per-channel n, k) in the
    working space ``working_space``.

    Attributes
    ----------
    name, source
        Material name and the citation of its data.
    eta_i
        Coating index the values are for.
    origin
        How the target curve was obtained (spectral reference or model curve).
    cos_theta
        The :data:`EXPORT_SAMPLES` values of mu in the coating.
    target
        T(mu), shape (EXPORT_SAMPLES, 3), in the working space.
    target_ACEScg
        The same in linear ACEScg (what the fidelity is scored against).
    n_rel, k_rel
        Per-channel relative index (n + i k) / eta_i, shape (3,).
    F0, F82_tint
        F82-tint model values, shape (3,) each, in [0, 1].
    F0_schlick
        Schlick F0, shape (3,), in [0, 1].
    roughness, coat_roughness
        Perceptual roughness of the metal and of the coat, [0, 1].
    view_cos, seen_ACEScg
        cos theta of the view angles in air (:data:`fitting.colour.seen.SEEN_ANGLES_DEG`)
        and the coated metal seen from air there, linear ACEScg (S, 3).
    seen_rough_ACEScg
        The same with the metal at ``roughness`` under a smooth coat
        (:func:`fitting.exports.gltf_fallback.rough_seen_ACEScg`), what the
        glTF fallback is fitted to; ``None`` where the glTF values are fitted
        at roughness 0 (no glTF, no coat or a smooth metal).
    tools
        Per tool (:data:`fitting.exports.tool_layering.TOOLS`) the values its
        export carries, fitted to ``seen_ACEScg`` under the tool's layering,
        and ``coat`` (False at eta_i 1); the conductor tools' also
        ``ior_per_facing`` and ``extinction_per_facing``, slopes in 1 - cos
        theta (:func:`fitting.exports.tool_layering.conductor_index`; 0 where
        the constant index fits as well). ``n_rel`` ... ``F0_schlick`` above
        are the naive fits under the coat (the baseline).
    model
        The fit's own float16 model (:class:`fitting.models.pack.PackedMaterial`),
        when the export carries it as well as the tool's values (glTF's
        ``EXT_materials_coated_conductor``); ``None`` otherwise.
    fit_id
        The stored fit's id (32 hex digits) when the export is of one;
        ``None`` otherwise (the export then carries a content address,
        :func:`fitting.exports.naming.export_id`).
    working_space
        ``lin_rec709`` or ``acescg``: the space every colour and per-channel
        n, k here is fitted and written in.
    """

    name: str
    source: str
    eta_i: float
    origin: str
    cos_theta: np.ndarray
    target: np.ndarray
    target_ACEScg: np.ndarray
    n_rel: np.ndarray
    k_rel: np.ndarray
    F0: np.ndarray
    F82_tint: np.ndarray
    F0_schlick: np.ndarray
    roughness: float = 0.2
    coat_roughness: float = 0.03
    model: PackedMaterial | None = None
    version: str = field(default_factory=project_version)
    view_cos: np.ndarray | None = None
    seen_ACEScg: np.ndarray | None = None
    tools: dict = field(default_factory=dict)
    fit_id: str | None = None
    working_space: str = DEFAULT_WORKING_SPACE
    seen_rough_ACEScg: np.ndarray | None = None

    def provenance(self, model_kind: str, fidelity: dict | None = None) -> dict:
        """
        What the export was made from, for a comment or ``extras``: material,
        the full fit id, its kind, the service version, eta_i, the working
        space (:func:`fitting.exports.naming.identity`), source (one line),
        model kind, what was fitted, colour space, generator and version,
        and the export's Delta E 2000 (``fidelity``, from
        :func:`fitting.exports.seen_fit.seen_fidelity`).
        """
        info = {
            "material": self.name,
            **identity(self),
            "source": " ".join(self.source.split()),
            "eta_i": self.eta_i,
            "model_kind": model_kind,
            "fitted_to": self.origin,
            "fitted_how": (
                "the tool's coat over its base, against the physical coat on the metal seen "
                "from air (both polarisations, metal at the refracted angle, bounces between "
                "the interfaces), Delta E 2000 least squares (the glTF fallback's base colour then "
                "refined to the least mean Delta E over the angles)"
            ),
            "colour_space": self.working_space,
            "generator": f"coated-fresnel {self.version}",
        }
        if fidelity is not None:
            info["delta_E_2000_seen"] = (
                f"mean {fidelity['delta_E_mean']:.3f}, max {fidelity['delta_E_max']:.3f} "
                f"over {SEEN_ANGLES_DEG[0]:g}-{SEEN_ANGLES_DEG[-1]:g} degrees in air, roughness 0"
            )
        return info


def _naive_fits(mu, target) -> tuple:
    """``target`` (working space) and its naive fits: n, k; F0, F82 tint; Schlick's F0."""
    return (
        target,
        *fit_channel_conductor(mu, target, joint=True),
        *fit_channel_f82(mu, target, joint=True),
        fit_channel_schlick(mu, target),
    )


def has_coat(eta_i: float) -> bool:
    """Whether an export at ``eta_i`` has a coat at all (eta_i 1: no coat, the bare metal)."""
    return float(eta_i) > ETA_I_MIN


def export_values(
    fit_or_nk,
    eta_i,
    roughness: float = 0.2,
    coat_roughness: float = 0.03,
    model: PackedMaterial | None = None,
    tools=None,
    fit_id: str | None = None,
    working_space: str = DEFAULT_WORKING_SPACE,
) -> ExportValues:
    """
    The values of every export of a material at one coating index.

    Parameters
    ----------
    fit_or_nk
        A :class:`fitting.optics.nk.SpectralNK` (measured n, k: the target is the
        1 nm spectral reference), or a mapping ``{"name", "source", "n",
        "k"}`` with per-channel n, k in linear ACEScg (an ``rgb-conductor``
        fit: the target is its exact Fresnel curve of (n + i k) / eta_i), or
        a mapping ``{"name", "source", "reflectance", "origin"}`` whose
        ``reflectance(cos_theta, eta_i)`` gives a fitted model's linear ACEScg
        curve (a fit made from edited curves: the target is that curve).
    eta_i
        Coating index, in [1, 3].
    roughness, coat_roughness
        Perceptual roughness of the metal and the coat, [0, 1].
    model
        The fit's float16 model, carried as is (:attr:`ExportValues.model`).
    tools
        The tools whose values to fit (keys of
        :data:`fitting.exports.tool_layering.TOOLS`); all when ``None``.
    fit_id
        The stored fit's id (32 lower-case hex digits), or ``None``.
    working_space
        ``lin_rec709`` (default) or ``acescg``: the space the values are
        fitted and written in.

    Raises
    ------
    ValueError
        For eta_i or a roughness outside its range, an input of another
        type, ``model`` not a ``PackedMaterial``, or n, k covering too little
        of 360-830 nm.
    """
    eta = check_eta_i(eta_i)
    roughness = check_roughness("roughness", roughness)
    coat_roughness = check_roughness("coat_roughness", coat_roughness)
    fit_id = check_fit_id(fit_id)
    working_space = check_working_space(working_space)
    if model is not None and not isinstance(model, PackedMaterial):
        raise ValueError(f"`model` must be a PackedMaterial or None, got {type(model).__name__}")
    tools = tuple(TOOLS) if tools is None else tuple(tools)
    for tool in tools:
        if tool not in TOOLS:
            raise ValueError(f"`tools` must name tools of {', '.join(TOOLS)}, got {tool!r}")
    mu = np.linspace(0.0, 1.0, EXPORT_SAMPLES)
    view = np.cos(np.radians(SEEN_ANGLES_DEG))
    key = None
    if isinstance(fit_or_nk, SpectralNK):
        name, source, key = fit_or_nk.name, fit_or_nk.source, (_nk_key(fit_or_nk), eta)
        target_ACEScg, seen = _kept(
            key, lambda: (reference_ACEScg(fit_or_nk, mu, eta, 1.0), seen_ACEScg(fit_or_nk, view, eta))
        )
        origin = "spectral (1 nm) air / coat / metal stack seen from air"
    elif isinstance(fit_or_nk, dict) and callable(fit_or_nk.get("reflectance")):
        name = str(fit_or_nk.get("name", "material"))
        source = str(fit_or_nk.get("source", ""))
        target_ACEScg = np.asarray(fit_or_nk["reflectance"](mu, eta), dtype=np.float64)
        if target_ACEScg.shape != (EXPORT_SAMPLES, 3) or not np.all(np.isfinite(target_ACEScg)):
            raise ValueError(
                f"`fit_or_nk['reflectance']` must give finite ({EXPORT_SAMPLES}, 3) RGB, "
                f"got shape {target_ACEScg.shape}"
            )
        origin = str(fit_or_nk.get("origin", "the fit's model curve under the coat"))
        seen = coated_stack_from_metal(view, eta, lambda mc: fit_or_nk["reflectance"](mc, eta))
        if seen.shape != (view.size, 3) or not np.all(np.isfinite(seen)):
            raise ValueError("`fit_or_nk['reflectance']` must give finite (S, 3) RGB for S cos theta")
    elif isinstance(fit_or_nk, dict) and {"n", "k"} <= set(fit_or_nk):
        name = str(fit_or_nk.get("name", "material"))
        source = str(fit_or_nk.get("source", ""))
        target_ACEScg = rgb_fresnel_conductor(mu, eta, fit_or_nk["n"], fit_or_nk["k"])
        n_c = np.asarray(fit_or_nk["n"], dtype=np.float64)
        k_c = np.asarray(fit_or_nk["k"], dtype=np.float64)
        seen = coated_stack(view[:, None], eta, n_c, k_c)
        origin = "rgb-conductor n, k per channel under the coat, seen from air"
    else:
        raise ValueError(
            "`fit_or_nk` must be a SpectralNK or a mapping with per-channel `n` and `k` "
            "or a `reflectance` function, "
            f"got {type(fit_or_nk).__name__}"
        )
    target, n_rel, k_rel, F0, tint, F0_schlick = _kept(
        key and (*key, working_space), lambda: _naive_fits(mu, ACEScg_to_working(target_ACEScg, working_space))
    )
    coat = has_coat(eta)
    rough_seen = (
        _kept(
            key and (*key, "rough", roughness),
            lambda: (rough_seen_ACEScg(view, eta, seen, mu, target_ACEScg, roughness),),
        )[0]
        if "gltf" in tools and coat and roughness > 0.0
        else None
    )
    fitted = {
        tool: fit_tool_values(
            tool, view, eta, seen, coat, space=working_space, roughness=roughness, rough_target_ACEScg=rough_seen
        )
        for tool in tools
    }
    return ExportValues(
        name=name,
        source=source,
        eta_i=eta,
        origin=origin,
        cos_theta=mu,
        target=target,
        target_ACEScg=target_ACEScg,
        n_rel=n_rel,
        k_rel=k_rel,
        F0=F0,
        F82_tint=tint,
        F0_schlick=F0_schlick,
        roughness=roughness,
        coat_roughness=coat_roughness,
        model=model,
        view_cos=view,
        seen_ACEScg=seen,
        tools=fitted,
        fit_id=fit_id,
        working_space=working_space,
        seen_rough_ACEScg=rough_seen,
    )
