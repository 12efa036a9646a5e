"""
Jobs
====

One module per kind of fit; each validates its input once, gives it an id
(:func:`service.jobs.common.content_address`), runs the CPU work in the
fitting pool (:mod:`service.runtime.pool`) and saves what it made:

-   :mod:`service.jobs.nk`: fits of measured n, k (a built-in material,
    inline data, an upload), and the curves of a stored fit for plotting.
-   :mod:`service.jobs.curves`: fits of edited RGB curves, and the error map
    of any stored fit against what it was fitted to.
-   :mod:`service.jobs.scenes`: scene packs (each material over the eta_i it
    uses, with the kind and degree its rule picks).

They raise ``ValueError`` for bad input and ``LookupError`` for something
not stored; the HTTP edge (:mod:`service.api.errors`) maps them to 422 and
404.
"""
