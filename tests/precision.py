"""
Named precision bounds the tests share (every numeric tolerance is
derived or is a documented promise). Import as ``from precision import ...``
(``tests/`` is on ``sys.path``: the root conftest lives there).

Each bound says how it is derived; a test that uses one adds its own factors
in a comment next to the assertion. The derivations assume only IEEE 754
correctly rounded +, -, *, /, sqrt (the same on every CPU and SIMD width),
numpy's transcendental functions (exp, log, sin, cos, pow, arctan, cbrt)
within 4 ulps on every SIMD target, and sums whose order numpy's pairwise
SIMD summation or the BLAS kernel (OpenBLAS's core type) chooses: a sum of L
terms is bounded by L u sum|terms| in any order.
"""

from __future__ import annotations

import numpy as np

from fitting.colour import reference as _reference

U64 = 2.0**-53  # float64 unit roundoff
U32 = 2.0**-24  # float32 unit roundoff
# float16 (10-bit significand): a value in [2^e, 2^(e+1)) rounds to nearest
# with error at most 2^(e-11); relative to the value, at most 2^-11.

# The 1 nm spectral weights (471 nodes): each channel's sum of |w| (1.147).
_NODES, _W = _reference.spectral_weights(1.0)
SPECTRAL_NODES = _NODES.size
SUM_ABS_W = float(np.abs(_W).sum(axis=1).max())
# The float64 reference against itself by another path (the complex form,
# the product grid, another loop order): 2 (50 + L) u64 sum|w| = 1.3e-13 per
# channel (tests/fitting/colour/test_reference_grid.py has the derivation).
F64_RGB_BOUND = 2 * (50 + SPECTRAL_NODES) * U64 * SUM_ABS_W
# Any closed form of <= ~16 float64 operations on values in [0, 1] (each
# within 4 ulps at worst: pow, exp), no cancelling difference: 64 u64.
F64_FEW_OPS = 64 * U64

# The user's promise for Delta E (docs/service.md): within 0.001 of the
# 1 nm / 100 x 100 definition.
DELTA_E_PROMISE = 1e-3

# GLSL in float32 (llvmpipe here, SwiftShader in the browser tests) against
# numpy's float64 at the same float32 inputs. GLSL ES 3.00 section 4.5.1
# (highp): +, -, * correctly rounded (llvmpipe contracts a * b + c into one
# FMA or not, by the host CPU: either is within the count below), / and
# inversesqrt within 2.5 ulps, exp2 and log2 within 3 ulps (log2 within
# 2^-21 absolute on [0.5, 2]), pow(x, y) inherited from exp2(y log2 x). For a
# term c x^y with x in [0, 1] that is an absolute error of at most
# |c| x^y (3 u32 + |y| 2^-21 ln 2 + 3 u32 |y log2 x|), and x^y |y ln x| <= 1/e.
# The coated-conductor model: ~30 roundings of terms <= 2 (30 * 2 u32 =
# 3.6e-6); Schlick's (1 - mu)^5 (|c| <= 1): 5 * 3.3e-7 + 6 u32 = 2.0e-6;
# the a mu (1 - mu)^alpha term (|a| <= 4, any alpha): 4 (6 u32 + 1/e 3.3e-7
# + ...) <= 2e-6. In all <= 7.6e-6 <= 1e-5 (absolute below 1, relative
# above, as each test states).
GLSL_F32_BOUND = 1.0e-5
