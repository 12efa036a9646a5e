"""
Fits
====

From reflectance data to the float16 coefficients of a model kind (layer 4).
"""
