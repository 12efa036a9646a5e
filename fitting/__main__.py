"""``python -m fitting``: see :mod:`fitting.cli.main`."""

import sys

from .cli.main import main

sys.exit(main())
