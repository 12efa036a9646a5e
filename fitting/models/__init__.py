"""
Models
======

Each model kind with its evaluator and its pack form (layer 3).
"""
