"""Stimulus harmonics and frequency bands of a periodic (PRTS) experiment.

A PRTS of cycle length T [s] has its power at the odd harmonics of f0 = 1/T (its second
half-period is the negative of the first): (2k − 1)·f0 for k = 1, 2, … The spectra are
averaged over bands of neighbouring odd harmonics, numbered from 1 (the k-th odd harmonic
is (2k − 1)/T).

The 11 bands of an 80-state, 20 s PRTS (:data:`PETERKA_BAND_HARMONICS`, the name kept from
earlier versions) are those of the Eurobench COMTEST protocol's analysis code (Lippi,
Mergner et al.; github.com/VittorioFreiburg/COMTEST, ANALYSIS/MATLAB/PRTS2012.m and
PRTS2020.m, which cut Peterka's 242-state analysis down to an 80-state sequence):

    [1], [2], [3, 4], [4, 5], [5–7], [6–9], [8–11], [10–13], [12–16], [16–20], [20–25]

whose mean frequencies are 0.05, 0.15, 0.30, 0.40, 0.55, 0.70, 0.90, 1.10, 1.35, 1.75 and
2.20 Hz. For another cycle length the same rule holds in harmonic numbers (the band
frequencies scale with 1/T).

For Peterka 2002's 242-state, 60.5 s sequence (:data:`PETERKA_242_BAND_HARMONICS`) the band
*sizes* are those a comment of Peterka's analysis code gives ("Additional frequency
averaging - 1,1,2,2,3,4,4,4,5,5,6,8,9,10,11,13,15 partial overlapping pts", kept in the same
COMTEST files); their *placement* was not found, and is posturelab's rule: the first 11 as
above, then each band starting at the last harmonic of the one before (as bands 9–11 do).
Its band frequencies run from 0.0165 Hz to 2.56 Hz; the range quoted for Peterka 2002's
stimulus is 0.017–2.23 Hz (not checked against the paper here), so the paper's own bands
12–17 probably overlap more and lie lower than these.

:data:`SEQUENCE_BANDS` gives each named sequence's layout
(:data:`posturelab.model.tilt.PRTS_SEQUENCES`); :func:`harmonic_bands` gives one band per odd
harmonic instead, and a user-given list of bands is any list of harmonic-number lists.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError

__all__ = ["PETERKA_BAND_HARMONICS", "PETERKA_BAND_FREQUENCIES", "odd_harmonic_frequency",
           "peterka_bands", "harmonic_bands", "band_frequencies", "check_bands",
           "PETERKA_242_BAND_SIZES", "PETERKA_242_BAND_HARMONICS", "SEQUENCE_BANDS",
           "sequence_bands"]

#: The 11 bands of the 80-state sequences (COMTEST's analysis; module notes): 1-based numbers
#: of the odd harmonics averaged in each.
PETERKA_BAND_HARMONICS: tuple[tuple[int, ...], ...] = (
    (1,), (2,), (3, 4), (4, 5), (5, 6, 7), (6, 7, 8, 9), (8, 9, 10, 11), (10, 11, 12, 13),
    (12, 13, 14, 15, 16), (16, 17, 18, 19, 20), (20, 21, 22, 23, 24, 25))
#: Their band frequencies for the 20 s cycle (COMTEST's ``Fr`` and ``f12``). [Hz]
PETERKA_BAND_FREQUENCIES: tuple[float, ...] = (0.05, 0.15, 0.30, 0.40, 0.55, 0.70, 0.90,
                                               1.10, 1.35, 1.75, 2.20)


#: Harmonics per band of Peterka's 242-state analysis (module notes). [-]
PETERKA_242_BAND_SIZES: tuple[int, ...] = (1, 1, 2, 2, 3, 4, 4, 4, 5, 5, 6, 8, 9, 10, 11, 13, 15)


def _continued_bands() -> tuple[tuple[int, ...], ...]:
    bands = list(PETERKA_BAND_HARMONICS)
    for size in PETERKA_242_BAND_SIZES[len(bands):]:
        first = bands[-1][-1]
        bands.append(tuple(range(first, first + size)))
    return tuple(bands)


#: The 17 bands posturelab uses for the 242-state sequence: Peterka's sizes, posturelab's
#: placement (module notes).
PETERKA_242_BAND_HARMONICS: tuple[tuple[int, ...], ...] = _continued_bands()
#: The band layout of each named PRTS sequence (:data:`posturelab.model.tilt.PRTS_SEQUENCES`).
SEQUENCE_BANDS: dict[str, tuple[tuple[int, ...], ...]] = {
    "posturelab-80": PETERKA_BAND_HARMONICS,
    "comtest-80": PETERKA_BAND_HARMONICS,
    "peterka-2002-242": PETERKA_242_BAND_HARMONICS,
}


def sequence_bands(tilt) -> tuple[tuple[int, ...], ...]:
    """The bands of a :class:`~posturelab.model.tilt.PRTSTilt`'s named sequence
    (:data:`SEQUENCE_BANDS`), or the 11 bands for an 80-state register without a name;
    one band per odd harmonic (the first 25) for any other. [-]"""
    name = getattr(tilt, "sequence_name", None)
    if name in SEQUENCE_BANDS:
        return SEQUENCE_BANDS[name]
    if getattr(tilt, "registers", 4) == 4:
        return PETERKA_BAND_HARMONICS
    return harmonic_bands(25)


def odd_harmonic_frequency(k, cycle_length: float) -> np.ndarray:
    """Frequency of the k-th odd harmonic (1-based), (2k − 1)/T. [Hz]"""
    return (2 * np.asarray(k, dtype=float) - 1) / float(cycle_length)


def peterka_bands() -> tuple[tuple[int, ...], ...]:
    """The 11 bands of an 80-state sequence (:data:`PETERKA_BAND_HARMONICS`)."""
    return PETERKA_BAND_HARMONICS


def harmonic_bands(count: int) -> tuple[tuple[int, ...], ...]:
    """One band per odd harmonic, the first ``count`` of them."""
    return tuple((k,) for k in range(1, int(count) + 1))


def check_bands(bands, n_available: int) -> tuple[tuple[int, ...], ...]:
    """Bands as tuples of 1-based odd-harmonic numbers, each within the first ``n_available``
    (those below the Nyquist frequency of the record)."""
    out = []
    try:
        bands = list(bands)
    except TypeError:
        raise ParameterError(f"bands must be a list of lists of odd-harmonic numbers, got "
                             f"{bands!r}"[:200]) from None
    for i, band in enumerate(bands):
        try:
            if any(isinstance(k, bool) or int(k) != k for k in band):
                raise ValueError
            members = tuple(int(k) for k in band)
        except (TypeError, ValueError, OverflowError):
            raise ParameterError(f"band {i + 1} must list whole odd-harmonic numbers, got "
                                 f"{band!r}"[:200]) from None
        if not members or any(k < 1 or k > n_available for k in members):
            raise ParameterError(f"band {i + 1} must list odd-harmonic numbers in 1 … "
                                 f"{n_available}, got {list(band)}")
        out.append(members)
    if not out:
        raise ParameterError("give at least one band")
    return tuple(out)


def resolve_bands(bands, n_available: int) -> tuple[tuple[int, ...], ...]:
    """The bands ``"peterka"`` (the 11 of an 80-state sequence), ``"harmonics"`` (one per
    odd harmonic below the Nyquist frequency: the first ``n_available``), a named sequence's
    (:data:`SEQUENCE_BANDS`) or a given list, checked (:func:`check_bands`)."""
    if isinstance(bands, str):
        if bands == "peterka":
            bands = peterka_bands()
        elif bands == "harmonics":
            bands = harmonic_bands(n_available)
        elif bands in SEQUENCE_BANDS:
            bands = SEQUENCE_BANDS[bands]
        else:
            raise ParameterError(f"bands must be 'peterka', 'harmonics', a PRTS sequence's "
                                 f"name ({', '.join(SEQUENCE_BANDS)}) or a list of bands, "
                                 f"got {bands!r}")
    return check_bands(bands, n_available)


def band_frequencies(bands, cycle_length: float) -> np.ndarray:
    """Mean frequency of each band's harmonics (the sum of their odd numbers over count × T,
    one rounding: 0.33 Hz prints as 0.33). [Hz]"""
    return np.array([float(np.sum(2 * np.asarray(b, dtype=np.int64) - 1))
                     / (len(b) * float(cycle_length)) for b in bands])
