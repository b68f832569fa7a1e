"""Stimulus harmonics and frequency bands of a periodic (PRTS) experiment.

A PRTS of cycle length T [s] has its power at the odd harmonics of f0 = 1/T (its second
half-period is the negative of the first): (2k − 1)·f0 for k = 1, 2, … Peterka (2002,
J Neurophysiol 88:1097–1118) averaged the spectra of an 80-state, 20 s PRTS over 11 bands of
odd harmonics, numbered from 1 (the k-th odd harmonic is (2k − 1)/T):

    [1], [2], [3, 4], [4, 5], [5–7], [6–9], [8–11], [10–13], [12–16], [16–20], [20–25]

whose mean frequencies are 0.05, 0.15, 0.30, 0.40, 0.55, 0.70, 0.90, 1.10, 1.35, 1.75 and
2.20 Hz. For another cycle length the same rule holds in harmonic numbers (the band
frequencies scale with 1/T); :func:`harmonic_bands` gives one band per odd harmonic instead,
and a user-given list of bands is any list of harmonic-number lists.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError

__all__ = ["PETERKA_BAND_HARMONICS", "PETERKA_BAND_FREQUENCIES", "odd_harmonic_frequency",
           "peterka_bands", "harmonic_bands", "band_frequencies", "check_bands"]

#: Peterka's 11 bands: 1-based numbers of the odd harmonics averaged in each.
PETERKA_BAND_HARMONICS: tuple[tuple[int, ...], ...] = (
    (1,), (2,), (3, 4), (4, 5), (5, 6, 7), (6, 7, 8, 9), (8, 9, 10, 11), (10, 11, 12, 13),
    (12, 13, 14, 15, 16), (16, 17, 18, 19, 20), (20, 21, 22, 23, 24, 25))
#: The band frequencies Peterka (2002) prints for the 20 s cycle. [Hz]
PETERKA_BAND_FREQUENCIES: tuple[float, ...] = (0.05, 0.15, 0.30, 0.40, 0.55, 0.70, 0.90,
                                               1.10, 1.35, 1.75, 2.20)


def odd_harmonic_frequency(k, cycle_length: float) -> np.ndarray:
    """Frequency of the k-th odd harmonic (1-based), (2k − 1)/T. [Hz]"""
    return (2 * np.asarray(k, dtype=float) - 1) / float(cycle_length)


def peterka_bands() -> tuple[tuple[int, ...], ...]:
    """Peterka's 11 bands (:data:`PETERKA_BAND_HARMONICS`)."""
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
    """The bands ``"peterka"``, ``"harmonics"`` (one per odd harmonic below the Nyquist
    frequency: the first ``n_available``) or a given list, checked (:func:`check_bands`)."""
    if isinstance(bands, str):
        if bands == "peterka":
            bands = peterka_bands()
        elif bands == "harmonics":
            bands = harmonic_bands(n_available)
        else:
            raise ParameterError(f"bands must be 'peterka', 'harmonics' or a list of bands, "
                                 f"got {bands!r}")
    return check_bands(bands, n_available)


def band_frequencies(bands, cycle_length: float) -> np.ndarray:
    """Mean frequency of each band's harmonics. [Hz]"""
    return np.array([odd_harmonic_frequency(np.array(b), cycle_length).mean() for b in bands])
