"""
Health and domain
=================

:class:`Health` (``GET /healthz``) and :class:`Domain` (``GET
/api/v1/domain``: the limits and defaults clients need, from the core's
constants, so that no client repeats them).
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, Field

__all__ = ["Health", "Domain", "ExportFormatPublic", "ModelKindPublic"]


class Health(BaseModel):
    status: Literal["ok"]
    fits_in_flight: int
    fit_workers: int
    max_in_flight: int
    store_writable: bool = Field(description="Whether a save can be written now")
    store_problem: str | None = Field(None, description="Why not, when it cannot")
    pool_restarts: int = Field(0, description="Times a dead worker made the pool restart")
    previews_in_flight: int = Field(
        0, description=("Previews rendering now in the render pool (at most COATED_MAX_PREVIEWS_IN_FLIGHT)")
    )
    store: dict[str, Any] = Field(
        default_factory=dict,
        description=(
            "The store: `kind` (sqlite | postgresql), `schema_version`, its `path` or password-free "
            "`url`, and for PostgreSQL this replica's pool: `connections` open, `connections_max`, "
            "`connections_idle`, `requests_waiting`, the role's `role_connection_limit` (-1: none) and "
            "the server's `server_connection_limit` (max_connections less the superusers' reserve)"
        ),
    )


class ExportFormatPublic(BaseModel):
    """One registered export format (:class:`fitting.exports.formats.ExportFormat`)."""

    name: str = Field(description="The `format` of a download")
    label: str = Field(description="What a menu shows, with the file extension")
    media_type: str
    extension: str = Field(description="The file name's suffix, without the leading dot")
    options: list[str] = Field(description="The query parameters it takes (eta_i, roughness, coat_roughness)")


class ModelKindPublic(BaseModel):
    """One registered model kind (:class:`fitting.models.kinds.ModelKind`), as a browser draws it."""

    name: str = Field(description="The `model` of a fit")
    description: str
    parameters: list[str] = Field(description="The keys of a fit's `coefficients`, each one row per channel R, G, B")
    max_degree: int = Field(
        description="0: each row is one number; above: each row is a polynomial in t of 1 to max_degree + 1 numbers"
    )
    split_sum: bool = Field(
        description="Whether the kind's rough lobe has the split-sum lookup (`cf_ibl`); "
        "otherwise its albedo is integrated from `glsl`'s Fresnel"
    )
    glsl: str = Field(
        description="GLSL of `cf_preview_model.glsl`: `vec3 cf_preview_model(float NdotV, "
        "float eta_i, vec2 eta_i_range, uint words[14])`, the kind's reflectance from "
        "its float16 coefficients two per word (parameter by parameter, channel R, G, "
        "B, then power); its `#include` lines name files served under /glsl/"
    )
    live_solver: str | None = Field(
        default=None,
        description="The editor's own solver of the kind's live step "
        "(`polynomial`, `exact-fresnel`), or null: the editor asks the service's",
    )


class Domain(BaseModel):
    """The rules a client checks before sending (the service checks them again)."""

    eta_i_limits: list[float] = Field(min_length=2, max_length=2, description="Every coating index lies in [lo, hi]")
    default_eta_i_range: list[float] = Field(min_length=2, max_length=2, description="The default fitted domain")
    objectives: list[str]
    default_objective: str
    library: list[str] = Field(description="The built-in conductors")
    pack_formats: list[str]
    export_formats: list[ExportFormatPublic] = Field(description="Every export format, in menu order")
    model_kinds: list[ModelKindPublic] = Field(description="Every model kind, in registry order")
    default_model: str = Field(description="The kind of a fit that names none")
    curve_samples: list[int] = Field(min_length=2, max_length=2, description="Samples per edited curve, [min, max]")
    max_curves: int
    max_nk_samples: int
    visible_range_nm: list[float] = Field(
        min_length=2, max_length=2, description="The range the colour integrates over, nm"
    )
    min_coverage: float = Field(
        description="The least fraction of `visible_range_nm` an n, k must cover "
        "(an upload's `min_coverage` may ask for more)"
    )
    draft_ttl_s: float | None = Field(
        None,
        description="How long an unsaved edit's refit (a draft) and a "
        "link to it are kept, seconds (COATED_DRAFT_TTL_S)",
    )
