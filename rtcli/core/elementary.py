"""The elementary functions of the kernels: x ** y, sin, cos, arcsin, arccos, arctan2, cbrt.

rtcli computes them itself, from IEEE arithmetic, sqrt, floor, frexp and ldexp alone:
operations that every CPU and every library rounds the same way. The numpy and the scalar
variants of each kernel (rtcli/kernels/variants.py) then give the same bits, and so do CPUs of
every kind. numpy's own power, arccos, arcsin, arctan2 and cbrt come from Intel's SVML on
CPUs with AVX-512 and from the C library elsewhere, and the two differ in the last bit now
and then: enough to tip a pixel from one 8-bit value to the next (docs/architecture.md,
Same pixels on every CPU).

Each function is the textbook method: a reduction to a small interval, a Taylor series
there (its coefficients are exact fractions, each rounded once), and the reduction undone.
Where a result is sensitive to one rounding (the logarithm inside x ** y, whose error the
exponent multiplies) a product or a sum is carried in two doubles, as Dekker and Knuth
showed, without a fused multiply-add. Measured against the exact values (tests/
test_elementary.py): power, sin, cos and cbrt within 1 ulp (unit in the last place),
arctan2 within 2, arcsin and arccos within 3; the C library's are within 1, its cbrt 3.
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext

import numpy as np

from rtcli.kernels.variants import (
    INF,
    copysign,
    floor,
    frexp,
    isfinite,
    isnan,
    kernel,
    ldexp,
    maximum,
    minimum,
    not_,
    select,
    sqrt,
    to_int,
)

NAN = math.nan


def _parts(value: Decimal, bits: int, count: int) -> tuple[float, ...]:
    """A constant as a sum of `count` doubles: each but the last holds the next `bits` significant
    bits (so it times an integer of up to 53 - bits bits is exact), the last the rest, rounded."""
    parts = []
    for _ in range(count - 1):
        exponent = math.frexp(float(value))[1]
        parts.append(math.ldexp(math.floor(math.ldexp(float(value), bits - exponent)), exponent - bits))
        value -= Decimal(parts[-1])
    return (*parts, float(value))


with localcontext() as _digits:
    _digits.prec = 80
    _PI = Decimal("3.14159265358979323846264338327950288419716939937510582097494459230781640628620899")
    _LN2 = Decimal("0.693147180559945309417232121458176568075500134360255254120680009493393621969694715")
    LN2_HI, LN2_LO = _parts(_LN2, 32, 2)                 # k LN2_HI is exact for |k| < 2^21
    PIO4_HI, PIO4_LO = _parts(_PI / 4, 50, 2)           # n PIO4_HI is exact for n <= 4
    PIO2_1, PIO2_2, PIO2_3 = _parts(_PI / 2, 33, 3)     # n PIO2_1 and n PIO2_2 exact for |n| < 2^20
    INVC = np.array([float(1 / (Decimal(3) / 4 + Decimal(j) / 128)) for j in range(97)])  # 1/c, rounded
    LOGC_HI, LOGC_LO = (np.array(part) for part in zip(*(_parts(-Decimal(i).ln(), 53, 2) for i in INVC)))
INV_LN2, TWO_OVER_PI = 1 / math.log(2), 2 / math.pi
TAN_PI_8 = math.sqrt(2) - 1
SPLIT = 134217729.0                            # 2^27 + 1: splits a double into halves of 26 bits

EXP = tuple(1 / math.factorial(k) for k in range(13, -1, -1))                # e^r, r^13/13! .. 1
LOG1P = tuple((-1) ** (k + 1) / k for k in range(10, 1, -1))              # ln(1 + r) = r + r^2 (..)
ATAN = tuple((-1) ** k / (2 * k + 1) for k in range(20, 0, -1))            # atan(w) = w + w^3 (..)
SIN = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(8, 0, -1))  # sin(r) = r + r^3 (..)
COS = tuple((-1) ** k / math.factorial(2 * k) for k in range(8, 0, -1))      # cos(r) = 1 + r^2 (..)


# --- exact sums and products, and polynomials ---
@kernel
def two_sum(a, b):
    """a + b = s + e exactly (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@kernel
def two_prod(a, b):
    """a b = p + e exactly (Dekker: each factor split into halves of 26 bits), for |a|, |b| < 2^995."""
    p = a * b
    ca, cb = SPLIT * a, SPLIT * b
    a_hi, b_hi = ca - (ca - a), cb - (cb - b)
    a_lo, b_lo = a - a_hi, b - b_hi
    return p, ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo


@kernel
def horner(coefficients, u):
    """c0 u^(n-1) + ... + c(n-1) for the coefficients c0, c1, ... (highest power first)."""
    p = coefficients[0]
    for c in coefficients[1:]:
        p = p * u + c
    return p


# --- x ** y = e^(y ln x) ---
@kernel
def log_parts(x):
    """ln x = hi + lo for finite x > 0, to about 2^-63 of it. x = m 2^k with m in [3/4, 3/2), c the
    nearest of the points 3/4 + j/128 and 1/c rounded to INVC[j]: ln x = k ln 2 + ln(1/INVC[j])
    + ln(1 + r), where 1 + r = m INVC[j] exactly (two parts), |r| < 1/190, and ln(1 + r) is its
    series. k ln 2 and the table's logarithms are carried in two parts."""
    m, e = frexp(x)
    low = m < 0.75
    m = select(low, 2 * m, m)
    k = e - select(low, 1.0, 0.0)
    j = floor((m - 0.75) * 128 + 0.5)
    j = to_int(minimum(select(j > 0, j, 0.0), 96.0))   # in the table whatever x is
    r, r_lo = two_prod(m, INVC[j])
    r = r - 1.0                                          # exact
    hi, lo = two_sum(k * LN2_HI, LOGC_HI[j])             # k LN2_HI is exact
    hi, lo_r = two_sum(hi, r)
    small = k * LN2_LO + LOGC_LO[j] + (r_lo - r * r_lo + r * r * horner(LOG1P, r))
    return two_sum(hi, lo + lo_r + small)


@kernel
def exp_parts(t, t_lo):
    """e^(t + t_lo), |t_lo| << |t|: t = n ln 2 + r, |r| <= ln 2 / 2, e^t = 2^n e^r."""
    tc = minimum(maximum(t, -1500.0), 1500.0)            # beyond, e^t is 0 or inf all the same
    n = floor(tc * INV_LN2 + 0.5)
    n = select(isfinite(n), n, 0.0)
    r = (tc - n * LN2_HI) + (select(tc == t, t_lo, 0.0) - n * LN2_LO)
    return ldexp(horner(EXP, r), to_int(n))


@kernel
def power(x, y):
    """x ** y, with IEEE's pow's special cases: 1 when y == 0 or x == 1, nan for finite x < 0 and
    y not whole, the sign of x for odd y."""
    ax = abs(x)
    yc = minimum(maximum(y, -1e19), 1e19)                # beyond, x ** y is 0 or inf for any x != 1
    hi, lo = log_parts(ax)
    t, t_lo = two_prod(yc, hi)
    value = exp_parts(t, t_lo + yc * lo)
    value = select(ax == 0, select(y > 0, 0.0, INF), value)
    value = select(ax == INF, select(y > 0, INF, 0.0), value)
    whole = floor(y) == y
    odd = whole & (floor(y / 2) * 2 != y) & (abs(y) < 9007199254740992.0)     # below 2^53
    value = select(odd & (copysign(1.0, x) < 0), -value, value)
    value = select((x < 0) & not_(whole) & (ax != INF), NAN, value)
    return select((y == 0) | (x == 1), 1.0, select(isnan(x) | isnan(y), NAN, value))


# --- arctan2, arcsin, arccos ---
@kernel
def atan_unit(z):
    """atan(z) = c pi/4 + a for 0 <= z <= 1: (c, a) = (0, atan z), or above tan(pi/8)
    (1, atan((z - 1) / (z + 1)))."""
    big = z > TAN_PI_8
    w = select(big, (z - 1) / (z + 1), z)
    u = w * w
    return select(big, 1.0, 0.0), w + w * u * horner(ATAN, u)


@kernel
def arctan2(y, x):
    """The angle of the point (x, y) from the +x axis, in [-pi, pi], with IEEE's atan2's signs of
    zero. From z = the smaller of |x|, |y| over the larger, it is n pi/4 +- atan z, n a whole number
    (pi/4 in two parts: n pi/4 is rounded once, at the end)."""
    ax, ay = abs(x), abs(y)
    steep = ay > ax
    num, den = select(steep, ax, ay), select(steep, ay, ax)
    z = select(den == 0, 0.0, num / den)
    z = select((ax == INF) & (ay == INF), 1.0, z)
    c, a = atan_unit(z)
    back = copysign(1.0, x) < 0
    n = select(steep, select(back, 2 + c, 2 - c), select(back, 4 - c, c))
    a = select(steep != back, -a, a)
    angle = n * PIO4_HI + (n * PIO4_LO + a)
    return select(isnan(x) | isnan(y), NAN, copysign(angle, y))


@kernel
def one_minus_square(x):
    """1 - x^2 rounded once: x^2 in two parts (exact), 1 - its high part exact for |x| >= 1/sqrt(2)."""
    p, e = two_prod(x, x)
    return (1.0 - p) - e


@kernel
def arcsin(x):
    """arcsin x = atan2(x, sqrt(1 - x^2)); nan outside [-1, 1]."""
    return arctan2(x, sqrt(one_minus_square(x)))


@kernel
def arccos(x):
    """arccos x = atan2(sqrt(1 - x^2), x), in [0, pi]; nan outside [-1, 1]."""
    return arctan2(sqrt(one_minus_square(x)), x)


# --- sin and cos ---
@kernel
def quadrant(x):
    """x = n pi/2 + r + r_lo, |r| <= pi/4: (r, r_lo, n mod 4). pi/2 in three parts of 33 bits, so
    that n times each is exact for |x| < 2^20, and r in two. Beyond 2^20 r is meaningless (rtcli's
    angles are in degrees, taken modulo 360 first)."""
    n = floor(x * TWO_OVER_PI + 0.5)
    r, r_lo = two_sum(x - n * PIO2_1, -(n * PIO2_2))     # x - n PIO2_1 is exact
    r, r_lo = two_sum(r, r_lo - n * PIO2_3)
    return r, r_lo, n - 4 * floor(n / 4)


@kernel
def sin_cos_reduced(r, r_lo):
    """(sin, cos) of r + r_lo, |r| <= pi/4, |r_lo| <= ulp(r) / 2: their series at r, and r_lo's
    first-order terms."""
    u = r * r
    s = r + (r_lo + r * u * horner(SIN, u))
    c = 1.0 + (u * horner(COS, u) - r * r_lo)
    return s, c


@kernel
def cos(x):
    """cos x, to 1 ulp for |x| < 2^20 (reduced by pi/2)."""
    r, r_lo, q = quadrant(x)
    s, c = sin_cos_reduced(r, r_lo)
    return select(q == 0, c, select(q == 1, -s, select(q == 2, -c, s)))


@kernel
def sin(x):
    """sin x, to 1 ulp for |x| < 2^20 (reduced by pi/2); x itself below 2^-27, where sin x rounds
    to x (so zeros keep their signs)."""
    r, r_lo, q = quadrant(x)
    s, c = sin_cos_reduced(r, r_lo)
    return select(abs(x) < 7.450580596923828e-09, x, select(q == 0, s, select(q == 1, c, select(q == 2, -s, -c))))


# --- cbrt ---
@kernel
def cbrt(x):
    """The real cube root: |x| = a 2^3q with a in [1/2, 4), its root by Halley's iteration from a
    straight line, then one Newton step on the exact residual, times 2^q."""
    m, e = frexp(abs(x))
    q = floor(e / 3)
    a = ldexp(m, to_int(e - 3 * q))                     # in [0.5, 4)
    y = 0.6803 + 0.2268 * a                               # the line through (1/2, 2^-1/3) and (4, 4^1/3)
    for _ in range(3):
        y3 = y * y * y
        y = y * (y3 + 2 * a) / (2 * y3 + a)                # Halley: the error cubed each time
    yy, yy_lo = two_prod(y, y)
    y3, y3_lo = two_prod(yy, y)
    y = y - ((y3 - a) + (y3_lo + yy_lo * y)) / (3 * yy)   # Newton, on y^3 - a to the last bit
    q = select(isfinite(q), q, 0.0)
    root = copysign(ldexp(y, to_int(q)), x)
    return select(isfinite(x) & (x != 0), root, x)
