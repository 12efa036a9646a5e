"""
Shading
=======

The coated-conductor model as a renderer uses it: the GGX
microfacet BRDF in the immersed and coated set-ups
(:mod:`fitting.shading.microfacet`), the split-sum pre-integration for
image-based lighting (:mod:`fitting.shading.ibl`) and the Monte Carlo ground
truth (:mod:`fitting.shading.monte_carlo`).
"""

from .microfacet import (
    MODES,
    ROUGHNESS_MIN,
    alpha_g_from_roughness,
    coated_brdf,
    ggx_D,
    microfacet_brdf,
    model_fresnel,
    refract_into_coat,
    sample_visible_normal,
    smith_G1,
    smith_G2,
    smith_lambda,
    specular_brdf,
)

__all__ = [
    "MODES",
    "ROUGHNESS_MIN",
    "alpha_g_from_roughness",
    "coated_brdf",
    "ggx_D",
    "microfacet_brdf",
    "model_fresnel",
    "refract_into_coat",
    "sample_visible_normal",
    "smith_G1",
    "smith_G2",
    "smith_lambda",
    "specular_brdf",
]
