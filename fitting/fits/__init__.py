"""
Layer 4, fits: from reflectance data to float16 coefficients, and their scores.

-   :mod:`.settings`: :class:`~fitting.fits.settings.FitSettings`, objectives, the fitting grid.
-   :mod:`.result`: :class:`~fitting.fits.result.FitResult`.
-   :mod:`.objective`: residuals and Jacobian of one fit (:class:`~fitting.fits.objective.Problem`).
-   :mod:`.start`: the deterministic start guess.
-   :mod:`.solver`: :func:`~fitting.fits.solver.fit_coefficients`.
-   :mod:`.quantise`: float16 coefficients that minimise the objective.
-   :mod:`.metrics`: :class:`~fitting.fits.metrics.ErrorMetrics` and Delta E scores.
-   :mod:`.material`, :mod:`.evaluate`: n, k fits and their evaluation.
-   :mod:`.curves_input`, :mod:`.curves_base`, :mod:`.curves`: fits to edited curves.
-   :mod:`.scene_schema`, :mod:`.scene_fit`, :mod:`.scene_report`: scene packs.
-   :mod:`.rgb_conductor`: per-channel n, k for the exact RGB conductor.

Imports only the layers below (domain, optics, colour, models).
"""
