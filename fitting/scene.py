"""
Scene packs
===========

Model only what a scene needs: a scene lists its materials and, for each, the
coating indices eta_i it uses; each material is fitted over those eta_i only,
with the lowest polynomial degree that serves them, and the pack holds only
those materials.

Scene description (JSON)::

    {
      "name": "showroom",                                  (optional)
      "materials": [
        {"material": "Au", "eta_i": 1.0},                  one eta_i (1 = uncoated)
        {"material": "Cu", "eta_i": [1.33, 1.5]},          a set
        {"material": "Al", "eta_i": {"min": 1.3, "max": 1.6}},   a range
        {"material": "Cr", "name": "trim", "eta_i": 1.5},  pack name != material
        {"name": "mine", "nk": {"wavelength_nm": [...], "n": [...], "k": [...],
                                "source": "..."}, "eta_i": 1.5}
      ]
    }

``material`` names a library conductor (:data:`fitting.library.LIBRARY_NAMES`)
or whatever a caller's resolver knows (the service's stored materials);
``nk`` gives the data inline. Names in a pack are unique.

Degree rule (:data:`DEGREE_TOLERANCE_MEAN`, :data:`DEGREE_TOLERANCE_MAX`):
one eta_i is fitted with degree 0 (9 coefficients, the scene-specialised
shader). A set of *m* values or a range is fitted with every degree up to
min(2, m - 1) (a range counts as many values); the lowest degree whose float16
fit has a mean Delta E 2000 at most :data:`DEGREE_TOLERANCE_MEAN` above the
highest degree's and no worse than the general fit's, and a max at most
:data:`DEGREE_TOLERANCE_MAX` above the highest degree's, is kept
(:func:`choose_degree`). Where no scene fit beats the general fit on the
scene's eta_i (a narrow range the general fit already follows as closely),
the general fit itself is shipped for that material
(``metrics["from_general_fit"]``), so a scene material is never worse than
the general fit.

Each material is compared with the general fit (degree 2, 27 coefficients,
over the default domain [1, 2.5], widened to hold the scene's eta_i): bytes in
the pack and Delta E 2000 against the 1 nm spectral reference, both on the
same evaluation grid: :data:`EVALUATION_MU_SAMPLES` values of cos theta times
the scene's eta_i (a range: :data:`EVALUATION_ETA_ROWS` values over it).

-   :func:`parse_scene`: a validated :class:`Scene` from JSON text or a dict.
-   :func:`fit_scene`: fits every material, returns a :class:`SceneResult`.
-   :func:`add_scene_parser`, :func:`scene_command`: ``python -m fitting scene``.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Eq. 1 and 2 (degree 0 is Eq. 1 with constant F0, a, alpha).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .fit import FitResult, FitSettings, fit_coefficients, fit_grid, fit_material
from .library import LIBRARY_NAMES, library_material
from .metrics import delta_E_map
from .model import DEFAULT_ETA_I_RANGE, coated_conductor_model
from .nk import SpectralNK
from .pack import PackedMaterial, encode_pack, pack_to_json
from .reference import reference_ACEScg

__all__ = [
    "MAX_SCENE_MATERIALS",
    "MAX_ETA_I_VALUES",
    "DEGREE_TOLERANCE_MEAN",
    "DEGREE_TOLERANCE_MAX",
    "EVALUATION_MU_SAMPLES",
    "EVALUATION_ETA_ROWS",
    "EtaSpec",
    "SceneMaterial",
    "Scene",
    "SceneMaterialResult",
    "SceneResult",
    "parse_eta_i",
    "parse_scene",
    "general_domain",
    "choose_degree",
    "material_record_bytes",
    "fit_scene_material",
    "fit_scene",
    "add_scene_parser",
    "scene_command",
]

MAX_SCENE_MATERIALS = 64
"""Most materials in one scene (each costs about a second to fit and score)."""

MAX_ETA_I_VALUES = 32
"""Most values in one eta_i set."""

DEGREE_TOLERANCE_MEAN = 0.05
"""A lower degree is kept if its mean Delta E 2000 is at most this much above
the highest degree's (a twentieth of a just-noticeable difference)."""

DEGREE_TOLERANCE_MAX = 0.5
"""... and its max Delta E 2000 at most this much above (half a JND)."""

EVALUATION_MU_SAMPLES = 100
"""cos theta values, evenly over [0, 1], of the evaluation grid."""

EVALUATION_ETA_ROWS = 50
"""eta_i values, evenly over a range, of the evaluation grid."""

_NAME_MAX = 200


@dataclass(frozen=True)
class EtaSpec:
    """
    The coating indices a scene uses for one material.

    ``kind`` is ``"one"``, ``"set"`` or ``"range"``; ``values`` the sorted
    distinct values (one or a set) or (lo, hi) (a range).
    """

    kind: str
    values: tuple[float, ...]

    @property
    def domain(self) -> tuple[float, float]:
        """The fitted domain [lo, hi]."""
        return (self.values[0], self.values[-1])

    @property
    def max_degree(self) -> int:
        """The highest polynomial degree the values determine."""
        if self.kind == "range":
            return 2
        return min(2, len(self.values) - 1)

    def evaluation_eta_i(self) -> np.ndarray:
        """The eta_i rows of the evaluation grid."""
        if self.kind == "range":
            return np.linspace(self.values[0], self.values[1], EVALUATION_ETA_ROWS)
        return np.array(self.values)

    def to_json(self) -> Any:
        if self.kind == "one":
            return self.values[0]
        if self.kind == "set":
            return list(self.values)
        return {"min": self.values[0], "max": self.values[1]}


@dataclass(frozen=True)
class SceneMaterial:
    """One material of a scene: pack ``name``, its data and its eta_i."""

    name: str
    material: str
    nk: SpectralNK
    eta_i: EtaSpec


@dataclass(frozen=True)
class Scene:
    """A validated scene: its name and materials (unique names)."""

    name: str
    materials: tuple[SceneMaterial, ...]


def _check_eta_value(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"`{where}` must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x) or not 1.0 <= x <= 3.0:
        raise ValueError(f"`{where}` must lie in [1, 3] (1 is uncoated), got {value!r}")
    return x


def parse_eta_i(value: Any, where: str = "eta_i") -> EtaSpec:
    """
    The :class:`EtaSpec` of a JSON value: a number, a list of numbers, or
    ``{"min": lo, "max": hi}``; every value in [1, 3].

    Raises
    ------
    ValueError
        Naming ``where`` and the broken rule.
    """
    if isinstance(value, dict):
        unknown = set(value) - {"min", "max"}
        if unknown or not {"min", "max"} <= set(value):
            raise ValueError(
                f"`{where}` as a range must be {{\"min\": lo, \"max\": hi}}, got keys {sorted(value)}"
            )
        lo = _check_eta_value(value["min"], f"{where}.min")
        hi = _check_eta_value(value["max"], f"{where}.max")
        if hi < lo:
            raise ValueError(f"`{where}` must have min <= max, got min {lo:g} > max {hi:g}")
        if hi == lo:
            return EtaSpec("one", (lo,))
        return EtaSpec("range", (lo, hi))
    if isinstance(value, list):
        if not value:
            raise ValueError(f"`{where}` must hold at least one value, got []")
        if len(value) > MAX_ETA_I_VALUES:
            raise ValueError(
                f"`{where}` must hold at most {MAX_ETA_I_VALUES} values, got {len(value)}; "
                "give a range {\"min\", \"max\"} instead"
            )
        values = sorted({_check_eta_value(v, f"{where}[{i}]") for i, v in enumerate(value)})
        return EtaSpec("one" if len(values) == 1 else "set", tuple(values))
    return EtaSpec("one", (_check_eta_value(value, where),))


def _nk_from_json(view: Any, name: str, where: str) -> SpectralNK:
    if not isinstance(view, dict):
        raise ValueError(f"`{where}` must be an object with wavelength_nm, n and k")
    missing = [key for key in ("wavelength_nm", "n", "k") if key not in view]
    if missing:
        raise ValueError(f"`{where}` is missing {', '.join(missing)}")
    source = view.get("source", "scene description")
    if not isinstance(source, str):
        raise ValueError(f"`{where}.source` must be a string")
    try:
        return SpectralNK(view["wavelength_nm"], view["n"], view["k"], name=name, source=source)
    except ValueError as error:
        raise ValueError(f"`{where}`: {error}") from None


def parse_scene(
    data: str | bytes | dict, resolve: Callable[[str], SpectralNK] | None = None
) -> Scene:
    """
    Validate a scene description (see the module docstring).

    Parameters
    ----------
    data
        JSON text or the decoded object.
    resolve
        Maps a ``material`` name to its data; by default
        :func:`fitting.library.library_material`. It raises ``ValueError``
        for names it does not know.

    Raises
    ------
    ValueError
        Naming the field (``materials[2].eta_i``), the rule and the value.
    """
    if isinstance(data, (str, bytes)):
        try:
            data = json.loads(data)
        except (json.JSONDecodeError, UnicodeDecodeError) as error:
            raise ValueError(f"scene is not valid JSON: {error}") from None
    if not isinstance(data, dict):
        raise ValueError("scene must be a JSON object with a `materials` list")
    unknown = set(data) - {"name", "materials"}
    if unknown:
        raise ValueError(f"scene has unknown keys {sorted(unknown)}; allowed: name, materials")
    scene_name = data.get("name", "scene")
    if not isinstance(scene_name, str) or not scene_name.strip() or len(scene_name) > _NAME_MAX:
        raise ValueError(f"`name` must be a non-empty string of at most {_NAME_MAX} characters")
    entries = data.get("materials")
    if not isinstance(entries, list) or not entries:
        raise ValueError("`materials` must be a non-empty list")
    if len(entries) > MAX_SCENE_MATERIALS:
        raise ValueError(
            f"`materials` must hold at most {MAX_SCENE_MATERIALS} entries, got {len(entries)}"
        )
    resolve = resolve or library_material
    materials, seen = [], set()
    for i, entry in enumerate(entries):
        where = f"materials[{i}]"
        if not isinstance(entry, dict):
            raise ValueError(f"`{where}` must be an object")
        unknown = set(entry) - {"name", "material", "nk", "eta_i"}
        if unknown:
            raise ValueError(
                f"`{where}` has unknown keys {sorted(unknown)}; allowed: name, material, nk, eta_i"
            )
        if ("material" in entry) == ("nk" in entry):
            raise ValueError(f"`{where}` must give exactly one of `material` and `nk`")
        if "eta_i" not in entry:
            raise ValueError(f"`{where}.eta_i` is required (1 for uncoated)")
        material = entry.get("material", "")
        if "material" in entry and (not isinstance(material, str) or not material):
            raise ValueError(
                f"`{where}.material` must be a material name, e.g. one of {', '.join(LIBRARY_NAMES)}"
            )
        name = entry.get("name", material)
        if not isinstance(name, str) or not name.strip() or len(name) > _NAME_MAX:
            raise ValueError(
                f"`{where}.name` must be a non-empty string of at most {_NAME_MAX} characters"
                + (" (required with `nk`)" if "nk" in entry else "")
            )
        if name in seen:
            raise ValueError(f"`{where}.name` {name!r} is used twice; names in a pack are unique")
        seen.add(name)
        eta = parse_eta_i(entry["eta_i"], f"{where}.eta_i")
        if "nk" in entry:
            nk = _nk_from_json(entry["nk"], name, f"{where}.nk")
        else:
            try:
                nk = resolve(material)
            except ValueError as error:
                raise ValueError(f"`{where}.material`: {error}") from None
        materials.append(SceneMaterial(name, material or name, nk, eta))
    return Scene(scene_name, tuple(materials))


def material_record_bytes(name: str, source: str, degree: int) -> int:
    """
    Bytes of one material in the binary pack (``fitting.pack``): name and
    source with their u16 lengths, the f32 domain, degree and padding, and
    9 (degree + 1) float16 coefficients.
    """
    return 2 + len(name.encode()) + 2 + len(source.encode()) + 12 + 18 * (degree + 1)


@dataclass
class SceneMaterialResult:
    """
    One fitted material of a scene.

    ``packed`` is the scene fit (in the pack), ``general`` the general fit it
    is compared with; ``by_degree`` the Delta E 2000 (mean, max) of each
    candidate degree, ``scene`` and ``general_error`` those of the chosen and
    the general float16 model, ``scene_vs_general`` the Delta E between the
    two models; all on the same evaluation grid.
    """

    material: SceneMaterial
    packed: PackedMaterial
    fit: FitResult
    general: PackedMaterial
    by_degree: dict[int, dict[str, float]]
    scene: dict[str, float]
    general_error: dict[str, float]
    scene_vs_general: dict[str, float]
    seconds: float

    @property
    def degree(self) -> int:
        return self.packed.degree

    @property
    def bytes(self) -> int:
        return material_record_bytes(self.packed.name, self.packed.source, self.degree)

    @property
    def general_bytes(self) -> int:
        return material_record_bytes(self.general.name, self.general.source, self.general.degree)

    @property
    def shader_variant(self) -> str:
        """``collapsed`` (Eq. 1 with constant F0, a, alpha) or ``packed``."""
        return "collapsed" if self.degree == 0 else "packed"

    def report(self) -> dict[str, Any]:
        return {
            "name": self.packed.name,
            "material": self.material.material,
            "eta_i": self.material.eta_i.to_json(),
            "eta_i_range": list(self.packed.eta_i_range),
            "degree": self.degree,
            "coefficients": 9 * (self.degree + 1),
            "shader_variant": self.shader_variant,
            "bytes": self.bytes,
            "delta_E_2000": self.scene,
            "by_degree": {str(d): v for d, v in self.by_degree.items()},
            "general": {
                "eta_i_range": list(self.general.eta_i_range),
                "degree": self.general.degree,
                "coefficients": 9 * (self.general.degree + 1),
                "bytes": self.general_bytes,
                "delta_E_2000": self.general_error,
            },
            "scene_vs_general_delta_E_2000": self.scene_vs_general,
            "fit": self.fit.summary(),
            "seconds": self.seconds,
        }


@dataclass
class SceneResult:
    """The fitted scene: one :class:`SceneMaterialResult` per material."""

    scene: Scene
    materials: list[SceneMaterialResult] = field(default_factory=list)

    @property
    def packed(self) -> list[PackedMaterial]:
        return [m.packed for m in self.materials]

    def pack_bytes(self) -> bytes:
        """The scene pack in the binary format."""
        return encode_pack(self.packed)

    def pack_json(self) -> str:
        """The scene pack in its JSON view."""
        return pack_to_json(self.packed)

    def report(self) -> dict[str, Any]:
        """JSON-friendly report: per material and totals."""
        general_pack = encode_pack([m.general for m in self.materials])
        return {
            "scene": self.scene.name,
            "materials": [m.report() for m in self.materials],
            "totals": {
                "pack_bytes": len(self.pack_bytes()),
                "general_pack_bytes": len(general_pack),
                "coefficients": sum(9 * (m.degree + 1) for m in self.materials),
                "general_coefficients": 27 * len(self.materials),
                "delta_E_2000_mean": float(np.mean([m.scene["mean"] for m in self.materials])),
                "general_delta_E_2000_mean": float(
                    np.mean([m.general_error["mean"] for m in self.materials])
                ),
            },
        }


def _error(ref: np.ndarray, model: np.ndarray) -> dict[str, float]:
    dE = delta_E_map(ref, model)
    return {"mean": float(dE.mean()), "max": float(dE.max())}


def _fit_degree(entry: SceneMaterial, degree: int, settings: FitSettings) -> FitResult:
    """The float16 fit of one candidate degree over the scene's eta_i."""
    spec = entry.eta_i
    if spec.kind != "set":
        return fit_material(entry.nk, spec.domain, settings, degree=degree)
    # A set: the fitting grid's rows are exactly the scene's values.
    t0 = time.perf_counter()
    rows = [fit_grid((v, v), settings.mu_samples, 1, settings.grid) for v in spec.values]
    mu, eta, weights = (np.concatenate(parts) for parts in zip(*rows))
    target = reference_ACEScg(entry.nk, mu, eta, settings.step_nm, settings.min_coverage)
    result = fit_coefficients(
        target, mu, eta, spec.domain, degree, settings.objective,
        settings.max_nfev, settings.quantise, weights=weights, irls_rounds=settings.irls_rounds,
    )
    result.packed = PackedMaterial(
        entry.name, result.coefficients_float16, spec.domain, source=entry.nk.source
    )
    result.timings["total"] = time.perf_counter() - t0
    return result


def choose_degree(
    by_degree: dict[int, dict[str, float]], general_error: dict[str, float]
) -> int:
    """
    The degree rule: the lowest degree whose mean Delta E is at most
    :data:`DEGREE_TOLERANCE_MEAN` above the highest degree's and no worse
    than the general fit's, and whose max is at most
    :data:`DEGREE_TOLERANCE_MAX` above the highest degree's; if none
    qualifies, the degree with the lowest mean.
    """
    top = by_degree[max(by_degree)]
    bound_mean = min(top["mean"] + DEGREE_TOLERANCE_MEAN, general_error["mean"])
    for degree in sorted(by_degree):
        error = by_degree[degree]
        if error["mean"] <= bound_mean and error["max"] <= top["max"] + DEGREE_TOLERANCE_MAX:
            return degree
    return min(by_degree, key=lambda d: (by_degree[d]["mean"], d))


def general_domain(spec: EtaSpec) -> tuple[float, float]:
    """The default domain [1, 2.5] widened to hold the scene's eta_i."""
    lo, hi = spec.domain
    return (min(DEFAULT_ETA_I_RANGE[0], lo), max(DEFAULT_ETA_I_RANGE[1], hi))


def fit_scene_material(entry: SceneMaterial, settings: FitSettings | None = None) -> SceneMaterialResult:
    """
    Fit one scene material with the degree rule of the module docstring and
    score it against the general fit.

    Raises
    ------
    ValueError
        For data the fit refuses (e.g. too little visible coverage).
    """
    t0 = time.perf_counter()
    settings = settings or FitSettings()
    spec = entry.eta_i
    eta_rows = spec.evaluation_eta_i()
    mu = np.linspace(0.0, 1.0, EVALUATION_MU_SAMPLES)
    E, M = np.meshgrid(eta_rows, mu, indexing="ij")
    ref = reference_ACEScg(entry.nk, M, E, 1.0, settings.min_coverage)
    general_fit = fit_material(entry.nk, general_domain(spec), settings, degree=2)
    general = PackedMaterial(
        entry.name, general_fit.coefficients_float16, general_fit.eta_i_range,
        source=entry.nk.source,
    )
    general_model = coated_conductor_model(M, E, general.coefficients, general.eta_i_range)
    general_error = _error(ref, general_model)
    fits, by_degree = {}, {}
    for degree in range(spec.max_degree + 1):
        fit = _fit_degree(entry, degree, settings)
        fits[degree] = fit
        # Scored as shipped: float16 coefficients, the pack's float32 domain.
        by_degree[degree] = _error(
            ref, coated_conductor_model(M, E, fit.packed.coefficients, fit.packed.eta_i_range)
        )
    chosen = choose_degree(by_degree, general_error)
    scene_error = by_degree[chosen]
    if scene_error["mean"] > general_error["mean"]:
        # No scene fit beats the general fit on the scene's eta_i (a narrow
        # range the general fit already follows as well as its own fit can):
        # the general fit itself serves it, never a worse one.
        packed = PackedMaterial(
            entry.name, general.coefficients, general.eta_i_range, source=entry.nk.source,
            metrics={"delta_E_2000": general_error, "eta_i": spec.to_json(),
                     "from_general_fit": True},
        )
        scene_error = general_error
    else:
        packed = PackedMaterial(
            entry.name, fits[chosen].packed.coefficients, spec.domain, source=entry.nk.source,
            metrics={"delta_E_2000": scene_error, "eta_i": spec.to_json(),
                     "from_general_fit": False},
        )
    fit = fits[chosen]
    scene_model = coated_conductor_model(M, E, packed.coefficients, packed.eta_i_range)
    return SceneMaterialResult(
        material=entry,
        packed=packed,
        fit=fit,
        general=general,
        by_degree=by_degree,
        scene=scene_error,
        general_error=general_error,
        scene_vs_general=_error(general_model, scene_model),
        seconds=time.perf_counter() - t0,
    )


def fit_scene(scene: Scene, settings: FitSettings | None = None) -> SceneResult:
    """Fit every material of ``scene`` (see :func:`fit_scene_material`)."""
    result = SceneResult(scene)
    for entry in scene.materials:
        try:
            result.materials.append(fit_scene_material(entry, settings))
        except ValueError as error:
            raise ValueError(f"material {entry.name!r}: {error}") from None
    return result


def _format_table(report: dict[str, Any]) -> str:
    rows = [
        f"scene {report['scene']}",
        f"{'name':<16} {'eta_i':<18} {'deg':>3} {'bytes':>6} {'general':>7} "
        f"{'dE mean':>8} {'general':>8} {'dE max':>7} {'general':>8}",
    ]
    for m in report["materials"]:
        eta = json.dumps(m["eta_i"])
        rows.append(
            f"{m['name'][:16]:<16} {eta[:18]:<18} {m['degree']:>3} {m['bytes']:>6} "
            f"{m['general']['bytes']:>7} {m['delta_E_2000']['mean']:>8.3f} "
            f"{m['general']['delta_E_2000']['mean']:>8.3f} {m['delta_E_2000']['max']:>7.3f} "
            f"{m['general']['delta_E_2000']['max']:>8.3f}"
        )
    totals = report["totals"]
    rows.append(
        f"pack {totals['pack_bytes']} bytes (general {totals['general_pack_bytes']}), "
        f"{totals['coefficients']} coefficients (general {totals['general_coefficients']}), "
        f"mean Delta E 2000 {totals['delta_E_2000_mean']:.3f} "
        f"(general {totals['general_delta_E_2000_mean']:.3f})"
    )
    return "\n".join(rows)


def _write_new_file(path: Path, data: bytes) -> None:
    """Write ``data`` to a new file ``path`` atomically; never replace one."""
    directory = path.parent if str(path.parent) else Path(".")
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=directory)
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
        # link() fails if the target exists: a file the user saved is never replaced.
        os.link(temporary, path)
    finally:
        os.unlink(temporary)


def scene_command(args: argparse.Namespace) -> int:
    """
    ``python -m fitting scene FILE [-o PACK] [--json]``: fit a scene, print
    the table (or the JSON report) and write the pack (``.json`` suffix: the
    JSON view, otherwise binary). Returns the exit status: 0, or 2 with a
    message on stderr for bad input or an existing output file.
    """
    try:
        output = Path(args.output) if args.output else None
        if output is not None and output.exists():
            raise ValueError(f"`--output` {output} exists; it is never overwritten, choose a new name")
        try:
            text = Path(args.file).read_bytes()
        except OSError as error:
            raise ValueError(f"cannot read scene `FILE` {args.file}: {error.strerror}") from None
        result = fit_scene(parse_scene(text))
        report = result.report()
        if output is not None:
            data = result.pack_json().encode() if output.suffix == ".json" else result.pack_bytes()
            try:
                _write_new_file(output, data)
            except FileExistsError:
                raise ValueError(f"`--output` {output} exists; it is never overwritten") from None
            except OSError as error:
                raise ValueError(f"cannot write `--output` {output}: {error.strerror}") from None
            report["output"] = str(output)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(json.dumps(report, indent=2) if args.json else _format_table(report))
    return 0


def add_scene_parser(subparsers) -> argparse.ArgumentParser:
    """Register the ``scene`` subcommand on an ``argparse`` subparsers object."""
    parser = subparsers.add_parser(
        "scene",
        help="fit only the materials and coating indices a scene uses",
        description=(
            "Fit each material of a scene description over the eta_i the scene "
            "uses, with the lowest polynomial degree that serves it, and report "
            "bytes and Delta E 2000 against the general 27-coefficient fit."
        ),
    )
    parser.add_argument("file", metavar="FILE", help="scene description (JSON)")
    parser.add_argument(
        "-o", "--output", metavar="PACK",
        help="write the scene pack here (.json: JSON view, else binary); never overwrites",
    )
    parser.add_argument("--json", action="store_true", help="print the JSON report")
    parser.set_defaults(func=scene_command)
    return parser
