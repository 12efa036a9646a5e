"""``python -m fitting``: see :mod:`fitting.cli.main`."""

import gc
import sys

from .cli.main import main

status = main()
# At exit the interpreter's last collections walk every object the command made (a tenth of
# `fit Au`'s wall time, benchmarks/cli_start.py): frozen, they are left to the process's end.
# Every file the command wrote is closed by now and the standard streams are flushed at exit
# as before; nothing here needs a finaliser to run.
gc.freeze()
sys.exit(status)
