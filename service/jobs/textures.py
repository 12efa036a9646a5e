"""
Reference textures
==================

-   :func:`reference_texture`: the spectral reference of a stored fit's
    measured n, k as a float32 texture over (cos theta, eta_i), with the
    headers that describe it (``GET /api/v1/fits/{fit_id}/reference-texture``,
    :mod:`service.api.routes.reference_texture`).
-   :func:`prefiltered_environment_texture`: a preview environment
    prefiltered per roughness for the split sum, as float32 equirect slices
    (``GET /api/v1/environments/{name}/prefiltered``,
    :mod:`service.api.routes.environments`);
    :func:`environment_texture`: the same in a render process of the
    render pool (:class:`service.runtime.previews.PreviewRunner`), on its renderer.
"""

from __future__ import annotations

from fitting.fits.curves_base import curve_base_from_nk
from fitting.models.baselines import baseline_inputs
from fitting.models.pack import material_from_json

from ..runtime import renderer
from ..store import FitRecord
from .common import measured_nk

__all__ = ["reference_texture", "prefiltered_environment_texture", "environment_texture"]


def reference_texture(record: FitRecord) -> tuple[bytes, dict[str, str]]:
    """The texture bytes and headers of a stored fit (ValueError without n, k)."""
    nk = measured_nk(record)
    if nk is None:
        raise ValueError(f"fit {record.id} was made from curves alone: it has no n, k to take a reference from")
    packed = material_from_json(record.material)
    base = curve_base_from_nk(nk, packed.eta_i_range)
    inputs = baseline_inputs(nk)
    body = base.RGB.astype("<f4").tobytes()
    triple = lambda v: ",".join(f"{float(x):.9g}" for x in v)  # noqa: E731
    lo, hi = base.eta_i_range
    headers = {
        "X-Texture-Width": str(base.cos_theta.size),
        "X-Texture-Height": str(base.eta_i.size),
        "X-Eta-I-Range": f"{lo:.9g},{hi:.9g}",
        "X-F0-Air": triple(inputs["F0_air"]),
        "X-F82-Air": triple(inputs["F82_air"]),
        "Cache-Control": "max-age=86400, immutable",
    }
    return body, headers


def prefiltered_environment_texture(renderer, environment: str) -> tuple[bytes, dict[str, str]]:
    """
    The slices of :func:`preview_shaders.rough.prefiltered_environment` for
    ``environment`` (one of :data:`preview_shaders.rough.ENVIRONMENTS`),
    drawn on ``renderer``'s GL thread and prefiltered once per process (and
    cached on disk), as little-endian float32 RGB ``[slice][row][column]``
    with their sizes in the headers.
    """
    from preview_shaders.rough import ENVIRONMENTS, prefiltered_environment

    data = prefiltered_environment(renderer.thread, ENVIRONMENTS.index(environment))
    nodes, height, width, _ = data.shape
    headers = {
        "X-Texture-Width": str(width),
        "X-Texture-Height": str(height),
        "X-Texture-Layers": str(nodes),
        "Cache-Control": "max-age=86400",
    }
    return data.astype("<f4").tobytes(), headers


def environment_texture(environment: str) -> tuple[bytes, dict[str, str]]:
    """Render process: :func:`prefiltered_environment_texture` on the process's own renderer."""
    return prefiltered_environment_texture(renderer(), environment)
