"""
Domain: the constants and rules of the fitting core
===================================================

Layer 0 of :mod:`fitting` (see ``docs/architecture.md``): every rule that more
than one module, the command line or the service applies is written here
once, and everything else imports it. Nothing here imports from the rest of
the package.

-   :data:`ETA_I_MIN`, :data:`ETA_I_MAX`: the coating indices the model is
    defined for, [1, 3] (1 is uncoated).
-   :data:`DEFAULT_ETA_I_RANGE`: the default fitted domain [1, 2.5], the
    paper's (Vernooij 2024, Section 4.1).
-   :data:`VISIBLE_RANGE_NM`, :data:`DEFAULT_MIN_COVERAGE`: the integration
    range of the reference and the least fraction of it data must cover.
-   :data:`WORKING_SPACES`, :data:`DEFAULT_WORKING_SPACE`: the colour spaces an
    export is fitted and written in (:mod:`fitting.exports.colour_space`).
-   :data:`COAT_PRESETS`: common clear coats by name, their index at the
    sodium D line (589 nm) and its source (the editor's coat presets).
-   :func:`check_eta_i`, :func:`check_eta_i_range`: one index, a domain.
-   :func:`cos_theta_from_angle`: angle theta in degrees to :math:`\\mu`.
-   :class:`BoundedCache`: the most recently used values by key, thread-safe,
    one build per key however many ask at once (curve bases, the service's
    measured curves); :func:`cached_once`, the same for a value computed
    once per process (the split-sum LUT and its file).
-   :func:`as_finite_array`, :func:`check_int`, :func:`check_choice`,
    :func:`check_number`, :func:`check_min_coverage`, :func:`check_step_nm`:
    the argument checks shared by the settings and the public functions.

Every check raises ``ValueError`` naming the argument, the rule and the
offending value ("`eta_i` must lie in [1, 3], got 0.8").

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Sections 3.1 and 4.1.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Any

import numpy as np

__all__ = [
    "ETA_I_MIN",
    "ETA_I_MAX",
    "DEFAULT_ETA_I_RANGE",
    "VISIBLE_RANGE_NM",
    "DEFAULT_MIN_COVERAGE",
    "STEP_NM_LIMITS",
    "ANGLE_LIMITS_DEG",
    "COAT_PRESETS",
    "WORKING_SPACES",
    "DEFAULT_WORKING_SPACE",
    "as_float_array",
    "as_finite_array",
    "INDEX_LIMITS",
    "check_eta_i",
    "check_eta_i_range",
    "cos_theta_from_angle",
    "check_int",
    "check_choice",
    "check_number",
    "check_min_coverage",
    "check_step_nm",
    "constants",
    "BoundedCache",
    "cached_once",
]

ETA_I_MIN: float = 1.0
"""Lowest coating index: 1 is no coating (air)."""

ETA_I_MAX: float = 3.0
"""Highest coating index the model and its fits accept."""

DEFAULT_ETA_I_RANGE: tuple[float, float] = (1.0, 2.5)
"""The default fitted domain [lo, hi] of eta_i (Vernooij 2024, Section 4.1)."""

VISIBLE_RANGE_NM: tuple[float, float] = (360.0, 830.0)
"""Integration range of the reference in nm (Vernooij 2024, Section 3.1)."""

DEFAULT_MIN_COVERAGE: float = 0.9
"""Smallest fraction of :data:`VISIBLE_RANGE_NM` the data must cover."""

STEP_NM_LIMITS: tuple[float, float] = (0.5, 100.0)
"""Accepted spectral steps of the reference in nm."""

ANGLE_LIMITS_DEG: tuple[float, float] = (0.0, 90.0)
"""Angles theta in the coating, degrees: normal to grazing incidence."""

WORKING_SPACES: tuple[str, ...] = ("lin_rec709", "acescg")
"""The working spaces an export can be fitted and written in (MaterialX's names;
:mod:`fitting.exports.colour_space` converts between them)."""

DEFAULT_WORKING_SPACE: str = "lin_rec709"
"""The working space of an export unless one is asked: glTF's, Blender's and MaterialX's default."""

COAT_PRESETS: tuple[tuple[str, str, float, str], ...] = (
    (
        "air",
        "Air (uncoated)",
        1.0,
        "Vacuum is 1; dry air at 15 C and 101.325 kPa is 1.00028 at 589 nm (Ciddor 1996, Appl. Opt. 35, "
        "1566), which no render tells apart from 1",
    ),
    ("water", "Water", 1.333, "1.3330 at 589 nm and 20 C (Daimon and Masumura 2007, Appl. Opt. 46, 3811)"),
    (
        "acrylic",
        "Lacquer, acrylic (PMMA)",
        1.49,
        "PMMA 1.4905 at 589 nm (Sultanova, Kasarova and Nikolov 2009, Acta Phys. Pol. A 116, 585); "
        "clear acrylic and nitrocellulose lacquers lie at 1.49-1.51",
    ),
    (
        "glass",
        "Glass (crown)",
        1.5,
        "Soda-lime and crown glasses 1.50-1.52 at 589 nm (Schott N-BK7: 1.5168 at 587.6 nm)",
    ),
    (
        "polyurethane",
        "Varnish, polyurethane",
        1.5,
        "Polyurethane clear coats about 1.50 at 589 nm (cured two-part automotive clear coats 1.49-1.52)",
    ),
    (
        "polycarbonate",
        "Polycarbonate",
        1.585,
        "1.5855 at 589 nm (Sultanova, Kasarova and Nikolov 2009, Acta Phys. Pol. A 116, 585)",
    ),
    (
        "sapphire",
        "Sapphire",
        1.768,
        "Ordinary ray 1.7681 at 589 nm (Malitson and Dodge 1972, J. Opt. Soc. Am. 62, 1405)",
    ),
    ("diamond", "Diamond", 2.417, "2.4175 at 589 nm (Phillip and Taft 1964, Phys. Rev. 136, A1445)"),
)
"""Coat presets ``(key, display name, eta_i, source)``: common clear coats by their
index at 589 nm, inside [ETA_I_MIN, ETA_I_MAX]. A coat's index falls by about 0.01-0.02
from 400 to 700 nm (dispersion); the model takes one real eta_i, so the 589 nm value stands
for the whole range."""

INDEX_LIMITS: tuple[float, float] = (1.0e-6, 1.0e8)
"""Where the physics kernels clamp a refractive index or extinction
coefficient (:mod:`fitting.optics.fresnel`). Measured indices lie far inside
(n > 0.01 and k < 100 for every material of the database); past 1e8 the
reflectance is 1 to 1e-8, and the clamp keeps every square inside float64
(1e8 squared twice is 1e32), so a finite input never gives inf / inf = NaN."""

_ETA_I_RULE = f"[{ETA_I_MIN:g}, {ETA_I_MAX:g}]"


def as_float_array(name: str, values) -> np.ndarray:
    """
    ``values`` as a float64 array, as the physics kernels take their input:
    refuses what is not numbers, and keeps NaN and infinity (a kernel
    documents what they give; the boundaries refuse them).
    """
    try:
        return np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be numbers, got {values!r:.60}") from None


def as_finite_array(name: str, values) -> np.ndarray:
    """``values`` as a float64 array; refuses non-numbers, NaN and infinity."""
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be numbers, got {values!r:.60}") from None
    if not np.all(np.isfinite(array)):
        bad = array[~np.isfinite(array)].ravel()[0]
        raise ValueError(f"`{name}` must be finite, got {bad}")
    return array


def check_eta_i(value: Any, name: str = "eta_i") -> float:
    """
    One coating index in [:data:`ETA_I_MIN`, :data:`ETA_I_MAX`], as a float.
    (JSON readers that accept numbers only check the type first.)
    """
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a number, got {value!r}") from None
    if not (math.isfinite(x) and ETA_I_MIN <= x <= ETA_I_MAX):
        raise ValueError(f"`{name}` must lie in {_ETA_I_RULE}, got {x:g}")
    return x


def check_eta_i_range(eta_i_range) -> tuple[float, float]:
    """Validate ``eta_i_range`` = (lo, hi) with 1 <= lo <= hi <= 3."""
    try:
        lo, hi = (float(v) for v in eta_i_range)
    except (TypeError, ValueError):
        raise ValueError(f"`eta_i_range` must be two numbers [lo, hi], got {eta_i_range!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise ValueError(f"`eta_i_range` must be finite, got [{lo}, {hi}]")
    if not (ETA_I_MIN <= lo <= hi <= ETA_I_MAX):
        raise ValueError(f"`eta_i_range` must satisfy {ETA_I_MIN:g} <= lo <= hi <= {ETA_I_MAX:g}, got [{lo:g}, {hi:g}]")
    return lo, hi


def cos_theta_from_angle(angle_deg) -> np.ndarray:
    """
    :math:`\\mu = \\cos\\theta` of angles theta in degrees, in [0, 1].

    The one rule: grazing (90 degrees) is exactly 0, although
    ``cos(radians(90))`` is 6e-17 in floating point, and angles past the
    ends of [0, 90] are held at 1 or 0 (callers validate their inputs).
    """
    angle = np.asarray(angle_deg, dtype=np.float64)
    return np.clip(np.where(angle >= 90.0, 0.0, np.cos(np.radians(angle))), 0.0, 1.0)


def check_int(name: str, value: Any, lo: int, hi: int | None = None) -> int:
    """An ``int`` in [lo, hi] (hi None: no upper limit; lo = 1: "positive")."""
    if isinstance(value, int) and not isinstance(value, bool) and lo <= value and (hi is None or value <= hi):
        return value
    if hi is None:
        rule = "a positive integer" if lo == 1 else f"an integer >= {lo}"
    else:
        rule = f"an integer in [{lo}, {hi}]"
    raise ValueError(f"`{name}` must be {rule}, got {value!r}")


def check_choice(name: str, value: Any, choices) -> Any:
    """One of ``choices``."""
    if value not in choices:
        raise ValueError(f"`{name}` must be one of {', '.join(choices)}, got {value!r}")
    return value


def check_number(name: str, value: Any, lo: float, hi: float | None = None) -> float:
    """
    A finite real number (int or float) in [lo, hi]; with ``hi`` None, > lo
    (the "finite number > 0" rule for lo = 0).
    """
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)
    if hi is None:
        if ok and value > lo:
            return float(value)
        raise ValueError(f"`{name}` must be a finite number > {lo:g}, got {value!r}")
    if ok and lo <= value <= hi:
        return float(value)
    raise ValueError(f"`{name}` must be a number in [{lo:g}, {hi:g}], got {value!r}")


def check_min_coverage(value: Any) -> float:
    """The least covered fraction of the visible range, in [0, 1]."""
    if not 0.0 <= float(value) <= 1.0:
        raise ValueError(f"`min_coverage` must lie in [0, 1], got {value!r}")
    return float(value)


def check_step_nm(value: Any) -> float:
    """A spectral step in nm within :data:`STEP_NM_LIMITS`."""
    step = float(value)
    lo, hi = STEP_NM_LIMITS
    if not (np.isfinite(step) and lo <= step <= hi):
        raise ValueError(f"`step_nm` must lie in [{lo:g}, {hi:g}], got {value!r}")
    return step


def constants() -> dict[str, Any]:
    """The domain's constants as JSON, for clients that must not repeat them."""
    return {
        "eta_i_min": ETA_I_MIN,
        "eta_i_max": ETA_I_MAX,
        "default_eta_i_range": list(DEFAULT_ETA_I_RANGE),
        "visible_range_nm": list(VISIBLE_RANGE_NM),
        "default_min_coverage": DEFAULT_MIN_COVERAGE,
        "step_nm_limits": list(STEP_NM_LIMITS),
        "angle_limits_deg": list(ANGLE_LIMITS_DEG),
    }


class _Flight:
    """One build in progress: those who asked for the same key meanwhile wait for it."""

    def __init__(self) -> None:
        self.done = threading.Event()
        self.value: Any = None
        self.error: BaseException | None = None


class BoundedCache:
    """
    The ``size`` most recently used values by key, safe across threads:
    :meth:`get` returns the value of ``key``, built by ``build()`` (outside
    the lock, so one slow build blocks no other key) when it is not kept,
    the least recently used dropped beyond ``size``. One flight per key:
    concurrent gets of a key not yet kept share one build (the others wait
    for it, and get its exception if it fails; a later get builds again).
    """

    def __init__(self, size: int) -> None:
        self.size = check_int("size", size, 1)
        self._values: OrderedDict[Hashable, Any] = OrderedDict()
        self._flights: dict[Hashable, _Flight] = {}
        self._lock = threading.Lock()

    def get(self, key: Hashable, build: Callable[[], Any]) -> Any:
        with self._lock:
            if key in self._values:
                self._values.move_to_end(key)
                return self._values[key]
            flight = self._flights.get(key)
            leader = flight is None
            if leader:
                flight = self._flights[key] = _Flight()
        if not leader:
            flight.done.wait()
            if flight.error is not None:
                raise flight.error
            return flight.value
        try:
            flight.value = build()
        except BaseException as error:
            flight.error = error
            raise
        finally:
            with self._lock:
                del self._flights[key]
                if flight.error is None:
                    self._values[key] = flight.value
                    while len(self._values) > self.size:
                        self._values.popitem(last=False)
            flight.done.set()
        return flight.value


def cached_once(function: Callable[[], Any]) -> Callable[[], Any]:
    """``function`` (no arguments) computed once per process, by one caller however many ask at once."""
    cache = BoundedCache(1)

    def once() -> Any:
        return cache.get(None, function)

    once.__wrapped__ = function  # type: ignore[attr-defined]
    once.__doc__, once.__name__ = function.__doc__, function.__name__
    return once
