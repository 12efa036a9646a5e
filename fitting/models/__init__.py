"""
Layer 3, models: the RGB Fresnel models a renderer evaluates, and their pack.

-   :mod:`.coated_conductor`: the model of Vernooij (2024), Eq. 1 and 2.
-   :mod:`.baselines`: Schlick and adjusted Lazanyi.
-   :mod:`.rgb_conductor`: the exact Fresnel equations per RGB channel.
-   :mod:`.pack`: the float16 coefficient pack, binary and JSON.

Imports only the layers below (domain, optics, colour).
"""
