"""
Scene packs: the scene description
==================================

Model only what a scene needs: a scene lists its materials and, for each, the
coating indices eta_i it uses; each material is fitted over those eta_i only,
with the lowest polynomial degree that serves them, and the pack holds only
those materials.

Scene description (JSON)::

    {
      "name": "showroom",                                  (optional)
      "max_delta_e": 0.05,        (optional) or "prefer": "accuracy"
      "materials": [
        {"material": "Au", "eta_i": 1.0},                  one eta_i (1 = uncoated)
        {"material": "Cu", "eta_i": [1.33, 1.5]},          a set
        {"material": "Al", "eta_i": {"min": 1.3, "max": 1.6}},   a range
        {"material": "Cr", "name": "trim", "eta_i": 1.5},  pack name != material
        {"name": "mine", "nk": {"wavelength_nm": [...], "n": [...], "k": [...],
                                "source": "..."}, "eta_i": 1.5}
      ]
    }

``material`` names a library conductor (:func:`fitting.optics.catalogue.resolve_material`: gold, Au, TiN)
or whatever a caller's resolver knows (the service's stored materials);
``nk`` gives the data inline. Names in a pack are unique.

Candidates (:data:`fitting.fits.scene_fit.CANDIDATES`, cheapest to shade
first): the coated-conductor of each degree up to min(2, m - 1) for a set
of *m* values (a range counts as many values; one eta_i: degree 0 only, the
scene-specialised shader) and the rgb-conductor, each fitted over the
scene's eta_i (a set: at its values only, the max guard included), and the
general fit as the dearest. Each is scored as shipped (float16) where the
scene looks: at the set's values, or over the range. A candidate worse than
the general fit on the mean or the max never ships; of the others:

-   by default, the cheapest no worse on mean and on max than every dearer
    candidate: nothing is passed over for its cost while it beats the one
    shipped on either figure;
-   with ``max_delta_e`` (a mean Delta E 2000 on the scene's eta_i, > 0),
    the cheapest within it, else as by default;
-   with ``"prefer": "accuracy"``, the lowest mean.

Where the general fit itself is chosen it ships
(``metrics["from_general_fit"]``). The report says per material what was
chosen and why, with every candidate's figures (``choice``).

Each material is compared with the general fit (degree 2, 27 coefficients,
over the default domain [1, 2.5], widened to hold the scene's eta_i): bytes in
the pack and Delta E 2000 against the 1 nm spectral reference, both on the
same evaluation grid: :data:`EVALUATION_MU_SAMPLES` values of cos theta times
the scene's eta_i (a range: :data:`EVALUATION_ETA_ROWS` values over it).

-   :func:`parse_scene`: a validated :class:`Scene` from JSON text or a dict.
-   The fits and the rule: :mod:`fitting.fits.scene_fit`; the
    results and their report: :mod:`fitting.fits.scene_report`; the command
    ``python -m fitting scene``: :mod:`fitting.cli.scene`.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Eq. 1 and 2 (degree 0 is Eq. 1 with constant F0, a, alpha).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..domain import check_eta_i
from ..optics.catalogue import catalogue_material
from ..optics.nk import SpectralNK

__all__ = [
    "MAX_SCENE_MATERIALS",
    "MAX_ETA_I_VALUES",
    "EVALUATION_MU_SAMPLES",
    "EVALUATION_ETA_ROWS",
    "PREFERENCES",
    "EtaSpec",
    "SceneMaterial",
    "Scene",
    "parse_eta_i",
    "parse_scene",
]

MAX_SCENE_MATERIALS = 64
"""Most materials in one scene (each costs about a second to fit and score)."""


MAX_ETA_I_VALUES = 32
"""Most values in one eta_i set."""


EVALUATION_MU_SAMPLES = 100
"""cos theta values, evenly over [0, 1], of the evaluation grid."""

EVALUATION_ETA_ROWS = 50
"""eta_i values, evenly over a range, of the evaluation grid."""


_NAME_MAX = 200

PREFERENCES = ("accuracy",)
"""Values of a scene's ``prefer``."""


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
    max_delta_e: float | None = None
    prefer: str | None = None


def _check_eta_value(value: Any, where: str) -> float:
    # JSON numbers only: a string "1.5" or true is refused, not converted.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"`{where}` must be a number, got {value!r}")
    return check_eta_i(value, where)


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
            raise ValueError(f'`{where}` as a range must be {{"min": lo, "max": hi}}, got keys {sorted(value)}')
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
                'give a range {"min", "max"} instead'
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


def parse_scene(data: str | bytes | dict, resolve: Callable[[str], SpectralNK] | None = None) -> Scene:
    """
    Validate a scene description (see the module docstring).

    Parameters
    ----------
    data
        JSON text or the decoded object.
    resolve
        Maps a ``material`` name to its data; by default
        :func:`fitting.optics.catalogue.catalogue_material`. It raises ``ValueError``
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
    unknown = set(data) - {"name", "materials", "max_delta_e", "prefer"}
    if unknown:
        raise ValueError(f"scene has unknown keys {sorted(unknown)}; allowed: name, materials, max_delta_e, prefer")
    max_delta_e, prefer = data.get("max_delta_e"), data.get("prefer")
    if max_delta_e is not None and prefer is not None:
        raise ValueError("give at most one of `max_delta_e` and `prefer`")
    if max_delta_e is not None:
        if (
            isinstance(max_delta_e, bool)
            or not isinstance(max_delta_e, (int, float))
            or not (np.isfinite(max_delta_e) and 0.0 < max_delta_e <= 100.0)
        ):
            raise ValueError(f"`max_delta_e` must be a number in (0, 100], got {max_delta_e!r}")
        max_delta_e = float(max_delta_e)
    if prefer is not None and prefer not in PREFERENCES:
        raise ValueError(f"`prefer` must be one of {', '.join(PREFERENCES)}, got {prefer!r}")
    scene_name = data.get("name", "scene")
    if not isinstance(scene_name, str) or not scene_name.strip() or len(scene_name) > _NAME_MAX:
        raise ValueError(f"`name` must be a non-empty string of at most {_NAME_MAX} characters")
    entries = data.get("materials")
    if not isinstance(entries, list) or not entries:
        raise ValueError("`materials` must be a non-empty list")
    if len(entries) > MAX_SCENE_MATERIALS:
        raise ValueError(f"`materials` must hold at most {MAX_SCENE_MATERIALS} entries, got {len(entries)}")
    resolve = resolve or catalogue_material
    materials, seen = [], set()
    for i, entry in enumerate(entries):
        where = f"materials[{i}]"
        if not isinstance(entry, dict):
            raise ValueError(f"`{where}` must be an object")
        unknown = set(entry) - {"name", "material", "nk", "eta_i"}
        if unknown:
            raise ValueError(f"`{where}` has unknown keys {sorted(unknown)}; allowed: name, material, nk, eta_i")
        if ("material" in entry) == ("nk" in entry):
            raise ValueError(f"`{where}` must give exactly one of `material` and `nk`")
        if "eta_i" not in entry:
            raise ValueError(f"`{where}.eta_i` is required (1 for uncoated)")
        material = entry.get("material", "")
        if "material" in entry and (not isinstance(material, str) or not material):
            raise ValueError(f"`{where}.material` must be a material name, e.g. gold, Au or TiN")
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
    return Scene(scene_name, tuple(materials), max_delta_e, prefer)
