"""
scipy.optimize on first use
===========================

-   :func:`scipy_optimize`: ``scipy.optimize`` imported when a solve first
    needs it (the bounded and constrained solves; a coated-conductor fit
    that keeps its mean fit, and the command line's start, never pay its
    import), with a thread-pool controller made after it, whose limit
    covers scipy's own BLAS (a controller made before the import does not
    see that library).
"""

from __future__ import annotations

import functools

__all__ = ["scipy_optimize"]


@functools.cache
def scipy_optimize():
    """``(scipy.optimize, threadpoolctl.ThreadpoolController())``, both made once, on first call."""
    import scipy.optimize
    from threadpoolctl import ThreadpoolController

    return scipy.optimize, ThreadpoolController()
