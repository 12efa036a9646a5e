"""
Layer 2, colour: spectra to linear ACEScg, CIE Lab, Delta E 2000 and its
linearisation, and the exact spectral reference of a coated conductor.

-   :mod:`.colorimetry`: spectral weights, ACEScg to XYZ and Lab.
-   :mod:`.delta_e`: CIEDE2000, its first-order metric, Delta E maps.
-   :mod:`.reference`: the 1 nm (or coarser) spectral reference.
-   :mod:`.seen`: the coated metal seen from air, spectrally, in ACEScg (the
    exports' target).

Imports only the layers below (:mod:`fitting.domain`, :mod:`fitting.optics`).
"""
