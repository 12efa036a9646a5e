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
"""

from __future__ import annotations

from typing import Any

from ..models.range_bound import certify_range

__all__ = ["fit_quality", "out_of_range_message", "provenance", "in_range_verdict"]


def out_of_range_message(range_report: dict[str, Any]) -> str:
    """The words of a model not proven in [0, 1] (``range_report``: :meth:`RangeCertificate.to_dict`)."""
    worst = range_report["worst"]
    if range_report["in_range"] is False:
        return (f"the model leaves [0, 1]: {worst['value']:.4f} in {worst['channel']} at "
                f"cos theta {worst['cos_theta']:.4g}, eta_i {worst['eta_i']:.4g}")
    return (f"the model is not proven inside [0, 1] (bounds {range_report['proven_min']:.4f} to "
            f"{range_report['proven_max']:.4f})")


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
