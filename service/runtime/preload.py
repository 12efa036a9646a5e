"""
What the fork server (:func:`service.runtime.worker.process_context`) imports once,
before it forks the fitting and render processes, so that each of them
starts with it: the fitting core, colour-science through
:func:`fitting.colour.colorimetry.colour_science` (its plotting package, and
matplotlib with it, load only on use; a plain ``import colour`` here loaded
both in every fork server), scipy's least squares, the downloads' jobs
(:mod:`service.downloads`: the exports and their writers, about 0.13 s of
imports that landed on each worker's first export), and the warm-up
(:func:`service.runtime.worker.warm_process`: the spectral weights of the fit and of
the metrics), whose caches every forked process inherits.
"""

from __future__ import annotations

import scipy.optimize  # noqa: F401 (imported for the processes forked from here)

import fitting
import service.downloads  # noqa: F401 (the export jobs' module: fitting.exports and the writers)
from fitting.colour.colorimetry import colour_science
from service.runtime.worker import warm_process

for _name in fitting.__all__:  # the core's public modules (``import fitting`` loads each on first use)
    getattr(fitting, _name)
colour_science()
warm_process()
