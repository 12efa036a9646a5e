"""
Packs
=====

``POST /api/v1/packs``: several stored fits in one download (a scene's
materials together), in any pack format, or their exports for one coating
index as a zip archive (any registered export format). Saves nothing, but
may cost seconds of fitting per request, so it needs what writes need
(:data:`service.api.deps.WriteAccess`: same site, and the bearer token when
the service requires one).
"""

from fastapi import APIRouter, Request, Response, status
from fastapi.concurrency import run_in_threadpool

from ...downloads import PACK_CONTENT, is_export, pack_response, render_export_pack
from ...jobs.common import stored_fit
from ...jobs.evaluation import ensure_metrics
from ...schemas import API_PREFIX, PackRequest
from ..deps import FIT_ERROR_RESPONSES, NOT_FOUND, RunnerDep, StoreDep, WriteAccess

router = APIRouter(prefix=f"{API_PREFIX}/packs", tags=["packs"])


@router.post(
    "",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {"content": PACK_CONTENT, "description": "The pack"},
        **NOT_FOUND,
        **FIT_ERROR_RESPONSES,
    },
    dependencies=[WriteAccess],
)
async def create_pack(request: PackRequest, store: StoreDep, runner: RunnerDep, http: Request) -> Response:
    """
    The fits named by ``fit_ids``, in that order, as one pack. A renderer
    looks materials up by name, so names in a pack are unique: two fits of
    the same name are refused (422) rather than shipped ambiguously.
    """
    records = await run_in_threadpool(_records, store, request.fit_ids)
    if is_export(request.format):
        # Each export fits its tool's values (up to about a second of CPU): a job in the
        # fitting pool, with its CPU limit and timeout, shared by identical requests, and
        # kept (the fits never change).
        key = (
            f"export pack {request.format} {request.eta_i!r} {request.roughness!r} "
            f"{request.coat_roughness!r} {request.working_space} {' '.join(r.id for r in records)}"
        )
        body = await http.app.state.derived.get_or_make(
            key,
            lambda: runner.once(
                key,
                lambda: runner.run(
                    render_export_pack,
                    records,
                    request.format,
                    request.eta_i,
                    request.roughness,
                    request.coat_roughness,
                    request.working_space,
                    cost_s=float(len(records)),
                ),
            ),
        )
        return Response(
            body,
            media_type="application/zip",
            headers={
                "Content-Disposition": f'attachment; filename="{request.name}-{request.format}-eta{request.eta_i:g}.zip"'
            },
        )
    if request.format != "binary":  # the JSON and the snippets quote the figures
        records = [await ensure_metrics(record, store, runner) for record in records]
    return await run_in_threadpool(pack_response, records, request.format, request.name)


def _records(store, fit_ids: list[str]) -> list:
    """The stored fits of ``fit_ids`` (404 naming the index of one not stored); 422 for a repeated name."""
    records, names = [], {}
    for index, fit_id in enumerate(fit_ids):
        record = stored_fit(store, fit_id, f"fit_ids[{index}]")
        if record.name in names:
            raise ValueError(
                f"`fit_ids[{index}]` is named {record.name!r} like `fit_ids[{names[record.name]}]`: "
                "names in a pack must be unique"
            )
        names[record.name] = index
        records.append(record)
    return records
