"""
What a fit can be trusted for
=============================

-   :func:`fit_quality`: the proof that a float16 coated-conductor model
    stays in [0, 1] over its whole domain
    (:func:`fitting.models.range_bound.certify_range`) and the warnings a
    fit carries (sparse data fitted with the gap limit relaxed,
    :func:`fitting.optics.quality.check_gaps`; a model leaving [0, 1]).
-   :func:`out_of_range_message`: the words of such a model, for warnings
    and ``--strict`` errors.
-   :func:`provenance`: the source citation with the warnings appended (the
    pack's provenance).
-   :func:`data_uncertainty`: how far a fit's figure can be off for the
    data's gaps or sparse sampling: the spread of the reference under other
    plausible interpolations of the data (splines instead of straight
    lines, each sample left out, a window as wide as the widest gap left out
    elsewhere); :func:`uncertainty_warning`: the warning when it exceeds
    the fit's own error.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from ..colour.delta_e import delta_E_map
from ..colour.reference import reference_ACEScg_grid, spectral_weights
from ..domain import VISIBLE_RANGE_NM
from ..models.kinds import model_ACEScg
from ..models.range_bound import certify_range
from ..numerics.splines import akima, cubic_spline, pchip
from ..optics.fresnel import fresnel_conductor
from ..optics.nk import SpectralNK, check_nk_range, resample_nk
from ..optics.quality import UNCERTAIN_GAP_NM, visible_gaps
from ..numerics.plain import median, union, unique

__all__ = [
    "fit_quality",
    "out_of_range_message",
    "provenance",
    "in_range_verdict",
    "SPARSE_SAMPLES",
    "data_uncertainty",
    "uncertainty_warning",
]

SPARSE_SAMPLES = 12
"""Data with fewer samples than this inside 360-830 nm (a spacing near 40 nm
or more) are sparse: their fits report an uncertainty whatever the widest gap."""

_MU = np.linspace(0.0, 1.0, 12)  # the uncertainty's grid: 12 angles x 3 eta_i over the fit's domain
_MOST_LEFT_OUT = 40  # samples left out one at a time, evenly chosen, at most
_WINDOW_STEP_NM = 20.0  # centres of the windows left out
_LOG_FLOOR = 1e-3  # splines run through log(n), log(k + floor): positive, as n and k must be


def out_of_range_message(range_report: dict[str, Any]) -> str:
    """The words of a model not proven in [0, 1] (``range_report``: :meth:`RangeCertificate.to_dict`)."""
    worst = range_report["worst"]
    if range_report["in_range"] is False:
        return (
            f"the model leaves [0, 1]: {worst['value']:.4f} in {worst['channel']} at "
            f"cos theta {worst['cos_theta']:.4g}, eta_i {worst['eta_i']:.4g}"
        )
    return (
        f"the model is not proven inside [0, 1] (bounds {range_report['proven_min']:.4f} to "
        f"{range_report['proven_max']:.4f})"
    )


def fit_quality(coefficients_float16, eta_i_range, warnings=()) -> dict[str, Any]:
    """``{"range": certificate JSON, "warnings": [...]}`` of a coated-conductor float16 fit."""
    certificate = certify_range(coefficients_float16, eta_i_range).to_dict()
    out = list(warnings)
    if certificate["in_range"] is not True:
        out.append(out_of_range_message(certificate))
    return {"range": certificate, "warnings": out}


def in_range_verdict(quality: dict[str, Any]) -> bool:
    """Whether a fit's ``quality`` proves its model inside [0, 1] (true when not a coated-conductor fit)."""
    report = quality.get("range") if quality else None
    return report is None or report.get("in_range") is True


def provenance(source: str, quality: dict[str, Any]) -> str:
    """``source`` with the fit's warnings appended, as the pack carries it."""
    warnings = quality.get("warnings") or []
    if not warnings:
        return source
    text = (source + "; " if source else "") + "; ".join(f"warning: {w}" for w in warnings)
    return text[:4000]


def _spline_nk(nk: SpectralNK, spline) -> SpectralNK:
    """``nk`` densified to 1 nm inside the visible range by ``spline`` through log n, log(k + floor)."""
    w = nk.wavelength_nm
    lo, hi = VISIBLE_RANGE_NM
    first = max(int(np.searchsorted(w, lo, side="right")) - 3, 0)
    last = min(int(np.searchsorted(w, hi, side="left")) + 3, w.size)
    ws = w[first:last]
    dense = np.arange(np.ceil(max(ws[0], lo)), np.floor(min(ws[-1], hi)) + 1.0)
    grid = union(w, dense)
    inside = (grid >= ws[0]) & (grid <= ws[-1])
    n, k = np.interp(grid, w, nk.n), np.interp(grid, w, nk.k)
    with np.errstate(all="ignore"):
        n_s = np.exp(spline(ws, np.log(nk.n[first:last]))(grid[inside]))
        k_s = np.exp(spline(ws, np.log(nk.k[first:last] + _LOG_FLOOR))(grid[inside])) - _LOG_FLOOR
    n[inside] = np.where(np.isfinite(n_s), np.clip(n_s, 1e-6, None), n[inside])
    k[inside] = np.where(np.isfinite(k_s), np.clip(k_s, 0.0, None), k[inside])
    return SpectralNK(grid, n, k, name=nk.name)


def _spreads(nk: SpectralNK, eta: np.ndarray, base: np.ndarray, variants: list[SpectralNK]) -> np.ndarray:
    """
    The mean Delta E 2000 on (``eta``, :data:`_MU`) between the reference of
    ``nk``, ``base`` (E, M, 3), and that of each of ``variants``. A variant's reference is
    ``nk``'s plus the change of Fresnel at the 1 nm nodes where its linear
    interpolation differs (a sample or a window left out moves a few), all
    variants in one evaluation: the sums of
    :func:`fitting.colour.reference.reference_ACEScg_grid` to rounding, at
    a fraction of the cost.
    """
    nodes, W = spectral_weights(1.0)
    sampled = resample_nk(nk, nodes, 0.0)
    E, M = (g[..., None] for g in np.meshgrid(eta, _MU, indexing="ij"))
    moved = [resample_nk(v, nodes, 0.0) for v in variants]
    changed = [np.flatnonzero((v.n != sampled.n) | (v.k != sampled.k)) for v in moved]
    at = np.concatenate(changed)
    n = np.concatenate([v.n[c] for v, c in zip(moved, changed)])
    k = np.concatenate([v.k[c] for v, c in zip(moved, changed)])
    dR = (fresnel_conductor(M, E, n, k) - fresnel_conductor(M, E, sampled.n, sampled.k)[..., at]).reshape(-1, at.size)
    # Each variant's changed nodes are one run of columns: summed run by run.
    sizes = np.array([c.size for c in changed])
    moves = np.zeros((len(variants), dR.shape[0], 3))
    if at.size:
        runs = np.add.reduceat(dR[:, :, None] * W[:, at].T, np.cumsum(sizes)[sizes > 0] - sizes[sizes > 0], axis=1)
        moves[sizes > 0] = runs.transpose(1, 0, 2)
    moves = moves.reshape(len(variants), *base.shape)
    return delta_E_map(base, base + moves).reshape(len(variants), -1).mean(axis=1)


_UNCERTAINTY_KEPT: dict = {}


def data_uncertainty(nk: SpectralNK, eta_i_range, min_coverage: float) -> dict[str, Any] | None:
    """
    :func:`_data_uncertainty`, kept (a copy returned) for the last 16 data
    and domains: a scene's fits of one material over one range ask for it
    once each, and it costs more than a fit.
    """
    key = (
        nk.name,
        nk.wavelength_nm.tobytes(),
        nk.n.tobytes(),
        nk.k.tobytes(),
        tuple(float(v) for v in eta_i_range),
        float(min_coverage),
    )
    if key not in _UNCERTAINTY_KEPT:
        if len(_UNCERTAINTY_KEPT) >= 16:
            _UNCERTAINTY_KEPT.pop(next(iter(_UNCERTAINTY_KEPT)))
        _UNCERTAINTY_KEPT[key] = _data_uncertainty(nk, eta_i_range, min_coverage)
    return copy.deepcopy(_UNCERTAINTY_KEPT[key])


def _data_uncertainty(nk: SpectralNK, eta_i_range, min_coverage: float) -> dict[str, Any] | None:
    """
    How far a figure measured against ``nk`` (linearly interpolated, as the
    reference does) can be off for the data's gaps and sparse sampling;
    None for data sampled densely (widest gap inside 360-830 nm under
    :data:`fitting.optics.quality.UNCERTAIN_GAP_NM` and at least
    :data:`SPARSE_SAMPLES` samples there).

    The uncertainty is the largest mean Delta E 2000 (12 angles x 3 eta_i
    over ``eta_i_range``) between the reference of the data as given and of
    other plausible readings of them: monotone cubic (PCHIP), Akima and
    not-a-knot cubic splines through log n and log k (scipy.interpolate's, as
    :mod:`fitting.numerics.splines` builds them); each sample left out
    (at most 40, evenly chosen; a quarter of the largest move, as leaving
    one out doubles the spacing and linear interpolation's error grows
    with its square); and the median over positions of a window
    as wide as the widest gap left out where the data have samples (what a
    gap that wide hides in this metal elsewhere).
    """
    w = nk.wavelength_nm
    gaps = visible_gaps(w)
    widest = gaps[0] if gaps else (VISIBLE_RANGE_NM[0], VISIBLE_RANGE_NM[0])
    width = widest[1] - widest[0]
    lo, hi = VISIBLE_RANGE_NM
    inner = np.flatnonzero((w > lo) & (w < hi))
    if width < UNCERTAIN_GAP_NM and inner.size >= SPARSE_SAMPLES:
        return None
    eta = np.linspace(eta_i_range[0], eta_i_range[1], 3)

    # scipy.interpolate's PCHIP, Akima and not-a-knot splines, as fitting.numerics.splines builds
    # them in numpy: scipy.interpolate's import alone costs a command-line fit ~0.5 s.
    splines = [_spline_nk(nk, spline) for spline in (pchip, akima, cubic_spline)]
    left_out = []
    for i in unique(np.round(np.linspace(0, inner.size - 1, min(inner.size, _MOST_LEFT_OUT))).astype(int)):
        keep = np.ones(w.size, dtype=bool)
        keep[inner[i]] = False
        left_out.append(SpectralNK(w[keep], nk.n[keep], nk.k[keep], name=nk.name))
    windows = []
    for centre in np.arange(lo + width / 2, hi - width / 2 + 1e-9, _WINDOW_STEP_NM):
        keep = (w < centre - width / 2) | (w > centre + width / 2)
        if keep.all() or keep.sum() < 2 or (widest[0] < centre < widest[1]):
            continue
        thin = SpectralNK(w[keep], nk.n[keep], nk.k[keep], name=nk.name)
        try:
            check_nk_range(thin)  # what its reference would refuse
        except ValueError:  # the window took an end of the data past the coverage
            continue
        windows.append(thin)
    # A spline moves every node: its reference by the product-grid kernel; the others move a few.
    base = reference_ACEScg_grid(nk, _MU, eta, 1.0, 0.0)
    parts: dict[str, float] = {
        "splines": max(float(delta_E_map(base, reference_ACEScg_grid(s, _MU, eta, 1.0, 0.0)).mean()) for s in splines)
    }
    # Windows a step apart often leave out the same samples (and a window one sample): each reading once.
    variants = left_out + windows
    readings: dict[bytes, int] = {}
    which = [readings.setdefault(v.wavelength_nm.tobytes(), len(readings)) for v in variants]
    distinct = {i: v for v, i in zip(variants, which)}
    spread = _spreads(nk, eta, base, [distinct[i] for i in range(len(readings))]) if variants else np.zeros(0)
    spread = spread[np.array(which, dtype=int)]
    # Leaving a sample out doubles the spacing there; linear interpolation's
    # error grows with the spacing squared, so a quarter of that move is the
    # data's own at their spacing.
    parts["leave_one_out"] = float(spread[: len(left_out)].max(initial=0.0)) / 4.0
    spread_windows = spread[len(left_out) :]
    parts["window_left_out"] = median(spread_windows) if spread_windows.size else 0.0
    value = max(parts.values())
    return {
        "delta_E_mean": value,
        "widest_gap_nm": [float(widest[0]), float(widest[1])],
        "samples_inside_visible": int(inner.size),
        "parts": parts,
        "grid": f"{_MU.size} x {eta.size} (cos theta x eta_i over the fit's domain), 1 nm",
    }


def uncertainty_warning(
    uncertainty: dict[str, Any] | None, nk: SpectralNK, eta_i_range, kind: str, coefficients_float16
) -> tuple[float | None, str | None]:
    """
    The fit's own mean Delta E 2000 on the uncertainty's grid, and the
    warning to carry when ``uncertainty`` exceeds it (else None).
    """
    if uncertainty is None:
        return None, None
    eta = np.linspace(eta_i_range[0], eta_i_range[1], 3)
    E, M = np.meshgrid(eta, _MU, indexing="ij")
    base = reference_ACEScg_grid(nk, _MU, eta, 1.0, 0.0)
    own = float(delta_E_map(base, model_ACEScg(kind, M, E, coefficients_float16, eta_i_range)).mean())
    u = uncertainty["delta_E_mean"]
    if u <= own:
        return own, None
    a, b = uncertainty["widest_gap_nm"]
    return own, (
        f"data uncertainty: other plausible interpolations of the data (widest gap {a:g}-{b:g} nm, "
        f"{uncertainty['samples_inside_visible']} samples inside 360-830 nm) move the reference by "
        f"{u:.3f} mean Delta E 2000, more than the fit's own error {own:.3f}: the figure can be off "
        f"by that much against the real metal"
    )
