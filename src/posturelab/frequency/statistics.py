"""FRF statistics: bootstrap bands for one FRF, and two groups of FRFs compared.

**Bootstrap bands of one FRF** (:func:`bootstrap_frf_bands`). A periodic (PRTS) trial of C
cycles gives C response spectra Y_c at the stimulus harmonics; the band FRF is
Ĥ = Σ_c Σ_j X̄_cj Y_cj / Σ_c Σ_j |X_cj|² over the band's harmonics j (as
:func:`posturelab.frequency.estimate_frf` computes it). The cycles are resampled with
replacement (R times, seeded), each resample's band FRF Ĥ* computed the same way, and
the deviations Ĥ* − Ĥ scaled by √(C/(C − 1)), the bootstrap's known shortfall for a mean
of C draws (Efron and Tibshirani, *An Introduction to the Bootstrap*, 1993, §5.2 — the
bootstrap variance of a mean is (C − 1)/C times the unbiased one). From them:

* **pointwise** bands per band: percentile intervals of Re, Im, the gain and the phase,
  and the radius of the circle about Ĥ that holds ``level`` of the resamples;
* **simultaneous** bands (all bands at once, after Lenhoff et al. 1999, Gait Posture
  9:10–17, and Olshen et al. 1989, Ann Stat 17:1419–1440): circles of radius c·s_k, s_k
  the bootstrap root-mean-square of |Ĥ*_k − Ĥ_k| and c the ``level`` quantile over the
  resamples of max_k |Ĥ*_k − Ĥ_k| / s_k.

Bootstrap bands for FRFs in posturography are proposed by Lippi (2025, "Bootstrap
prediction and confidence bands for frequency response functions in posturography",
arXiv:2504.20588), over subjects; here the resampled unit is the stimulus cycle, the unit
over which the response of a periodic stimulus is independent (Pintelon and Schoukens,
*System Identification*, 2nd ed. 2012, ch. 2: the sample variance over periods; Zoubir
and Iskander, *Bootstrap Techniques for Signal Processing*, 2004, for the bootstrap of
independent blocks). With C cycles there are only C(2C − 1, C) distinct resamples: 2
cycles give 3, 5 give 126. And the bootstrap of few cycles is narrow: over 100 seeded
trials of a known system with white noise in the response (the tests), the 95 % bands
held the true band FRF as follows (pointwise per band; simultaneous, all 11 at once):

    cycles        5      8      12     20
    pointwise     89 %   91 %   92 %   93 %
    simultaneous  70 %   83 %   88 %   94 %

Below about 12 cycles the analytic circles of the estimate (whose F quantile knows the
degrees of freedom; measured 95 %) are the better pointwise bounds.

**Two groups compared** (:func:`compare_frf_groups`). Group A has n_a subjects' FRFs, B
n_b, each over the same B bands. Per band k, the difference of the group means
Δ_k = H̄_A,k − H̄_B,k with percentile intervals of Re Δ_k and Im Δ_k from an unpaired
bootstrap (subjects resampled with replacement within each group, seeded; after Lippi
2025, "Unpaired test for the comparison of frequency response functions groups",
arXiv:2505.23778), each group's resampled mean deviation scaled by √(n/(n − 1)) as for the
cycles above. They remain a little narrow for small groups (the normal, not Student's,
quantile): for 10 subjects per group the tests measure 93 % coverage of each part for
95 % asked. The global test is a permutation test (the group labels shuffled,
seeded) of the statistic

    T = Σ_k  n_a n_b / (n_a + n_b) · Δ_kᵀ S_k⁻¹ Δ_k

with Δ_k = [Re Δ_k, Im Δ_k] and S_k the pooled within-group 2×2 covariance of
[Re H_k, Im H_k]: the sum over the bands of each band's two-sample Hotelling T². Why
this statistic: (i) each band is measured in its own scatter, so the bands whose gain
and spread are large (the low frequencies) do not outweigh the rest, as they would in a
plain Euclidean distance; (ii) within a band the real and imaginary parts are correlated
(the scatter is an ellipse, not a circle), which S_k takes into account; (iii) it needs
only n_a + n_b ≥ 4 subjects, where one Hotelling T² over all 2B = 22 real numbers of
the 11 bands needs n_a + n_b ≥ 24 for its covariance to be invertible; (iv) the
correlation between bands, which it leaves out, does not bias the test: the permutation
distribution is exact under the null hypothesis that the two groups' FRFs have one
distribution (exchangeable labels) whatever that correlation (Pesarin and Salmaso,
*Permutation Tests for Complex Data*, 2010, ch. 4, for such sums of partial statistics).
S_k is recomputed in every permutation; since the pooled covariance is the total scatter
less the groups' mean terms, only the group means change with the labels, and all
permutations are one matrix product (module code). The p-value counts the observed split
among the permutations, p = (1 + #{T* ≥ T}) / (1 + P) (Phipson and Smyth 2010, Stat Appl
Genet Mol Biol 9:39: never 0); when the number of distinct splits C(n_a + n_b, n_a) is at
most P, every split is enumerated and p is exact.

**Which bands differ.** The bootstrap intervals above are far too narrow for a handful of
subjects (with 2–3 per group, 2–5 of 11 bands of two groups from one population excluded
0 at 95 %), so they do not say which bands differ. Each band's own term of T,
T_k = n_a n_b/(n_a + n_b) Δ_kᵀ S_k⁻¹ Δ_k, is tested by the same permutations (the same
splits, its own count): p_k = (1 + #{T*_k ≥ T_k}) / (1 + P), exact when every split is
enumerated. Under the null hypothesis each p_k is valid at any n (the labels are
exchangeable), so a band is marked when p_k ≤ 1 − ``level``, uncorrected for the number
of bands (the global p is the test of all of them). With few subjects no band can be
marked: the smallest attainable p_k is 1/C(n_a + n_b, n_a) (2/C with n_a = n_b, where the
swapped split gives the same T_k): 1/3 for 2 + 2 subjects, 1/10 for 3 + 2, 1/10 for 3 + 3,
0.029 for 4 + 4 (``smallest_band_p``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validation import finite_array
from ..errors import ParameterError

__all__ = ["BootstrapBands", "bootstrap_frf_bands", "GroupComparison", "compare_frf_groups",
           "frf_matrix", "band_t2_statistic", "permutation_statistics",
           "permutation_band_statistics", "MAX_PERMUTATIONS",
           "MAX_RESAMPLES", "MAX_SUBJECTS"]

#: Most permutations a comparison may ask for. [-]
MAX_PERMUTATIONS = 1_000_000
#: Most bootstrap resamples. [-]
MAX_RESAMPLES = 100_000
#: Most FRFs in one group. [-]
MAX_SUBJECTS = 10_000
#: Numbers held at once by the vectorised permutations and resamples (memory bound). [-]
_CHUNK_NUMBERS = 4_000_000


def _count(name: str, value, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) \
            or not low <= value <= high:
        raise ParameterError(f"{name} must be an integer in [{low:,}, {high:,}], got "
                             f"{value!r}"[:200])
    return int(value)


def _level(level) -> float:
    if isinstance(level, bool) or not isinstance(level, int | float | np.floating) \
            or not 0.5 <= float(level) < 1.0:
        raise ParameterError(f"level must be in [0.5, 1), got {level!r}"[:200])
    return float(level)


def _seed(seed) -> int:
    return _count("seed", seed, 0, 2**63 - 1)


@dataclass(frozen=True)
class BootstrapBands:
    """Bootstrap bands of one FRF over its stimulus cycles (module notes).

    Attributes
    ----------
    frequency : numpy.ndarray, shape (B,)
        [Hz]
    frf : numpy.ndarray of complex, shape (B,)
        The estimate Ĥ. [response unit / stimulus unit]
    re_ci, im_ci : numpy.ndarray, shape (B, 2)
        Pointwise percentile intervals of Re H and Im H.
    gain_ci : numpy.ndarray, shape (B, 2)
        Of |H|.
    phase_ci_deg : numpy.ndarray, shape (B, 2)
        Of arg H, about the estimate's unwrapped phase. [deg]
    radius : numpy.ndarray, shape (B,)
        Pointwise: the circle about Ĥ holding ``level`` of the resamples.
    simultaneous_radius : numpy.ndarray, shape (B,)
        Simultaneous: circles that hold every band at once in ``level`` of the resamples.
    level : float
        [-]
    resamples, n_cycles, seed : int
    """

    frequency: np.ndarray
    frf: np.ndarray
    re_ci: np.ndarray
    im_ci: np.ndarray
    gain_ci: np.ndarray
    phase_ci_deg: np.ndarray
    radius: np.ndarray
    simultaneous_radius: np.ndarray
    level: float
    resamples: int
    n_cycles: int
    seed: int

    def to_dict(self) -> dict:
        """Plain numbers for JSON (complex as {re, im}, intervals as [low, high])."""
        def pairs(a):
            return [[float(lo), float(hi)] for lo, hi in a]

        return {"frequency": [float(f) for f in self.frequency],
                "frf": [{"re": float(h.real), "im": float(h.imag)} for h in self.frf],
                "re_ci": pairs(self.re_ci), "im_ci": pairs(self.im_ci),
                "gain_ci": pairs(self.gain_ci), "phase_ci_deg": pairs(self.phase_ci_deg),
                "radius": [float(r) for r in self.radius],
                "simultaneous_radius": [float(r) for r in self.simultaneous_radius],
                "level": self.level, "resamples": self.resamples,
                "n_cycles": self.n_cycles, "seed": self.seed}


def bootstrap_frf_bands(stimulus, response, sample_rate: float, cycle_length: float, *,
                        discard_cycles: int = 0, bands="peterka", response_sign: float = 1.0,
                        resamples: int = 2000, level: float = 0.95,
                        seed: int = 0) -> BootstrapBands:
    """Bootstrap bands of the FRF of ``response`` to a periodic ``stimulus``, resampling the
    stimulus cycles (module notes).

    Parameters
    ----------
    stimulus, response, sample_rate, cycle_length, discard_cycles, bands, response_sign
        As for :func:`posturelab.frequency.estimate_frf` (one trial, or a list of trials
        of one condition; their cycles are pooled). [stimulus unit], [response unit],
        [Hz], [s], [-]
    resamples : int
        R, 1 … :data:`MAX_RESAMPLES`. [-]
    level : float
        Coverage of the bands, in [0.5, 1). [-]
    seed : int
        Of the resampling.

    Returns
    -------
    BootstrapBands
    """
    from .estimate import estimate_frf

    R = _count("resamples", resamples, 1, MAX_RESAMPLES)
    q = _level(level)
    rng = np.random.default_rng(_seed(seed))
    est = estimate_frf(stimulus, response, sample_rate, cycle_length,
                       discard_cycles=discard_cycles, bands=bands,
                       response_sign=response_sign)  # every check, and the point estimate
    L = int(round(float(sample_rate) * float(cycle_length)))
    several = isinstance(stimulus, list | tuple) and bool(stimulus) and isinstance(
        stimulus[0], list | tuple | np.ndarray)  # several trials, as estimate_frf takes
    xs, ys = (stimulus, response) if several else ([stimulus], [response])
    X, Y = [], []
    for x, y in zip(xs, ys, strict=True):
        x = finite_array("stimulus", x, (None,))
        y = float(response_sign) * finite_array("response", y, (None,))
        X.append(np.fft.rfft(x.reshape(-1, L)[discard_cycles:], axis=1))
        Y.append(np.fft.rfft(y.reshape(-1, L)[discard_cycles:], axis=1))
    X, Y = np.concatenate(X), np.concatenate(Y)
    C = X.shape[0]
    bins = [np.array([2 * k - 1 for k in band]) for band in est.bands]
    # per cycle and band: the cross- and auto-spectra summed over the band's harmonics
    cross = np.stack([np.sum(np.conj(X[:, b]) * Y[:, b], axis=1) for b in bins], axis=1)
    auto = np.stack([np.sum(np.abs(X[:, b]) ** 2, axis=1) for b in bins], axis=1)
    H = cross.sum(axis=0) / auto.sum(axis=0)
    chunk = max(1, _CHUNK_NUMBERS // max(1, C * len(bins)))
    dev = np.empty((R, len(bins)), dtype=complex)
    for lo in range(0, R, chunk):
        hi = min(R, lo + chunk)
        counts = rng.multinomial(C, np.full(C, 1.0 / C), size=hi - lo).astype(float)
        dev[lo:hi] = counts @ cross / (counts @ auto) - H
    dev *= math.sqrt(C / (C - 1))
    star = H + dev
    tail = (1 - q) / 2

    def interval(values):
        return np.stack([np.quantile(values, tail, axis=0),
                         np.quantile(values, 1 - tail, axis=0)], axis=1)

    phase = np.degrees(np.unwrap(np.angle(H)))
    dphase = np.degrees(np.angle(star / H))  # about the estimate, in (−180°, 180°]
    distance = np.abs(dev)
    rms = np.sqrt(np.mean(distance ** 2, axis=0))
    with np.errstate(invalid="ignore", divide="ignore"):
        scaled = np.where(rms > 0, distance / np.where(rms > 0, rms, 1.0), 0.0)
    c = float(np.quantile(scaled.max(axis=1), q))
    return BootstrapBands(est.frequency, H, interval(star.real), interval(star.imag),
                          interval(np.abs(star)), phase[:, None] + interval(dphase),
                          np.quantile(distance, q, axis=0), c * rms, q, R, C, int(seed))


def frf_matrix(frfs, what: str = "FRFs") -> tuple[np.ndarray, np.ndarray]:
    """The band frequencies [Hz] and an (N, B) complex array of N FRFs, each an
    :class:`~posturelab.frequency.FRFEstimate`, an :class:`~posturelab.frequency.FRFTable`
    or a complex array of B values (then the frequencies are NaN); all over the same bands
    (frequencies equal within 0.1 %)."""
    rows, freq = [], None
    try:
        items = list(frfs)
    except TypeError:
        raise ParameterError(f"{what} must be a list of FRFs, got {type(frfs).__name__}") \
            from None
    if not 1 <= len(items) <= MAX_SUBJECTS:
        raise ParameterError(f"{what}: give 1 … {MAX_SUBJECTS:,} FRFs, got {len(items)}")
    for i, item in enumerate(items):
        if hasattr(item, "frf") and hasattr(item, "frequency"):
            h, f = np.asarray(item.frf, dtype=complex), np.asarray(item.frequency, float)
        else:
            h = np.asarray(item)
            if h.dtype == bool or not np.issubdtype(h.dtype, np.number):
                raise ParameterError(f"{what} {i + 1} must be complex numbers")
            h = h.astype(complex)
            f = np.full(h.shape, np.nan)
        if h.ndim != 1 or not np.all(np.isfinite(h)):
            raise ParameterError(f"{what} {i + 1} must be a finite 1-D FRF")
        if freq is None:
            freq = f
        elif h.size != freq.size:
            raise ParameterError(f"{what} {i + 1} has {h.size} bands, the first {freq.size}")
        elif not np.allclose(f, freq, rtol=1e-3, equal_nan=True):
            raise ParameterError(f"{what} {i + 1} is at other frequencies than the first "
                                 f"({', '.join(f'{v:.3g}' for v in f[:4])} … Hz against "
                                 f"{', '.join(f'{v:.3g}' for v in freq[:4])} … Hz)")
        rows.append(h)
    return freq, np.stack(rows)


def _split(Z: np.ndarray) -> np.ndarray:
    """(N, B) complex → (N, 2B) real: the real parts of the bands, then the imaginary."""
    return np.concatenate([Z.real, Z.imag], axis=1)


def band_t2_statistic(a: np.ndarray, b: np.ndarray) -> float:
    """T of one split, written plainly (module notes): ``a`` (n_a, B) and ``b`` (n_b, B)
    complex FRFs; per band the two-sample Hotelling T² with the pooled 2×2 covariance,
    summed over the bands. The reference that :func:`permutation_statistics` is checked
    against. [-]"""
    na, nb = len(a), len(b)
    total = 0.0
    for k in range(a.shape[1]):
        za = np.stack([a[:, k].real, a[:, k].imag], axis=1)
        zb = np.stack([b[:, k].real, b[:, k].imag], axis=1)
        d = za.mean(axis=0) - zb.mean(axis=0)
        pooled = ((za - za.mean(axis=0)).T @ (za - za.mean(axis=0))
                  + (zb - zb.mean(axis=0)).T @ (zb - zb.mean(axis=0))) / (na + nb - 2)
        total += na * nb / (na + nb) * float(d @ np.linalg.solve(pooled, d))
    return total


def permutation_statistics(Z: np.ndarray, in_a: np.ndarray) -> np.ndarray:
    """T for many splits at once (module notes): the sum over the bands of
    :func:`permutation_band_statistics`. [-]"""
    return permutation_band_statistics(Z, in_a).sum(axis=1)


def permutation_band_statistics(Z: np.ndarray, in_a: np.ndarray) -> np.ndarray:
    """Each band's term T_k of T for many splits at once (module notes).

    Parameters
    ----------
    Z : numpy.ndarray of complex, shape (N, B)
        All subjects' FRFs.
    in_a : numpy.ndarray of bool, shape (P, N)
        Each row a split: True for the subjects in group A (the same count in every row).

    Returns
    -------
    numpy.ndarray, shape (P, B)
        [-]
    """
    N, B = Z.shape
    na = int(in_a[0].sum())
    nb = N - na
    re, im = Z.real, Z.imag
    total = Z.sum(axis=0)
    scatter = np.stack([np.sum(re * re, axis=0), np.sum(re * im, axis=0),
                        np.sum(im * im, axis=0)])  # Σ z zᵀ per band: xx, xy, yy
    ma = (in_a.astype(float) @ Z) / na  # (P, B) complex
    mb = (total - na * ma) / nb
    d = ma - mb

    def mean_terms(m, n):
        return n * np.stack([m.real * m.real, m.real * m.imag, m.imag * m.imag])

    S = (scatter[:, None, :] - mean_terms(ma, na) - mean_terms(mb, nb)) / (N - 2)
    sxx, sxy, syy = S
    det = sxx * syy - sxy * sxy
    dx, dy = d.real, d.imag
    with np.errstate(invalid="ignore", divide="ignore"):
        q = (syy * dx * dx - 2 * sxy * dx * dy + sxx * dy * dy) / det
    # each T_k is a quadratic form in a positive definite matrix: >= 0; rounding can leave
    # -1e-16 where the means agree (NaN, a singular split, stays NaN)
    return np.maximum(na * nb / (na + nb) * q, 0.0)


def _at_least(statistics: np.ndarray, observed):
    """How many permuted statistics reach the observed one (to rounding: 1e-12 relative and
    1e-9 absolute, T being dimensionless and of order one for chance differences, so equal
    means tie however rounding leaves them); a split whose pooled covariance is singular
    (NaN) counts as reaching it, which can only make p larger. Over axis 0: per band for
    (P, B) statistics and (B,) observed ones."""
    return np.sum(~(statistics < observed * (1 - 1e-12) - 1e-9), axis=0)


@dataclass(frozen=True)
class GroupComparison:
    """Two groups of FRFs compared (module notes).

    Attributes
    ----------
    frequency : numpy.ndarray, shape (B,)
        [Hz] (NaN when the FRFs did not say).
    difference : numpy.ndarray of complex, shape (B,)
        Δ = H̄_A − H̄_B. [FRF unit]
    re_ci, im_ci : numpy.ndarray, shape (B, 2)
        Percentile intervals of Re Δ and Im Δ (unpaired bootstrap; descriptive, too
        narrow for small groups: :attr:`band_p_values` says which bands differ).
    mean_a, mean_b : numpy.ndarray of complex, shape (B,)
    statistic : float
        T of the observed split. [-]
    p_value : float
        Of the permutation test. [-]
    permutations : int
        Splits drawn (or all of them when ``exact``). [-]
    exact : bool
        Every distinct split enumerated.
    n_a, n_b, resamples, seed : int
    level : float
    band_p_values : numpy.ndarray, shape (B,)
        Each band's permutation p-value, from the same splits as ``p_value`` (module notes,
        "Which bands differ"). [-]
    smallest_band_p : float
        The smallest p-value a band can have with these group sizes and splits. [-]
    """

    frequency: np.ndarray
    difference: np.ndarray
    re_ci: np.ndarray
    im_ci: np.ndarray
    mean_a: np.ndarray
    mean_b: np.ndarray
    statistic: float
    p_value: float
    permutations: int
    exact: bool
    n_a: int
    n_b: int
    resamples: int
    seed: int
    level: float
    statistic_name: str = field(default="sum over bands of the two-sample Hotelling T² of "
                                        "[Re H, Im H] (pooled 2×2 covariance per band)")
    band_p_values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    smallest_band_p: float = math.nan

    @property
    def band_differs(self) -> np.ndarray:
        """Per band, p_k ≤ 1 − ``level`` (uncorrected for the number of bands). [-]"""
        return self.band_p_values <= 1.0 - self.level + 1e-12

    def to_dict(self) -> dict:
        """What ``posturelab compare-frf --json`` prints."""
        def cplx(z):
            return {"re": float(z.real), "im": float(z.imag)}

        bands = []
        for k in range(self.difference.size):
            bands.append({"frequency": float(self.frequency[k]),
                          "mean_a": cplx(self.mean_a[k]), "mean_b": cplx(self.mean_b[k]),
                          "difference": cplx(self.difference[k]),
                          "re_ci": [float(v) for v in self.re_ci[k]],
                          "im_ci": [float(v) for v in self.im_ci[k]],
                          "excludes_zero": bool(not (self.re_ci[k, 0] <= 0 <= self.re_ci[k, 1]
                                                     and self.im_ci[k, 0] <= 0
                                                     <= self.im_ci[k, 1])),
                          "p_value": float(self.band_p_values[k]),
                          "differs": bool(self.band_differs[k])})
        return {"p_value": self.p_value, "statistic": self.statistic,
                "statistic_name": self.statistic_name, "permutations": self.permutations,
                "exact": self.exact, "n_a": self.n_a, "n_b": self.n_b, "level": self.level,
                "resamples": self.resamples, "seed": self.seed,
                "smallest_band_p": float(self.smallest_band_p), "bands": bands}


def compare_frf_groups(a, b, *, permutations: int = 10_000, resamples: int = 2000,
                       level: float = 0.95, seed: int = 0) -> GroupComparison:
    """Compare two groups of FRFs band by band and as a whole (module notes).

    Parameters
    ----------
    a, b : lists of FRFs
        Each a list of :class:`~posturelab.frequency.FRFEstimate`,
        :class:`~posturelab.frequency.FRFTable` or complex arrays of B values (one per
        subject), all over the same bands; at least 2 per group and 4 in all.
    permutations : int
        P, 1 … :data:`MAX_PERMUTATIONS`: random splits; all splits when there are no more
        than P. [-]
    resamples : int
        Of the unpaired bootstrap of the per-band intervals, 1 … :data:`MAX_RESAMPLES`. [-]
    level : float
        Of the per-band intervals, in [0.5, 1). [-]
    seed : int
        Of the permutations and the resamples.

    Returns
    -------
    GroupComparison
    """
    from itertools import combinations

    P = _count("permutations", permutations, 1, MAX_PERMUTATIONS)
    R = _count("resamples", resamples, 1, MAX_RESAMPLES)
    q = _level(level)
    s = _seed(seed)
    fa, A = frf_matrix(a, "group A FRF")
    fb, Bm = frf_matrix(b, "group B FRF")
    if A.shape[1] != Bm.shape[1] or not np.allclose(fa, fb, rtol=1e-3, equal_nan=True):
        raise ParameterError(f"the groups' FRFs are over other bands ({A.shape[1]} bands "
                             f"in A, {Bm.shape[1]} in B, or other frequencies)")
    na, nb = len(A), len(Bm)
    if na < 2 or nb < 2:
        raise ParameterError(f"each group needs at least 2 FRFs (a pooled covariance needs "
                             f"n_a + n_b >= 4); got {na} and {nb}")
    Z = np.concatenate([A, Bm])
    N = na + nb
    observed = np.zeros((1, N), dtype=bool)
    observed[0, :na] = True
    T_k = permutation_band_statistics(Z, observed)[0]
    T = float(T_k.sum())
    if not math.isfinite(T):
        raise ParameterError("a band's FRFs have no scatter (a singular pooled covariance): "
                             "identical FRFs cannot be compared")
    rng = np.random.default_rng(s)
    splits = math.comb(N, na)
    chunk = max(1, _CHUNK_NUMBERS // max(N, Z.shape[1] * 8))
    exceed = 0
    exceed_k = np.zeros(Z.shape[1], dtype=np.int64)
    if splits <= P:  # every split, the observed one among them
        it = combinations(range(N), na)
        done = 0
        while done < splits:
            n = min(chunk, splits - done)
            in_a = np.zeros((n, N), dtype=bool)
            for r in range(n):
                in_a[r, list(next(it))] = True
            terms = permutation_band_statistics(Z, in_a)
            exceed += int(_at_least(terms.sum(axis=1), T))
            exceed_k += _at_least(terms, T_k)
            done += n
        p, drawn = exceed / splits, splits
        band_p = exceed_k / splits
        smallest = (2 if na == nb else 1) / splits
    else:
        for lo in range(0, P, chunk):
            n = min(chunk, P - lo)
            order = rng.permuted(np.tile(np.arange(N), (n, 1)), axis=1)[:, :na]
            in_a = np.zeros((n, N), dtype=bool)
            np.put_along_axis(in_a, order, True, axis=1)
            terms = permutation_band_statistics(Z, in_a)
            exceed += int(_at_least(terms.sum(axis=1), T))
            exceed_k += _at_least(terms, T_k)
        p, drawn = (1 + exceed) / (1 + P), P
        band_p = (1 + exceed_k) / (1 + P)
        smallest = max(1 / (1 + P), (2 if na == nb else 1) / splits)
    ma, mb = A.mean(axis=0), Bm.mean(axis=0)
    diff = ma - mb
    boot = np.empty((R, Z.shape[1]), dtype=complex)
    step = max(1, _CHUNK_NUMBERS // max(1, N * Z.shape[1]))
    for lo in range(0, R, step):
        n = min(step, R - lo)
        boot[lo:lo + n] = diff + (
            math.sqrt(na / (na - 1)) * (A[rng.integers(0, na, (n, na))].mean(axis=1) - ma)
            - math.sqrt(nb / (nb - 1)) * (Bm[rng.integers(0, nb, (n, nb))].mean(axis=1) - mb))
    tail = (1 - q) / 2

    def interval(v):
        return np.stack([np.quantile(v, tail, axis=0), np.quantile(v, 1 - tail, axis=0)],
                        axis=1)

    return GroupComparison(fa, diff, interval(boot.real), interval(boot.imag),
                           ma, mb, T, float(p), int(drawn),
                           splits <= P, na, nb, R, s, q,
                           band_p_values=band_p.astype(float), smallest_band_p=float(smallest))
