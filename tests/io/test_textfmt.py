"""The compiled text formatter writes exactly what C's printf (Python's ``%``) writes."""

from fractions import Fraction

import numpy as np
import pytest

import ipmc_asym.io.textfmt as textfmt
import ipmc_asym.studies.sweeps as sweeps
from ipmc_asym.io.textfmt import format_floats, format_table


def _doubles(n, seed=0):
    """Random bit patterns (every exponent), decimal-looking values, integers with trailing 5s,
    dyadic ties, powers of ten and their neighbours, zeros, subnormals, the largest double."""
    rng = np.random.default_rng(seed)
    bits = rng.integers(0, 2**63 - 1, n, dtype=np.int64).view(np.float64)
    bits = bits[np.isfinite(bits)]
    p10 = 10.0 ** np.arange(-320, 309).astype(float)
    p10 = p10[p10 > 0]
    special = np.array([0.0, -0.0, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, 2.0**-15, 2.0**-25,
                        12345678905.0, 99999999995.0, 0.5, 1.5, 2.5, 9.9999999995, 9.99999999949, 1e22, 1e23,
                        123456789012345678.0])
    parts = [bits, rng.uniform(0, 1, n) * 10.0 ** rng.integers(-30, 30, n),
             rng.integers(1, 10**15, n // 2).astype(float) * 10.0 ** rng.integers(-5, 6, n // 2),
             (rng.integers(1, 10**6, n // 4) * 10 + 5).astype(float),
             2.0 ** rng.integers(-1074, 1023, n // 4).astype(float),
             p10, np.nextafter(p10, 0.0), np.nextafter(p10, np.inf), special]
    x = np.concatenate(parts)
    return x * rng.choice([-1.0, 1.0], x.size)


@pytest.mark.parametrize("precision", [10, 17, 15, 6, 1])
def test_floats_byte_identical_to_printf(precision):
    x = _doubles(60000, seed=precision)
    text = format_floats(x, precision)
    assert text is not None  # no rounding too close to call in this sample
    want = [("%%.%dg" % precision) % v for v in x.tolist()]
    got = text.split("\n")
    bad = [(v, g, w) for v, g, w in zip(x.tolist(), got, want) if g != w]
    assert not bad, bad[:5]


def test_ties_decided_in_integers():
    """``_is_tie`` against exact rational arithmetic: is ``a 10^k`` an integer plus one half?"""
    rng = np.random.default_rng(1)
    cases = [(2.0**-15, 14), (2.0**-25, 24), (12345678905.0, -1), (99999999995.0, -1), (0.5, 0), (2.5, 0),
             (1.0, 0), (3.0, -1), (2.0**-15, 13), (12345678905.0, -2)]
    cases += [(float(m) * 2.0**int(e), int(k)) for m, e, k in
              zip(rng.integers(1, 2**20, 300), rng.integers(-40, 40, 300), rng.integers(-12, 30, 300))]
    for a, k in cases:
        v = Fraction(a) * Fraction(10) ** k
        want = (v - Fraction(1, 2)).denominator == 1
        assert textfmt._is_tie(a, k) == want, (a, k)


def test_rows_columns_and_errors():
    txt = format_table([("f", np.array([1.5, np.nan, -2e-7])), ("s", (np.array([0, 1, 1]), ["no", "yes"])),
                        ("u", np.array(["a", "bc", ""]))], ["", ";", ";"], 10, nonfinite="NA",
                       row_start="<", row_end=">", row_sep="|")
    assert txt == "<1.5;no;a>|<NA;yes;bc>|<-2e-07;yes;>"
    with pytest.raises(ValueError, match="precision"):
        format_table([("f", np.ones(2))], [""], 18)
    with pytest.raises(ValueError, match="one length"):
        format_table([("f", np.ones(2)), ("f", np.ones(3))], ["", ","], 10)
    with pytest.raises(ValueError, match="ASCII"):
        format_table([("u", np.array(['say "hi"']))], [""], 10)


@pytest.mark.parametrize("kind", ["csv", "json"])
def test_format_chunk_is_the_python_text(kind):
    """The sweep's rows (NaN where withheld, both signs of voltage, all models) as text: the
    compiled path writes the same bytes as one Python ``%`` per row."""
    vary = {"thickness": np.geomspace(2e-6, 2e-3, 23), "voltage": np.linspace(-3.0, 3.0, 17)}
    arr = np.concatenate([sweeps.withhold(c) for c in sweeps.iter_sweep(vary, "all", "leading")])
    assert np.isnan(arr["w"]).any() and (~np.isnan(arr["w"])).any()
    assert sweeps.format_chunk(arr, kind) == sweeps._format_chunk_python(arr, kind)


def test_shortest_round_trip_text():
    """SHORTEST: the first of %.15g/%.16g/%.17g reading back as the same double (no float noise
    such as 0.0050000000000000001); exact midpoints read half to even; scaled and tiny exponents."""
    rng = np.random.default_rng(3)
    x = np.concatenate([_doubles(40000, seed=11), np.round(rng.standard_normal(5000), 3),
                        rng.integers(1, 2**62, 5000).astype(float),
                        np.array([0.005, 0.1, 1e-300, 1e-200, 1e300, 7.189405658150542e16, 4.450147717014403e-308,
                                  5e-324, -0.0, 1.7976931348623157e308])])
    text = format_floats(x, textfmt.SHORTEST)
    assert text is not None
    got = text.split("\n")
    for v, g in zip(x.tolist(), got):
        assert float(g) == v and g == textfmt.shortest_text(v), (v, g)
        # at most one digit more than Python's shortest repr (which may round a %.16g tie the
        # other way, e.g. 2^-24), never 17 where repr has <= 15 (subnormals: 17)
        if abs(v) >= 2.2250738585072014e-308:
            def sig(t):
                return len(t.split("e")[0].replace("-", "").replace(".", "").lstrip("0").rstrip("0")) or 1

            assert sig(g) <= sig(repr(v)) + 1 and (sig(repr(v)) > 15 or sig(g) <= 15), (v, g)
    assert got[-10:-7] == ["0.005", "0.1", "1e-300"]
