"""rtcli's elementary functions (rtcli/core/elementary.py): the same bits in every variant and on
every CPU, IEEE's special cases, and their accuracy against exact values (mpmath).

numpy has two code paths for its math on x86-64: with AVX-512 it takes x ** y, arccos, arcsin,
arctan2, cbrt, tan, exp and log from Intel's SVML, otherwise from the C library, and the two
differ in the last bit. rtcli's functions use neither. A CPU without AVX-512 cannot take the
other path, so the outputs are also pinned by their SHA-256: any CPU must reproduce them.
"""

from __future__ import annotations

import hashlib
import json
import math
import os

import numpy as np
import pytest
from helpers import avx512_features, without_avx512

from rtcli.core import elementary
from rtcli.kernels import variants

FUNCTIONS = {"power": 2, "arctan2": 2, "arcsin": 1, "arccos": 1, "cbrt": 1, "cos": 1, "sin": 1}
SPECIALS = np.array([0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 3.0, -3.0, 1.5, 1e-300, 5e-324, 1e300,
                     1.7976931348623157e308, 0.9999999999, math.pi, -math.pi / 2, np.inf, -np.inf, np.nan])
# SHA-256 of each function's outputs on inputs(name): the bits every CPU must reproduce.
PINNED = {
    "power": "8dfa16b282fbfef09f11f81d83f4db202b43041240a63a81eacecf37088b9145",
    "arctan2": "4cd79b08a0a0a4e86a4113782e7014be91ec4801f3848fa9495bc40a11a0586d",
    "arcsin": "837b36921893843c02b464747a2929d8a2440580528a6dff4185c453c7b71bf2",
    "arccos": "3471b7eb3e60293ebaa87d3fc18add19cab071d1dd40284a98d09117c981c482",
    "cbrt": "b32b7e438687ca0995a8d3595da65db8ecd3fd8335c0370516c86d51cc451538",
    "cos": "77bb58a9220876350dc0fd14c48e4061b2ae5c3b99479dc299dbde81476eb965",
    "sin": "9f6ea27c0b2746b5e840b0675f88b6ce7ade70bce01f6bb960bfbbe92b333ae5",
}


@pytest.fixture(autouse=True)
def quiet():
    """inf - inf and the like happen on purpose, on lanes a select then drops: numpy need not warn."""
    with np.errstate(all="ignore"):
        yield


def inputs(name: str) -> list[np.ndarray]:
    """Arguments for a function: random over its useful range and far beyond, then every pair of
    special values (zeros of both signs, infinities, NaN, subnormals, the largest double). Made
    with exact operations only (no np.exp), so every CPU makes the same ones."""
    rng = np.random.default_rng(sorted(FUNCTIONS).index(name))
    n = 4000

    def spread(count, low, high):                  # |values| from 2^low to 2^high, random signs
        return np.ldexp(rng.uniform(-1, 1, count), rng.integers(low, high, count))
    if name == "power":
        big = np.abs(spread(n, -1000, 1000))
        x = np.concatenate([rng.uniform(0, 1, n), big, -rng.integers(1, 9, n) / 2])
        e = np.abs(np.frexp(big)[1]) + 1.0                          # |log2 x| + 1, about
        y = np.concatenate([rng.uniform(0, 2000, n), rng.uniform(-800, 800, n) / e, rng.integers(-9, 9, n) * 1.0])
    elif name in ("arcsin", "arccos"):
        x = np.concatenate([rng.uniform(-1, 1, 2 * n), 1 - np.abs(spread(n, -52, 0))])
    else:
        x = np.concatenate([spread(2 * n, -60, 60), rng.uniform(-1e5, 1e5, n)])
    if FUNCTIONS[name] == 1:
        return [np.concatenate([x, SPECIALS])]
    a, b = np.meshgrid(SPECIALS, SPECIALS)
    y = y if name == "power" else spread(len(x), -60, 60)
    return [np.concatenate([x, a.ravel()]), np.concatenate([y, b.ravel()])]


def numpy_variant(name: str) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.asarray(getattr(elementary, name)(*inputs(name)), dtype=np.float64)


def digest(values: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(values, dtype="<f8").tobytes()).hexdigest()


def same_bits(a, b) -> np.ndarray:
    """Equal to the last bit, the sign of zero included (NaN equal to NaN)."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return (a.view(np.uint64) == b.view(np.uint64)) | (np.isnan(a) & np.isnan(b))


@pytest.mark.parametrize("variant", ["python"] + (["compiled"] if variants.ENABLED else []))
@pytest.mark.parametrize("name", FUNCTIONS)
def test_scalar_variants_give_the_numpy_variants_bits(name, variant):
    args, whole = inputs(name), numpy_variant(name)
    f = variants.compiled(getattr(elementary, name)) if variant == "compiled" else \
        variants.python(getattr(elementary, name))
    step = 1 if variant == "compiled" else 7                  # plain Python is slow: every 7th value
    rows = range(0, len(args[0]), step)
    one = np.array([f(*(float(a[i]) for a in args)) for i in rows], dtype=np.float64)
    same = same_bits(whole[::step], one)
    assert same.all(), f"{name}: {np.count_nonzero(~same)} differ, e.g. at {[a[::step][~same][:3] for a in args]}"


@pytest.mark.parametrize("name", FUNCTIONS)
def test_outputs_are_the_pinned_bits(name):
    """On any CPU, with or without AVX-512, numpy 1 or 2: the same bits as where they were pinned."""
    assert digest(numpy_variant(name)) == PINNED[name]


def test_numpys_two_code_paths_give_the_same_bits():
    """Where this CPU has AVX-512, numpy's SVML functions differ from its other path (shown, so the
    comparison can fail), and rtcli's functions do not."""
    code = ("import json, numpy as np; from test_elementary import FUNCTIONS, numpy_variant, digest; "
            "print(json.dumps({n: digest(numpy_variant(n)) for n in FUNCTIONS}))")
    other = json.loads(without_avx512(["-c", code], cwd=os.path.dirname(os.path.abspath(__file__))).stdout)
    assert other == {name: digest(numpy_variant(name)) for name in FUNCTIONS}
    if avx512_features():
        x = np.random.default_rng(0).uniform(0, 1, 100000)
        other = without_avx512(["-c", "import numpy as np; x = np.random.default_rng(0).uniform(0, 1, 100000); "
                                      "print(np.power(x, 37.5).tobytes().hex())"]).stdout
        assert bytes.fromhex(other.strip()) != np.power(x, 37.5).tobytes(), "numpy's two paths agree here"


# --- IEEE's special cases ---
@pytest.mark.parametrize("x, y, expected", [
    (0.0, 2.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, math.inf), (-0.0, 3.0, -0.0), (-0.0, -3.0, -math.inf),
    (-0.0, 2.0, 0.0), (2.0, 0.0, 1.0), (math.nan, 0.0, 1.0), (1.0, math.nan, 1.0), (1.0, math.inf, 1.0),
    (-2.0, 3.0, -8.0), (-2.0, 2.0, 4.0), (-2.0, 0.5, math.nan), (2.0, math.nan, math.nan),
    (0.5, math.inf, 0.0), (2.0, math.inf, math.inf), (0.5, -math.inf, math.inf), (2.0, -math.inf, 0.0),
    (math.inf, 2.0, math.inf), (math.inf, -2.0, 0.0), (-math.inf, 3.0, -math.inf), (-math.inf, 0.5, math.inf),
    (2.0, 1024.0, math.inf), (2.0, -1074.0, 5e-324), (2.0, -1076.0, 0.0), (1e300, 1e300, math.inf),
    (4.0, 0.5, 2.0), (2.0, 10.0, 1024.0), (10.0, 2.0, 100.0),
])
def test_power_special_cases(x, y, expected):
    got = float(elementary.power(np.float64(x), np.float64(y)))
    assert same_bits(got, expected), f"{x} ** {y}: {got}, not {expected}"


@pytest.mark.parametrize("y, x, expected", [
    (0.0, 1.0, 0.0), (-0.0, 1.0, -0.0), (0.0, -1.0, math.pi), (-0.0, -1.0, -math.pi), (0.0, 0.0, 0.0),
    (-0.0, 0.0, -0.0), (0.0, -0.0, math.pi), (-0.0, -0.0, -math.pi), (1.0, 0.0, math.pi / 2),
    (-1.0, -0.0, -math.pi / 2), (math.inf, math.inf, math.pi / 4), (math.inf, -math.inf, 3 * math.pi / 4),
    (-math.inf, -math.inf, -3 * math.pi / 4), (1.0, math.inf, 0.0), (1.0, -math.inf, math.pi),
    (math.nan, 1.0, math.nan), (1.0, math.nan, math.nan), (math.nan, 0.0, math.nan), (1.0, 1.0, math.pi / 4),
])
def test_arctan2_special_cases(y, x, expected):
    got = float(elementary.arctan2(np.float64(y), np.float64(x)))
    assert same_bits(got, expected), f"arctan2({y}, {x}): {got}, not {expected}"


def test_the_other_functions_at_their_special_points():
    with np.errstate(all="ignore"):
        assert same_bits(elementary.arcsin(np.array([0.0, -0.0, 1.0, -1.0, 1.5, np.nan])),
                         [0.0, -0.0, math.pi / 2, -math.pi / 2, np.nan, np.nan]).all()
        assert same_bits(elementary.arccos(np.array([1.0, -1.0, 0.0, -1.5])), [0.0, math.pi, math.pi / 2, np.nan]).all()
        assert same_bits(elementary.cbrt(np.array([0.0, -0.0, 27.0, -8.0, np.inf, -np.inf, np.nan, 1e-300])),
                         [0.0, -0.0, 3.0, -2.0, np.inf, -np.inf, np.nan, 1e-100]).all()
        assert same_bits(elementary.cos(np.array([0.0, np.inf, np.nan])), [1.0, np.nan, np.nan]).all()
        assert same_bits(elementary.sin(np.array([0.0, -0.0, np.inf])), [0.0, -0.0, np.nan]).all()


# --- accuracy ---
BOUND = {"power": 1, "arctan2": 2, "arcsin": 3, "arccos": 3, "cbrt": 1, "cos": 1, "sin": 1}


@pytest.mark.parametrize("name", FUNCTIONS)
def test_within_the_stated_ulps_of_the_exact_value(name):
    """Against mpmath at 120 bits, on the random inputs (every 5th; special values apart): the
    docstring of rtcli/core/elementary.py states these bounds."""
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.prec = 120
    exact_f = {"power": mpmath.power, "arctan2": mpmath.atan2, "arcsin": mpmath.asin, "arccos": mpmath.acos,
               "cbrt": mpmath.cbrt, "cos": mpmath.cos, "sin": mpmath.sin}[name]
    args = [a[:-len(SPECIALS) ** FUNCTIONS[name]][::5] for a in inputs(name)]
    got = numpy_variant(name)[:-len(SPECIALS) ** FUNCTIONS[name]][::5]
    if name == "cbrt":
        exact = np.array([float(mpmath.cbrt(abs(mpmath.mpf(float(x))))) * math.copysign(1, x) for x in args[0]])
    else:
        exact = np.array([float(exact_f(*(mpmath.mpf(float(a[i])) for a in args))) for i in range(len(args[0]))])
    finite = np.isfinite(exact) & (exact != 0)
    if name in ("sin", "cos"):
        finite &= np.abs(args[0]) < 2.0 ** 20            # their stated domain; beyond, only the same bits
    ulps = np.abs(got[finite] - exact[finite]) / np.spacing(np.abs(exact[finite]))
    assert ulps.max() <= BOUND[name], f"{name}: {ulps.max():.0f} ulps from the exact value"
