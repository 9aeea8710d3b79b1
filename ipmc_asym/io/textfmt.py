"""Compiled text formatting of table rows (the CSV and JSON output of sweeps).

One compiled call writes a whole block of rows into a byte buffer: floats exactly as C's
``printf("%.{P}g")`` (Python's ``'%.10g' % x``: the same bytes), booleans and short strings
from small vocabularies, with per-column prefixes, so that CSV and JSON are the same kernel.

Why: a 10^6-row sweep spent ~6 s formatting one Python ``%`` per row (25 columns), three
times the computation.  Here a float costs ~40 ns.

Exactness: ``|x|`` is scaled by ``10^k`` held as a double-double (exact ``Fraction`` at
import), so the scaled value carries ~1e-32 relative error.  A value whose discarded part
lies within ``AMBIGUOUS`` of one half is either an exact decimal tie, decided in integer
arithmetic (:func:`_is_tie`) and rounded half to even, or not guessed: the kernel reports
it and the caller formats that block in Python instead (never seen in practice).

Layer rule: ``_jit`` and numpy only.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ipmc_asym.kernels.jit import jit

__all__ = ["format_table", "format_floats", "shortest_text", "AMBIGUOUS", "MAX_FLOAT_WIDTH", "SHORTEST"]

#: ``precision`` of :func:`format_table` asking for the shortest text that reads back as the
#: same double (``0.005``, not ``%.17g``'s ``0.0050000000000000001``): the first of ``%.15g``,
#: ``%.16g``, ``%.17g`` that round-trips (15 digits always reproduce a double that has a
#: representation of <= 15 digits, so this is as short as Python's ``repr`` in digits)
SHORTEST = 0

#: a discarded fraction within this of 1/2 (the double-double's error is < 1e-14 at 17 digits)
#: is either an exact tie (decided in integers, :func:`_is_tie`) or left to the caller
AMBIGUOUS = 1e-13
#: widest ``%.17g`` field: sign, 17 digits, point, ``e-308`` (or ``0.000`` + 17 digits)
MAX_FLOAT_WIDTH = 26

#: decimal scalings 10^k, k in [K_LO, K_HI], as double-doubles; beyond +-SCALED_FROM the value is
#: first scaled by 2^-+SCALE_BITS (exact) so that neither it nor the table leaves the normal range
K_LO, K_HI = -345, 345
SCALED_FROM = 280
SCALE_BITS = 256


def _pow10_tables():
    k = np.arange(K_LO, K_HI + 1)
    hi = np.empty(k.size)
    lo = np.empty(k.size)
    for i, kk in enumerate(k):
        x = Fraction(10) ** int(kk)
        if kk > SCALED_FROM:
            x /= Fraction(2) ** SCALE_BITS
        elif kk < -SCALED_FROM:
            x *= Fraction(2) ** SCALE_BITS
        h = float(x)
        hi[i] = h
        lo[i] = float(x - Fraction(h))
    return hi, lo


_P10_HI, _P10_LO = _pow10_tables()
#: 10^k rounded to a double (unscaled; inf beyond the range): the exponent estimate's check
_P10_DBL = np.array([float(10.0 ** int(k)) if k < 309 else np.inf for k in range(K_LO, K_HI + 1)])
_SPLIT = 134217729.0  # 2^27 + 1, Dekker's split of a double into two 26-bit halves
_TWO_SCALE = 2.0 ** SCALE_BITS
_POW10_INT = np.array([10**i for i in range(19)], dtype=np.int64)


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _two_prod(a, b):
    """``(p, e)`` with ``p + e = a b`` exactly (Dekker; no FMA needed)."""
    p = a * b
    t = _SPLIT * a
    ah = t - (t - a)
    al = a - ah
    t = _SPLIT * b
    bh = t - (t - b)
    bl = b - bh
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, e


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _scaled_digits(a, e10, P):
    """``(n, s, exact)``: ``a 10^(P-1-e10) = n + 1/2 + s``, ``n`` integer, ``-1/2 <= s < 1/2``
    (``s``: where the discarded fraction lies from one half; its sign decides the rounding)."""
    k = P - 1 - e10
    x = a
    if k > SCALED_FROM:
        x = a * _TWO_SCALE
    elif k < -SCALED_FROM:
        x = a / _TWO_SCALE
    hi = _P10_HI[k - K_LO]
    lo = _P10_LO[k - K_LO]
    p, e = _two_prod(x, hi)
    e += x * lo
    mh = p + e  # fast two-sum (|p| >= |e|): mh + ml = p + e exactly
    ml = e - (mh - p)
    f = math.floor(mh)
    rh = mh - f  # exact; the fraction is rh + ml, ml at most half an ulp of mh (<= 8 at 17 digits)
    n = np.int64(f)  # integer steps in int64: above 2^53 a float cannot step by one
    while rh + ml < 0.0:
        n -= 1
        rh += 1.0
    while rh + ml >= 1.0:
        n += 1
        rh -= 1.0
    return n, (rh - 0.5) + ml, (0 <= k <= 22)


#: "00" "01" ... "99": two digits per division
_DIG2 = np.frombuffer("".join(f"{i:02d}" for i in range(100)).encode(), np.uint8).copy()


_U_10 = np.uint64(10)
_U_1E8 = np.uint64(10**8)
_U_1E4 = np.uint64(10**4)
_U_100 = np.uint64(100)
_U_M4 = np.uint64(3518437209)  # x // 10^4 = (x * _U_M4) >> 45 for every x < 2^32
_U_M2 = np.uint64(5243)        # x // 100 = (x * _U_M2) >> 19 for every x < 43699
_U_S45 = np.uint64(45)
_U_S19 = np.uint64(19)


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _two_digits(x, out, pos):
    """``x < 100`` (uint64) as two digits at ``out[pos:]``."""
    k = np.int64(x) * 2
    out[pos] = _DIG2[k]
    out[pos + 1] = _DIG2[k + 1]


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _eight_digits(x, out, pos):
    """``x < 10^8`` (uint64) as eight digits at ``out[pos:]``: multiplications, no division."""
    a = (x * _U_M4) >> _U_S45  # first four digits
    b = x - a * _U_1E4
    a1 = (a * _U_M2) >> _U_S19
    b1 = (b * _U_M2) >> _U_S19
    _two_digits(a1, out, pos)
    _two_digits(a - a1 * _U_100, out, pos + 2)
    _two_digits(b1, out, pos + 4)
    _two_digits(b - b1 * _U_100, out, pos + 6)


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _digits(n, P, out, pos):
    """The ``P`` decimal digits of ``n`` (uint64, ``< 10^P``, ``P <= 17``, leading zeros kept)
    at ``out[pos:]``: blocks of eight by multiply-shift (one 64-bit division above 8 digits)."""
    if P > 8:
        h = n // _U_1E8
        lo = n - h * _U_1E8
        _eight_digits(lo, out, pos + P - 8)
        k = P - 8  # digits of h, 1..9
        if k == 9:
            out[pos] = 48 + np.int64(h // _U_1E8)
            h = h - (h // _U_1E8) * _U_1E8
            _eight_digits(h, out, pos + 1)
        else:
            # h < 10^k <= 10^8: its eight digits end where lo starts; the first 8 - k are zeros
            if k == 8:
                _eight_digits(h, out, pos)
            else:
                _short_digits(h, k, out, pos)
        return
    _short_digits(n, P, out, pos)


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _short_digits(n, k, out, pos):
    """The ``k`` digits of ``n < 10^k`` (uint64) at ``out[pos:]``, one at a time."""
    j = pos + k - 1
    while j >= pos:
        q = n // _U_10
        out[j] = 48 + np.int64(n - q * _U_10)
        n = q
        j -= 1


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _is_tie(a, k):
    """Whether ``a 10^k`` is exactly an integer plus one half (``a > 0`` finite).

    With ``a = M 2^E``, ``M`` odd: for ``k >= 0``, ``a 10^k = M 5^k 2^(E+k)`` is a half-integer
    iff ``E + k = -1``; for ``k < 0``, ``M 2^(E+k) / 5^-k`` is one iff ``E + k = -1`` and
    ``5^-k`` divides ``M`` (impossible beyond ``5^22 > 2^53 > M``).  Integer arithmetic only.
    """
    m, e = math.frexp(a)
    M = np.int64(m * 9007199254740992.0)  # m in [1/2, 1): M = m 2^53 exactly
    E = np.int64(e) - 53
    while (M & 1) == 0:
        M >>= 1
        E += 1
    if E + k != -1:
        return False
    if k >= 0:
        return True
    if -k > 22:
        return False
    f = np.int64(1)
    for _ in range(-k):
        f *= 5
    return M % f == 0


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _decompose(x, P):
    """``x`` (finite) as ``(n, e10, neg, ok)``: ``|x|`` rounded to ``P`` significant digits is
    ``n 10^(e10 - P + 1)``, ``10^(P-1) <= n < 10^P`` (``n = 0`` for zero); ``ok`` is False
    where the rounding is too close to call (the caller formats in Python)."""
    neg = x < 0.0 or (x == 0.0 and math.copysign(1.0, x) < 0.0)
    a = -x if neg else x
    if a == 0.0:
        return np.int64(0), np.int64(0), neg, True
    # decimal exponent from the binary one (log10(2) ~ 78913 / 2^18, exact floor for
    # |e2| < 1650), then one comparison; the digit count below corrects a rare miss
    m2, e2 = math.frexp(a)
    e10 = ((np.int64(e2) - 1) * 78913) >> 18
    if e10 + 1 <= K_HI and a >= _P10_DBL[e10 + 1 - K_LO]:
        e10 += 1
    lo_n = _POW10_INT[P - 1]
    hi_n = _POW10_INT[P]
    n, s, exact = _scaled_digits(a, e10, P)
    if n < lo_n or n >= hi_n:  # the estimate was one off (near a power of ten)
        e10 += 1 if n >= hi_n else -1
        n, s, exact = _scaled_digits(a, e10, P)
    if not exact and abs(s) < AMBIGUOUS:  # too close to one half for the double-double
        if _is_tie(a, P - 1 - e10):
            s = 0.0
        else:
            return n, e10, neg, False
    # round half to even, on the exact value (the sign of s is exact: a rounded sum keeps it)
    n += np.int64(s > 0.0) | (np.int64(s == 0.0) & (n & 1))  # branch-free: s's sign is random
    if n >= hi_n:
        n //= 10
        e10 += 1
    return n, e10, neg, True


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _write_decomposed(n, e10, neg, P, out, pos):
    """Write the ``%.{P}g`` text of ``(n, e10, neg)`` (:func:`_decompose`); return the new position."""
    if neg:
        out[pos] = 45  # '-'
        pos += 1
    if n == 0:
        out[pos] = 48
        return pos + 1
    fixed = -4 <= e10 < P
    # where the P digits go: after "0.000" for fixed notation below 1, else at pos
    start = pos + 1 - e10 if (fixed and e10 < 0) else pos
    _digits(np.uint64(n), P, out, start)
    d = P
    while d > 1 and out[start + d - 1] == 48:  # %g drops trailing zeros
        d -= 1
    if fixed:
        if e10 < 0:
            out[pos] = 48
            out[pos + 1] = 46
            for j in range(pos + 2, start):
                out[j] = 48
            return start + d
        ip = e10 + 1  # digits before the point
        if d <= ip:
            for j in range(start + d, start + ip):
                out[j] = 48
            return start + ip
        for j in range(start + d, start + ip, -1):  # open a slot for the point
            out[j] = out[j - 1]
        out[start + ip] = 46
        return start + d + 1
    # exponential: d.ddd e+XX
    if d > 1:
        for j in range(start + d, start + 1, -1):
            out[j] = out[j - 1]
        out[start + 1] = 46
        pos = start + d + 1
    else:
        pos = start + 1
    out[pos] = 101  # 'e'
    out[pos + 1] = 45 if e10 < 0 else 43
    pos += 2
    ae = -e10 if e10 < 0 else e10
    if ae >= 100:
        out[pos] = 48 + ae // 100
        ae %= 100
        pos += 1
    out[pos] = _DIG2[2 * ae]
    out[pos + 1] = _DIG2[2 * ae + 1]
    return pos + 2


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _round_trips(n, e10, P, a):
    """Does ``n 10^(e10 - P + 1)`` (``P`` digits) read back as the double ``a`` (> 0)?

    The decimal times the double-double power of ten (~1e-32 relative error) is compared with
    half an ulp of ``a`` (a quarter below a power of two); a value within 1e-9 of the edge
    answers False (the caller then takes more digits, which is always right at 17).
    """
    k = e10 - P + 1
    if k < K_LO or k > K_HI or a < 2.2250738585072014e-308:
        return False  # subnormal: 17 digits (the ulp is no longer relative)
    m2, e2 = math.frexp(a)
    ulp = math.ldexp(1.0, e2 - 53)
    # the table holds 10^k scaled by 2^-+SCALE_BITS beyond +-SCALED_FROM: scale a and its ulp alike
    if k > SCALED_FROM:
        a = a / _TWO_SCALE
        ulp = ulp / _TWO_SCALE
    elif k < -SCALED_FROM:
        a = a * _TWO_SCALE
        ulp = ulp * _TWO_SCALE
    hi = _P10_HI[k - K_LO]
    lo = _P10_LO[k - K_LO]
    nh = float(n)
    nl = float(n - np.int64(nh))
    p, e = _two_prod(nh, hi)
    e += nh * lo + nl * hi
    d = (p - a) + e  # p - a exact (Sterbenz: p within a factor 2 of a)
    half = 0.25 * ulp if (m2 == 0.5 and d < 0.0) else 0.5 * ulp
    if abs(d) == half and 0 <= k <= 22:
        # an exact decimal midpoint (10^k and the products exact): reading rounds half to
        # even, so it comes back as ``a`` iff a's significand is even (for k < 0 no decimal of <= 16
        # digits is a binary midpoint)
        return (np.int64(m2 * 9007199254740992.0) & 1) == 0
    return abs(d) < half * (1.0 - 1e-9)


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _decompose_all(F, P, N, E, S, PV):
    """:func:`_decompose` of every finite element of ``F`` (2-D) into ``N``, ``E``, ``S`` (sign)
    and ``PV`` (the digits used: ``P``, or with ``P = SHORTEST`` the first of 15, 16, 17 that
    round-trips); a tight loop of independent iterations, which the processor overlaps.  False
    if a rounding was too close to call."""
    ok_all = True
    for j in range(F.shape[0]):
        for i in range(F.shape[1]):
            x = F[j, i]
            if math.isfinite(x):
                if P == 0:
                    a = -x if x < 0.0 else x
                    for q in range(15, 18):
                        n, e10, neg, ok = _decompose(x, q)
                        if q == 17 or (ok and (a == 0.0 or _round_trips(n, e10, q, a))):
                            break
                else:
                    q = P
                    n, e10, neg, ok = _decompose(x, P)
                N[j, i] = n
                E[j, i] = e10
                S[j, i] = neg
                PV[j, i] = q
                ok_all = ok_all and ok
    return ok_all


@jit(inline="always")  # numba-level: cached callers keep it inlined
def _copy(src, start, m, out, pos):
    """``src[start:start + m]`` to ``out[pos:]``; the new position."""
    for q in range(m):
        out[pos + q] = src[start + q]
    return pos + m


@jit
def _format_rows(F, C, U, kinds, idx, quote_strings, P, text, pre_off, pre_len, vocab_off, vocab_len, voc_base,
                 nonfinite_off, nonfinite_len, row_start_off, row_start_len, row_end_off, row_end_len,
                 row_sep_off, row_sep_len, out):
    """All rows into ``out``; returns the bytes written, -1 (an ambiguous rounding) or -2 (a
    text column with a character that is not printable ASCII, or a quote or backslash).

    Every fixed piece of text (prefixes, vocabulary words, the non-finite field, row start,
    end and separator) is a slice ``text[off:off + len]``.  Column ``j`` of kind 0 is float
    row ``idx[j]`` of ``F``; kind 1 a code ``C[idx[j], i]`` into the words
    ``voc_base[j] + code``; kind 2 the ASCII text of ``U[idx[j], i]`` (code points,
    NUL-padded), in double quotes if ``quote_strings``.
    """
    n = F.shape[1] if F.shape[0] > 0 else (C.shape[1] if C.shape[0] > 0 else U.shape[1])
    N = np.empty(F.shape, np.int64)
    E = np.empty(F.shape, np.int64)
    S = np.empty(F.shape, np.bool_)
    PV = np.empty(F.shape, np.int64)
    if not _decompose_all(F, P, N, E, S, PV):
        return -1
    ncol = kinds.size
    w = U.shape[2]
    pos = 0
    # the last float of each column and where its text is: a value equal to the previous
    # row's (constant columns, outer grid axes) is copied, not formatted again
    last = np.full(ncol, np.nan)
    last_pos = np.zeros(ncol, np.int64)
    last_len = np.zeros(ncol, np.int64)
    for i in range(n):
        if i > 0:
            pos = _copy(text, row_sep_off, row_sep_len, out, pos)
        pos = _copy(text, row_start_off, row_start_len, out, pos)
        for j in range(ncol):
            pos = _copy(text, pre_off[j], pre_len[j], out, pos)
            kd = kinds[j]
            k = idx[j]
            if kd == 0:
                x = F[k, i]
                if x == last[j] and (x != 0.0 or math.copysign(1.0, x) == math.copysign(1.0, last[j])):
                    pos = _copy(out, last_pos[j], last_len[j], out, pos)
                elif math.isfinite(x):
                    start = pos
                    pos = _write_decomposed(N[k, i], E[k, i], S[k, i], PV[k, i], out, pos)
                    last[j] = x
                    last_pos[j] = start
                    last_len[j] = pos - start
                else:
                    pos = _copy(text, nonfinite_off, nonfinite_len, out, pos)
            elif kd == 1:
                r = voc_base[j] + C[k, i]
                pos = _copy(text, vocab_off[r], vocab_len[r], out, pos)
            else:
                if quote_strings:
                    out[pos] = 34
                    pos += 1
                for q in range(w):
                    c = U[k, i, q]
                    if c == 0:
                        break
                    if c < 32 or c > 126 or c == 34 or c == 92:  # not printable ASCII, '"' or '\\'
                        return -2
                    out[pos] = c
                    pos += 1
                if quote_strings:
                    out[pos] = 34
                    pos += 1
        pos = _copy(text, row_end_off, row_end_len, out, pos)
    return pos


class _Text:
    """Fixed pieces of text packed into one byte array (offsets and lengths)."""

    def __init__(self):
        self._parts = []
        self._size = 0

    def add(self, s: str):
        b = s.encode("ascii")
        self._parts.append(b)
        off = self._size
        self._size += len(b)
        return off, len(b)

    def array(self):
        return np.frombuffer(b"".join(self._parts) or b"\0", np.uint8).copy()


def format_table(columns, prefixes, precision: int, nonfinite: str = "", row_start: str = "",
                 row_end: str = "", row_sep: str = "\n", quote_strings: bool = False, as_bytes: bool = False):
    """Rows of ``columns`` as text, or None if a float's rounding was too close to call.

    Parameters
    ----------
    columns : list of (kind, values)
        ``("f", float array)`` formatted ``%.{precision}g`` (non-finite -> ``nonfinite``);
        ``("s", (codes, vocabulary))`` with ``codes`` an integer array indexing the list of
        ASCII strings ``vocabulary`` (written as they are); ``("u", str array)`` a NumPy
        unicode array, ASCII without ``"``, ``\\`` or control characters (else ValueError),
        written as is (in double quotes if ``quote_strings``).  All arrays shape ``(n,)``.
    prefixes : list of str
        Text written before each column's field (separators, JSON keys).
    precision : int
        Significant digits of the floats, 1-17, or :data:`SHORTEST` (0): the shortest of
        ``%.15g``/``%.16g``/``%.17g`` that reads back as the same double (:func:`shortest_text`).
    nonfinite, row_start, row_end, row_sep : str
        Field of a NaN/inf; text before and after each row; text between rows.
    as_bytes : bool
        Return ASCII bytes (for a binary file: no decoding and encoding again).

    Returns
    -------
    str or bytes or None
    """
    if not 0 <= int(precision) <= 17:
        raise ValueError(f"precision must be an integer in 1..17 or SHORTEST (0); got {precision!r}")
    if len(prefixes) != len(columns):
        raise ValueError("prefixes must give one prefix per column")
    floats, codes, texts, kinds, idx, offs, vocab = [], [], [], [], [], [], []
    n = None
    for kind, values in columns:
        offs.append(len(vocab))
        if kind == "f":
            a = np.asarray(values, dtype=np.float64)
            kinds.append(0)
            idx.append(len(floats))
            floats.append(a)
        elif kind == "s":
            c, words = values
            a = np.asarray(c, dtype=np.int64)
            if a.size and (a.min() < 0 or a.max() >= len(words)):
                raise ValueError("string codes must index their vocabulary")
            kinds.append(1)
            idx.append(len(codes))
            codes.append(a)
            vocab.extend(words)
        elif kind == "u":
            a = np.asarray(values)
            if a.dtype.kind != "U":
                raise ValueError(f"a 'u' column must be a unicode array; got dtype {a.dtype}")
            kinds.append(2)
            idx.append(len(texts))
            texts.append(a)
        else:
            raise ValueError(f"column kind must be 'f', 's' or 'u'; got {kind!r}")
        if n is None:
            n = a.size
        elif a.size != n:
            raise ValueError("columns must have one length")
    n = 0 if n is None else n
    F = np.empty((len(floats), n))
    for i, a in enumerate(floats):
        F[i] = a
    C = np.empty((len(codes), n), np.int64)
    for i, a in enumerate(codes):
        C[i] = a
    wmax = max([a.dtype.itemsize // 4 for a in texts] + [1])
    U = np.zeros((len(texts), n, wmax), np.uint32)
    for i, a in enumerate(texts):
        w = a.dtype.itemsize // 4
        if w:
            U[i, :, :w] = np.ascontiguousarray(a).view(np.uint32).reshape(n, w)
    tx = _Text()
    pre = [tx.add(p) for p in prefixes]
    voc = [tx.add(v) for v in vocab] or [(0, 0)]
    nf, rs, re_, sep = (tx.add(t) for t in (nonfinite, row_start, row_end, row_sep))
    width = (sum(m for _, m in pre) + len(floats) * max(MAX_FLOAT_WIDTH, nf[1]) + len(codes) * max(m for _, m in voc)
             + len(texts) * (wmax + 2) + rs[1] + re_[1] + sep[1])
    out = np.empty(max(n * width, 1), np.uint8)
    i64 = (lambda v: np.array(v, np.int64))
    m = _format_rows(F, C, U, i64(kinds), i64(idx), bool(quote_strings), int(precision), tx.array(),
                     i64([o for o, _ in pre]), i64([m for _, m in pre]), i64([o for o, _ in voc]),
                     i64([m for _, m in voc]), i64(offs), *nf, *rs, *re_, *sep, out)
    if m == -2:
        raise ValueError("text columns must be printable ASCII without '\"' or '\\'")
    if m < 0:
        return None
    b = out[:m].tobytes()
    return b if as_bytes else b.decode("ascii")


def shortest_text(x: float) -> str:
    """The first of ``%.15g``, ``%.16g``, ``%.17g`` of ``x`` that reads back as ``x`` (the
    Python reference of ``precision=SHORTEST``)."""
    x = float(x)
    if x != 0.0 and abs(x) < 2.2250738585072014e-308:
        return "%.17g" % x  # subnormal: the compiled formatter's rule (17 digits, exact round trip)
    for p in (15, 16):
        t = "%.*g" % (p, x)
        if float(t) == x:
            return t
    return "%.17g" % x


def format_floats(x, precision: int) -> str | None:
    """``'%.{precision}g'`` of each float of ``x``, one per line (a test and debugging aid)."""
    x = np.asarray(x, dtype=np.float64).reshape(-1)
    return format_table([("f", x)], [""], precision, nonfinite="nan")
