"""
Curves of a metal given by colours
==================================

Request :class:`ColourCurvesRequest`, response :class:`ColourCurves`:
the editor's colour controls (a base colour and an edge tint) turned into
the reflectance curves its edits hold.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from fitting.fits.curves_input import CURVE_MAX_COUNT, CURVE_MAX_SAMPLES

from .common import EtaI, RequestModel, WorkingSpace
from .fits import RGBColour

__all__ = ["ColourCurvesRequest", "ColourCurve", "ColourCurves"]


class ColourCurvesRequest(RequestModel):
    """
    A metal given by its F0 (base colour) and F82 tint (edge tint), linear
    colours of ``space``, as seen from a medium of index ``seen_at`` (1: in
    air; the coat's index: under the coat), and the coating indices
    ``eta_i`` to give its curves at.
    """

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {
                    "f0": [0.944, 0.776, 0.373],
                    "f82": [0.93, 0.96, 0.99],
                    "space": "lin_rec709",
                    "seen_at": 1.0,
                    "eta_i": [1.0, 1.5, 2.0, 2.5],
                    "samples": 46,
                },
            ]
        },
    )

    f0: RGBColour = Field(description="F0 (OpenPBR base_color), linear, [0, 1] per channel of `space`")
    f82: RGBColour = Field(description="F82 tint (OpenPBR specular_color), linear, [0, 1] per channel")
    space: WorkingSpace = Field("lin_rec709", description="lin_rec709 | acescg: the space of `f0`, `f82`")
    seen_at: EtaI = Field(
        1.0,
        description="Index of the medium the colours are seen from: 1 in air, "
        "the coat's index for colours seen under the coat",
    )
    eta_i: list[EtaI] = Field(
        min_length=1, max_length=CURVE_MAX_COUNT, description="Coating indices to give the curves at"
    )
    samples: int = Field(46, ge=2, le=CURVE_MAX_SAMPLES, description="Angles evenly from 0 to 90 degrees")


class ColourCurve(BaseModel):
    eta_i: float
    rgb: list[list[float]] = Field(description="Linear ACEScg reflectance per angle")


class ColourCurves(BaseModel):
    """The metal's curves (exact Fresnel of its per-channel index) and the index."""

    theta_deg: list[float]
    curves: list[ColourCurve]
    n: list[float] = Field(description="Real index per ACEScg channel, in air")
    k: list[float] = Field(description="Imaginary index per ACEScg channel, in air")
    reachable: list[bool] = Field(
        description="Per ACEScg channel, whether a conductor reaches the F82 tint (else the nearest one is taken)"
    )
    F82_error: list[float] = Field(description="Per ACEScg channel, the tint reached minus the one asked for")
