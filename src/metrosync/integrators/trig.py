"""Branch-free sin and cos that LLVM can vectorize.

numba ≥ 0.62 no longer maps `math.sin`/`math.cos` to SIMD routines, so a loop that
calls them runs one libm call per element. `sincos` instead reduces the argument by
Cody–Waite, r = x − k·π/2 with π/2 split in three parts (the first two hold 33
significant bits, so k·part is exact for |k| < 2²⁰), and evaluates near-minimax
polynomials for sin and cos on |r| ≤ π/4 (degree 13 and 14), then picks the quadrant
with selects, not branches. Beyond `REDUCTION_LIMIT` the reduction loses
accuracy, so kernels check the largest angle of each step and fall back to libm.

The split of π/2 was computed with 300-bit arithmetic (mpmath):
π/2 = 0x1.921fb544p+0 + 0x1.0b4611a6p-34 + 0x1.3198a2e037073p-69 + O(1e-37).
"""

from __future__ import annotations

import math

import numba as nb

PIO2_1 = float.fromhex("0x1.921fb54400000p+0")
PIO2_2 = float.fromhex("0x1.0b4611a600000p-34")
PIO2_3 = float.fromhex("0x1.3198a2e037073p-69")
TWO_OVER_PI = 2.0 / math.pi
#: Largest |x| for which the three-part reduction stays exact enough (k < 2²⁰).
REDUCTION_LIMIT = 2.0**19 * math.pi

# Near-minimax polynomials in z = r² on [0, (π/4)²], fitted with 50-digit arithmetic:
#   mpmath.chebyfit(lambda z: (sin(√z) − √z)/(z√z), [0, (π/4)²], 6)   → S1…S6
#   mpmath.chebyfit(lambda z: (cos(√z) − 1 + z/2)/z², [0, (π/4)²], 6) → C2…C7
# Fit error: 1.3e-17 relative for sin, 4.9e-19 absolute for cos (below an ulp).
S1, S2, S3, S4, S5, S6 = (
    -0.16666666666666666,
    0.008333333333330948,
    -0.00019841269836758574,
    2.755731610255244e-06,
    -2.5051131845003624e-08,
    1.5918129294866608e-10,
)
C2, C3, C4, C5, C6, C7 = (
    0.041666666666666664,
    -0.0013888888888887398,
    2.480158729876569e-05,
    -2.7557317271729793e-07,
    2.08761462684032e-09,
    -1.1382632425521717e-11,
)


@nb.njit(inline="always", cache=True)
def sincos(x):
    """(sin x, cos x) for |x| ≤ REDUCTION_LIMIT, within 2 ulp of libm (measured)."""
    k = round(x * TWO_OVER_PI)
    r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3
    z = r * r
    s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))))
    c = 1.0 - 0.5 * z + z * z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * (C6 + z * C7)))))
    q = int(k) & 3
    sin_x = c if q & 1 else s
    cos_x = s if q & 1 else c
    sin_x = -sin_x if q & 2 else sin_x
    cos_x = -cos_x if (q + 1) & 2 else cos_x
    return sin_x, cos_x


@nb.njit(inline="always", cache=True)
def libm_sincos(x):
    """(sin x, cos x) from libm: the fallback beyond `REDUCTION_LIMIT`, with the same
    calling convention as `sincos` so that a kernel can pass either to one loop."""
    return math.sin(x), math.cos(x)
