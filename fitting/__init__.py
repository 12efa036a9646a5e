"""
fitting: measured n, k of a conductor to a float16 RGB Fresnel model
====================================================================

The scientific core of the coated-metals authoring service: optical constants,
the exact spectral Fresnel reference in linear ACEScg, the coated-conductor
model of Vernooij (2024, Eq. 1 and 2), its fit, the baselines, the metrics and
the float16 coefficient pack.
"""
