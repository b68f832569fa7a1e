"""Compiled CSV text of a stability map: exact ``%.12g`` formatting of whole columns.

:func:`csv_rows` writes the rows ``x,y,max_real_part,stable`` of a map as ASCII bytes,
the same text Python's ``"%.12g,%.12g,%.12g,%d\\n" % row`` gives, about ten times
faster than formatting each number in Python (the GIL is released).

Exactness. A value v with 1e-11 <= |v| < 1e12 is formatted here: with its decimal
exponent e, the product |v| · 10^(11 − e) is formed exactly as a sum hi + lo of two
doubles (Dekker's product; 10^k is exact for k <= 22, and the kernels are compiled
without floating-point contraction, which would break the exact product), and
rounded to the nearest integer with ties to even, as Python's correctly rounded
conversion does. Every other value (0 aside: "0" or "-0"; NaN; ±inf; |v| outside that
range) comes preformatted from Python, so the text is Python's in every case. The
x and y columns have few distinct values and are always preformatted.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import kernel

#: Significant digits of every number written. [-]
DIGITS = 12

#: Smallest and (exclusive) largest magnitude formatted by the kernel. [-]
FAST_LOW, FAST_HIGH = 1e-11, 1e12

#: Room for one formatted number ("-1.23456789012e-308" has 19 characters). [bytes]
WIDTH = 32

_POW10 = np.array([10.0**k for k in range(23)])  # exact: 10^k < 2^53 · 2^k for k <= 22
_COMMA, _NEWLINE, _MINUS, _POINT, _ZERO = 44, 10, 45, 46, 48


@kernel(fastmath=False)
def _put_g12(v, out, pos):
    """Write ``"%.12g" % v`` into ``out`` at ``pos``; return the new position, or −1 when v
    is outside [FAST_LOW, FAST_HIGH) in magnitude (and not 0) or not finite."""
    if v == 0.0:
        if math.copysign(1.0, v) < 0.0:
            out[pos] = _MINUS
            pos += 1
        out[pos] = _ZERO
        return pos + 1
    a = abs(v)
    if not (a >= FAST_LOW and a < FAST_HIGH):  # also NaN
        return -1
    e = min(11, max(-11, int(math.floor(math.log10(a)))))
    hi = 0.0
    lo = 0.0
    for _ in range(4):  # log10 may be one off near a power of ten
        # hi + lo = a · 10^(11 − e) exactly: Dekker's product (splitting by 2^27 + 1)
        b = _POW10[11 - e]
        hi = a * b
        ca = 134217729.0 * a
        a_hi = ca - (ca - a)
        a_lo = a - a_hi
        cb = 134217729.0 * b
        b_hi = cb - (cb - b)
        b_lo = b - b_hi
        lo = ((a_hi * b_hi - hi) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo
        if (hi > 1e12 or (hi == 1e12 and lo >= 0.0)) and e < 11:
            e += 1
        elif (hi < 1e11 or (hi == 1e11 and lo < 0.0)) and e > -11:
            e -= 1
        else:
            break
    # hi + lo in [1e11, 1e12): round to an integer, ties to even. r is a multiple of
    # ulp(hi) >= 2|lo|, so only r == 0.5 needs lo (r == 0 with lo < 0 is just below
    # the integer f, and rounds to it).
    f = math.floor(hi)
    r = hi - f  # exact
    digits = np.int64(f)
    if r > 0.5 or (r == 0.5 and (lo > 0.0 or (lo == 0.0 and digits % 2 == 1))):
        digits += 1
    if digits == 1_000_000_000_000:
        digits = 100_000_000_000
        e += 1
    used = DIGITS  # significant digits left once trailing zeros are dropped
    while used > 1 and digits % 10 == 0:
        digits //= 10
        used -= 1
    if v < 0.0:
        out[pos] = _MINUS
        pos += 1
    # the layout of %g: fixed notation for -4 <= e < 12, else d.ddd e±XX
    point = -1  # digits before the decimal point, when there is one among the digits
    pad = 0  # zeros after the digits (an integer with trailing zeros)
    if 0 <= e < DIGITS:
        if used > e + 1:
            point = e + 1
        else:
            pad = e + 1 - used
    elif -4 <= e < 0:
        out[pos] = _ZERO
        out[pos + 1] = _POINT
        pos += 2
        for _ in range(-e - 1):
            out[pos] = _ZERO
            pos += 1
    elif used > 1:
        point = 1
    end = pos + used + (1 if point > 0 else 0)
    k = end - 1
    for j in range(used - 1, -1, -1):  # the digits, last first
        out[k] = _ZERO + digits % 10
        digits //= 10
        k -= 1
        if j == point:
            out[k] = _POINT
            k -= 1
    pos = end
    for _ in range(pad):
        out[pos] = _ZERO
        pos += 1
    if -4 <= e < DIGITS:
        return pos
    out[pos] = 101  # "e"
    out[pos + 1] = _MINUS if e < 0 else 43  # "-" or "+"
    pos += 2
    x = abs(e)
    if x >= 100:
        out[pos] = _ZERO + x // 100
        pos += 1
    out[pos] = _ZERO + (x // 10) % 10
    out[pos + 1] = _ZERO + x % 10
    return pos + 2


@kernel(nogil=True, entry=True, fastmath=False)
def format_g12(values, out, lengths):
    """``"%.12g" % values[i]`` into row i of ``out`` (uint8, width WIDTH) and its length
    into ``lengths[i]``, or −1 where the value needs Python (see the module notes)."""
    for i in range(values.shape[0]):
        lengths[i] = _put_g12(values[i], out[i], 0)


@kernel(nogil=True, entry=True, fastmath=False)
def csv_rows(start, stop, nx, x_text, x_len, y_text, y_len, values, stable, special_index,
             special_text, special_len, out):
    """Rows ``start:stop`` of a map's CSV into ``out`` (uint8); returns the bytes written.

    Row i is ``x[i % nx],y[i // nx],values[i],stable[i]`` with x and y preformatted
    (``x_text``/``x_len``, ``y_text``/``y_len``); values that :func:`_put_g12` does not
    format are at the ascending global row numbers ``special_index``, preformatted in
    ``special_text``/``special_len``. ``out`` must hold the rows (WIDTH bytes per value
    is enough).
    """
    pos = 0
    s = 0  # the first special row at or after start (binary search)
    high = special_index.shape[0]
    while s < high:
        middle = (s + high) // 2
        if special_index[middle] < start:
            s = middle + 1
        else:
            high = middle
    for i in range(start, stop):
        ix = i % nx
        iy = i // nx
        for k in range(x_len[ix]):
            out[pos + k] = x_text[ix, k]
        pos += x_len[ix]
        out[pos] = _COMMA
        pos += 1
        for k in range(y_len[iy]):
            out[pos + k] = y_text[iy, k]
        pos += y_len[iy]
        out[pos] = _COMMA
        pos += 1
        if s < special_index.shape[0] and special_index[s] == i:
            for k in range(special_len[s]):
                out[pos + k] = special_text[s, k]
            pos += special_len[s]
            s += 1
        else:
            pos = _put_g12(values[i], out, pos)
        out[pos] = _COMMA
        out[pos + 1] = _ZERO + 1 if stable[i] else _ZERO
        out[pos + 2] = _NEWLINE
        pos += 3
    return pos


def text_table(values) -> tuple[np.ndarray, np.ndarray]:
    """``"%.12g"`` of each value (formatted by Python) as a uint8 table and lengths."""
    texts = [("%.12g" % v).encode("ascii")  # noqa: UP031 (the format of the CSV)
             for v in np.asarray(values, dtype=float).tolist()]
    table = np.zeros((len(texts), WIDTH), dtype=np.uint8)
    lengths = np.empty(len(texts), dtype=np.int64)
    for i, text in enumerate(texts):
        table[i, :len(text)] = np.frombuffer(text, dtype=np.uint8)
        lengths[i] = len(text)
    return table, lengths


def special_values(values: np.ndarray) -> np.ndarray:
    """Indices of the values :func:`_put_g12` leaves to Python (ascending). [-]"""
    a = np.abs(values)
    return np.flatnonzero(~((a >= FAST_LOW) & (a < FAST_HIGH)) & (values != 0.0))
