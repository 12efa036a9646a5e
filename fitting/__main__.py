"""``python -m fitting``: see :mod:`fitting.cli.main`."""

import gc
import os
import sys

# One BLAS thread unless the environment asks for more, set before numpy's import: the
# command's solves are tens of unknowns (as in the service's workers, which run one), and
# OpenBLAS's thread pool, started at the import, took about as much CPU as the import itself.
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

from .cli.main import main  # noqa: E402 (after the thread settings)

status = main()
# At exit the interpreter's last collections walk every object the command made (a tenth of
# `fit Au`'s wall time, benchmarks/cli_start.py): frozen, they are left to the process's end.
# Every file the command wrote is closed by now and the standard streams are flushed at exit
# as before; nothing here needs a finaliser to run.
gc.freeze()
sys.exit(status)
