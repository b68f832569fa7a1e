"""FRF estimation from measured series of a periodic stimulus (Peterka 2002's method).

Given a stimulus x(t) and a response y(t) sampled at f_s over whole cycles of length T:

1. the record is cut into cycles (``discard_cycles`` leading ones dropped: the transient);
2. each cycle's DFT is taken, X_c(f_k), Y_c(f_k), at the stimulus harmonics;
3. the auto- and cross-spectra are averaged over cycles (and trials) and then over the
   harmonics of each band: G_xx = ⟨|X|²⟩, G_yy = ⟨|Y|²⟩, G_xy = ⟨X̄ Y⟩;
4. the FRF is H = G_xy / G_xx, the coherence γ² = |G_xy|² / (G_xx G_yy).

95 % bounds: with n_d the number of spectral estimates averaged in a band (cycles × trials ×
harmonics), the true H lies, with 95 % probability, within a circle about the estimate of
radius r·|H|. For a periodic stimulus (the same PRTS every cycle) and noise in the response,
Ĥ − H is complex normal with variance σ²/Σ|X|² and the residual variance has 2(n_d − 1)
degrees of freedom, so (``bounds="periodic"``, the default; e.g. Pintelon and Schoukens,
*System Identification: A Frequency Domain Approach*, 2nd ed. 2012, ch. 2)

    r² = F_{0.95}(2, 2 n_d − 2) / (n_d − 1) · (1 − γ²) / γ²,

defined from n_d = 2 on (two cycles of a one-harmonic band: F_{0.95}(2, 2) = 19). The same
form, with the same F quantiles tabulated (19.0 for two cycles of a one-point band), is
the one of COMTEST's analysis (Eurobench; github.com/VittorioFreiburg/COMTEST,
ANALYSIS/MATLAB/PRTS2020.m: r = √(2(1 − γ²) F / (dof − 2) · G_yy/G_xx), dof = 2 n_d).

``bounds="otnes-enochson"`` gives the form Peterka 2002 used (after Otnes and Enochson 1972;
Bendat and Piersol, *Random Data*, 4th ed. 2010, §9.2.4), r² = 2/(n_d − 2) · F_{0.95}(2,
2 n_d − 4) · (1 − γ²)/γ², derived for random stimuli: for a periodic one it is about √2
wider (the tests measure 95 % coverage of the circle for the first, over 99.9 % for this).
The gain bounds are |H|(1 ± r) (the lower clipped at 0), the phase bounds ±asin(r) (±180°
when r >= 1). Phase [deg] is unwrapped across the bands from the first, which lies in
(−180°, 180°].

Precision per band (what :func:`posturelab.frequency.fit.fit_frf` weights by): the band's
Ĥ = Σ_j G_j Ĥ_j / Σ_j G_j over its harmonics j (G_j = Σ_c |X_cj|² over the C cycles,
Ĥ_j = Σ_c X̄_cj Y_cj / G_j) has, for noise of variance σ² in the response spectrum about the
band, E|Ĥ − H|² = σ² / Σ_j G_j. σ² is estimated from the scatter of the cycles about the
periodic response, s_j² = Σ_c |Y_cj − Ĥ_j X_cj|² / (C − 1) with 2(C − 1) degrees of
freedom at each DFT bin j (the sample variance over periods: Pintelon and Schoukens,
*System Identification*, 2nd ed. 2012, ch. 2; Schoukens, Godfrey and Schoukens 2018, IEEE
Control Syst Mag 38(4):49–88). σ² at harmonic j pools the bins about it (excited or not),
widened until they hold at least ``POOLED_DOF`` = 20 degrees of freedom: a power law
a·(f/f_j)^b fitted to ln s² over them (least squares; ln s² is biased by
ψ(C − 1) − ln(C − 1), which is removed), so that a noise spectrum falling with frequency,
as sway driven by motor noise does, is not averaged flat (with 2 cycles a flat mean put
the lowest band's variance at half and the mid bands' at 1.5× their spread over 80 seeded
runs). ``dof`` ν = 2(C − 1) × the bins about the band. The pooling (posturelab's choice:
it assumes the noise spectrum is smooth over those few bins) is what keeps the weights of
the lowest bands usable with 2 or 3 cycles, where one harmonic alone gives 2 or 4 degrees
of freedom. Unlike the band coherence, this does not count the FRF's variation across a
band's harmonics as noise (noise-free, a multi-harmonic band has γ² < 1 but a variance of
0). Bands that share harmonics are correlated: ``covariance`` = Σ_{j in both} G_j σ_j² /
(Σ_a G · Σ_b G), σ_j² the pooled noise about harmonic j (a fit that took Peterka's
overlapping bands as independent gave intervals 1.25× too narrow).

Sign: ``response_sign`` multiplies the response first. posturelab reports tilt FRFs so that a
body that follows the surface has H = 1 (gain 1, phase 0): its angles are positive leaning
forward while the tilt is positive toes-up, so a link or centre-of-mass angle responding to a
tilt is taken with sign −1 (``posturelab frf`` does this for a ``tilt`` stimulus).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .._validation import finite_array, float_in_range
from ..errors import ParameterError
from .bands import band_frequencies, resolve_bands

__all__ = ["FRFEstimate", "estimate_frf", "confidence_radius", "whole_cycles",
           "sign_convention", "BOUNDS", "MAX_SAMPLES"]

#: Degrees of freedom the noise estimate of a band pools at least (module notes). [-]
POOLED_DOF = 20
#: Most samples a record may have. [-]
MAX_SAMPLES = 50_000_000


@dataclass(frozen=True)
class FRFEstimate:
    """An FRF estimated from data.

    Attributes
    ----------
    frequency : numpy.ndarray, shape (B,)
        Band frequencies. [Hz]
    frf : numpy.ndarray of complex, shape (B,)
        H = G_xy/G_xx. [response unit / stimulus unit]
    gain : numpy.ndarray, shape (B,)
        |H|.
    phase_deg : numpy.ndarray, shape (B,)
        arg H, unwrapped. [deg]
    coherence : numpy.ndarray, shape (B,)
        γ² in [0, 1]. [-]
    gain_ci95 : numpy.ndarray, shape (B, 2)
        Lower and upper 95 % bounds of the gain (NaN where n_d <= 2).
    phase_ci95_deg : numpy.ndarray, shape (B, 2)
        Lower and upper 95 % bounds of the phase. [deg]
    averages : numpy.ndarray of int, shape (B,)
        n_d, the spectral estimates averaged per band. [-]
    bands : tuple of tuple of int
        The odd-harmonic numbers of each band (1-based).
    n_cycles : int
        Cycles used (over all trials). [-]
    cycle_length : float
        [s]
    cycle_stimulus, cycle_response : numpy.ndarray, shape (L,)
        The time-domain averages over the cycles used (the response with its sign).
    harmonic_frequency : tuple of numpy.ndarray
        Per band, the frequencies of its harmonics. [Hz]
    harmonic_weight : tuple of numpy.ndarray
        Per band, the stimulus auto-spectrum at them: a noise-free linear system's band FRF
        is Σ w H(f) / Σ w over them (:meth:`band_average`). [stimulus unit²]
    variance : numpy.ndarray, shape (B,)
        E|Ĥ − H|² estimated from the cycle-to-cycle scatter (module notes); empty when not
        known. [(response unit / stimulus unit)²]
    dof : numpy.ndarray, shape (B,)
        Its degrees of freedom ν. [-]
    response_sign : float
        The sign the response was multiplied by. [-]
    covariance : numpy.ndarray, shape (B, B)
        E[(Ĥ_a − H_a)(Ĥ_b − H_b)*]: bands that share harmonics (the 80-state ones do) are
        correlated (module notes). [(response unit / stimulus unit)²]
    warnings : tuple of str
        What the estimate itself warns of, one line each: the response sign probably the
        opposite of the recording's convention (:func:`sign_warning`; ``posturelab frf``
        prints these).
    """

    frequency: np.ndarray
    frf: np.ndarray
    gain: np.ndarray
    phase_deg: np.ndarray
    coherence: np.ndarray
    gain_ci95: np.ndarray
    phase_ci95_deg: np.ndarray
    averages: np.ndarray
    bands: tuple
    n_cycles: int
    cycle_length: float
    cycle_stimulus: np.ndarray = field(repr=False)
    cycle_response: np.ndarray = field(repr=False)
    harmonic_frequency: tuple = field(default=(), repr=False)
    harmonic_weight: tuple = field(default=(), repr=False)
    variance: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    dof: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    response_sign: float = 1.0
    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)
    warnings: tuple = ()

    def band_average(self, frf_at) -> np.ndarray:
        """The band FRF a noise-free linear system with FRF ``frf_at(f)`` [f in Hz, vectorised]
        would give with this stimulus: Σ w H / Σ w over each band's harmonics."""
        f = np.concatenate(self.harmonic_frequency)
        values = np.asarray(frf_at(f))
        out, start = [], 0
        for w in self.harmonic_weight:
            v = values[start:start + w.size]
            out.append(np.sum(w * v) / np.sum(w))
            start += w.size
        return np.array(out)

    def to_dict(self) -> dict:
        """The JSON of ``posturelab frf`` (frequency [Hz], FRF as {re, im}, gain, phase [deg],
        coherence, 95 % bounds as [low, high] pairs, each band's harmonics [Hz] and their
        share of the band's stimulus power (for a fit's band average), the standard error of
        the complex estimate √var, its degrees of freedom and the bands' covariance; null
        where not defined)."""
        def num(v):
            return None if not math.isfinite(v) else float(v)

        extra = {}
        if self.harmonic_weight:
            extra["harmonic_frequency"] = [[float(f) for f in fs]
                                           for fs in self.harmonic_frequency]
            extra["harmonic_weight"] = [[float(w / np.sum(ws)) for w in ws]
                                        for ws in self.harmonic_weight]
        if self.variance.size:
            extra.update({"frf_se": [num(math.sqrt(v)) for v in self.variance],
                          "dof": [num(v) for v in self.dof]})
        C = self.covariance
        if C.shape == (self.frf.size,) * 2 and np.any(C - np.diag(np.diag(C))):
            extra["frf_covariance"] = [[num(v) for v in row] for row in C]  # overlapping bands
        return {
            "frequency": [float(f) for f in self.frequency],
            "frf": [{"re": float(h.real), "im": float(h.imag)} for h in self.frf],
            "gain": [float(g) for g in self.gain],
            "phase_deg": [float(p) for p in self.phase_deg],
            "coherence": [float(c) for c in self.coherence],
            "gain_ci95": [[num(lo), num(hi)] for lo, hi in self.gain_ci95],
            "phase_ci95_deg": [[num(lo), num(hi)] for lo, hi in self.phase_ci95_deg],
            **extra,
            "response_sign": int(self.response_sign),
            "warnings": list(self.warnings),
        }


#: The forms of the 95 % bounds (module notes).
BOUNDS = ("periodic", "otnes-enochson")


def confidence_radius(coherence, averages, bounds: str = "periodic") -> np.ndarray:
    """r of the 95 % circle about H relative to |H| (module notes); NaN where n_d < 2
    (periodic) or n_d <= 2 (otnes-enochson)."""
    from scipy.stats import f as fisher

    if bounds not in BOUNDS:
        raise ParameterError(f"bounds must be one of {', '.join(BOUNDS)}, got {bounds!r}")
    try:
        g = np.clip(np.asarray(coherence, dtype=float), 1e-300, 1.0)
        n = np.asarray(averages, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"coherence and averages must be numbers, got {coherence!r}, "
                             f"{averages!r}"[:200]) from None
    if not (np.all(np.isfinite(g)) and np.all(np.isfinite(n))):
        raise ParameterError("coherence and averages must be finite")
    out = np.full(np.broadcast(g, n).shape, np.nan)
    ok = np.broadcast_to(n, out.shape) >= (2 if bounds == "periodic" else 3)
    if np.any(ok):
        nn = np.broadcast_to(n, out.shape)[ok]
        gg = np.broadcast_to(g, out.shape)[ok]
        if bounds == "periodic":
            scale = fisher.ppf(0.95, 2, 2 * nn - 2) / (nn - 1)
        else:
            scale = 2.0 / (nn - 2) * fisher.ppf(0.95, 2, 2 * nn - 4)
        out[ok] = np.sqrt(scale * (1.0 - gg) / gg)
    return out


#: Largest |value| a stimulus or response sample may have (its spectra must stay finite).
MAX_ABS_SAMPLE = 1e100


def _trials(values, label: str) -> list[np.ndarray]:
    arrays = values if isinstance(values, list | tuple) and values and isinstance(
        values[0], list | tuple | np.ndarray) else [values]
    out = []
    for a in arrays:
        if np.asarray(a).dtype == bool:
            raise ParameterError(f"{label} must be numbers, not booleans")
        x = finite_array(label, a, (None,))
        if x.size and np.max(np.abs(x)) > MAX_ABS_SAMPLE:
            raise ParameterError(f"{label} has a value of {np.max(np.abs(x)):g}; at most "
                                 f"{MAX_ABS_SAMPLE:g} in size")
        out.append(x)
    if not out:
        raise ParameterError(f"{label}: give at least one trial")
    return out


def estimate_frf(stimulus, response, sample_rate: float, cycle_length: float, *,
                 discard_cycles: int = 0, bands="peterka", response_sign: float = 1.0,
                 ci: str = "periodic", harmonic_step: int = 1) -> FRFEstimate:
    """Estimate the FRF of ``response`` to a periodic ``stimulus`` (module notes).

    Parameters
    ----------
    stimulus, response : array_like, shape (S,), or lists of them (several trials of one
        condition, each a whole number of cycles)
        [stimulus unit], [response unit]
    sample_rate : float
        f_s. [Hz]
    cycle_length : float
        T; f_s·T must be a whole number of samples and divide each record. [s]
    discard_cycles : int
        Leading cycles of each trial to drop. [-]
    bands : "peterka", "harmonics", a sequence's name or a list of lists of harmonic numbers
        The 11 bands of the 80-state protocol (COMTEST; "peterka" is their historical name,
        "posturelab-80" and "comtest-80" the same; the rule in 1-based odd-harmonic numbers,
        for any T), one band per odd harmonic below the Nyquist frequency, a named
        sequence's bands (:data:`~.bands.SEQUENCE_BANDS`), or the bands given.
    response_sign : {1, -1}
        Multiplies the response. Default +1 here (the response as recorded), while
        ``posturelab frf --response-sign`` defaults to −1 (posturelab's tilt convention):
        give −1 for posturelab's angles against a tilt, +1 for a translation. A sign that
        looks opposite to the recording's convention is in the result's ``warnings``. [-]
    ci : {"periodic", "otnes-enochson"}
        The form of the 95 % bounds (module notes).
    harmonic_step : int
        m: the stimulus repeats every T/m, so its harmonics are the DFT bins m·(2k − 1) of a
        cycle T (a dual-stimulus trial analysed over the common cycle T:
        :mod:`posturelab.frequency.dual`); its bands are numbered in its own odd
        harmonics. [-]

    Returns
    -------
    FRFEstimate
    """
    fs = float_in_range("sample rate [Hz]", sample_rate, 1e-3, 1e7, unit="Hz")
    T = float_in_range("cycle length [s]", cycle_length, 1e-3, 1e5, unit="s")
    if isinstance(response_sign, bool) or response_sign not in (1, -1, 1.0, -1.0):
        raise ParameterError(f"response_sign must be 1 or -1, got {response_sign!r}")
    if isinstance(discard_cycles, bool) or not isinstance(discard_cycles, int | np.integer) \
            or discard_cycles < 0:
        raise ParameterError(f"discard_cycles must be an integer >= 0, got {discard_cycles!r}")
    xs, ys = _trials(stimulus, "stimulus"), _trials(response, "response")
    if len(xs) != len(ys):
        raise ParameterError(f"{len(xs)} stimulus trials but {len(ys)} response trials")
    L = fs * T
    if abs(L - round(L)) > 1e-6 * max(1.0, L):
        raise ParameterError(f"the cycle length {T:g} s is {L:g} samples at {fs:g} Hz, not a "
                             "whole number")
    if round(L) < 4:
        raise ParameterError(f"the cycle length {T:g} s is {round(L)} samples at {fs:g} Hz; "
                             "a cycle needs at least 4")
    L = int(round(L))
    X, Y, cx, cy = [], [], [], []
    for i, (x, y) in enumerate(zip(xs, ys, strict=True)):
        if x.size != y.size:
            raise ParameterError(f"trial {i + 1}: stimulus has {x.size} samples, response "
                                 f"{y.size}")
        if x.size > MAX_SAMPLES:
            raise ParameterError(f"trial {i + 1} has {x.size:,} samples; at most "
                                 f"{MAX_SAMPLES:,}")
        if x.size % L:
            raise ParameterError(f"trial {i + 1}: {x.size} samples are not a whole number of "
                                 f"cycles of {L} samples ({T:g} s at {fs:g} Hz); on the "
                                 "command line --drop-partial leaves out the part cycle, "
                                 "--start sets where the first cycle begins")
        cycles = x.size // L - discard_cycles
        if cycles < 1:
            raise ParameterError(f"trial {i + 1} has {x.size // L} cycles; discarding "
                                 f"{discard_cycles} leaves none")
        xc = x.reshape(-1, L)[discard_cycles:]
        yc = (float(response_sign) * y).reshape(-1, L)[discard_cycles:]
        X.append(np.fft.rfft(xc, axis=1))
        Y.append(np.fft.rfft(yc, axis=1))
        cx.append(xc)
        cy.append(yc)
    X, Y = np.concatenate(X), np.concatenate(Y)
    n_cycles = X.shape[0]
    if n_cycles < 2:
        raise ParameterError(f"an FRF needs at least 2 cycles; the record has {n_cycles} "
                             "after discarding")
    if isinstance(harmonic_step, bool) or not isinstance(harmonic_step, int | np.integer) \
            or not 1 <= harmonic_step <= L // 4:
        raise ParameterError(f"harmonic_step must be an integer in [1, {L // 4}], got "
                             f"{harmonic_step!r}")
    step = int(harmonic_step)
    n_odd = L // (4 * step)  # odd bins step·(1, 3, …) below the Nyquist bin L/2
    chosen = resolve_bands(bands, n_odd)
    bins = [np.array([step * (2 * k - 1) for k in band]) for band in chosen]
    check_repeats(cx, xs, fs, T, np.concatenate(bins))
    yall = np.concatenate(cy)
    if np.ptp(yall) <= 1e-12 * np.max(np.abs(yall)):
        raise ParameterError(f"the response is constant ({float(yall.flat[0]) + 0.0:g} "
                             "throughout): it has no variation to relate to the stimulus "
                             "(a dead channel, or the wrong column?)")
    Gxx_h = np.mean(np.abs(X) ** 2, axis=0)
    Gyy_h = np.mean(np.abs(Y) ** 2, axis=0)
    Gxy_h = np.mean(np.conj(X) * Y, axis=0)
    Gxx = np.array([Gxx_h[b].mean() for b in bins])
    Gyy = np.array([Gyy_h[b].mean() for b in bins])
    Gxy = np.array([Gxy_h[b].mean() for b in bins])
    # no power: exactly none, or rounding noise (a constant column's DFT off DC is ~1e-16 of
    # its mean): below 1e-20 of the stimulus's total power per bin, the ratio is meaningless
    floor = 1e-20 * float(np.sum(Gxx_h))
    if np.any(Gxx <= floor):
        k = int(np.argmax(Gxx <= floor))
        raise ParameterError(f"the stimulus has no power in the band at "
                             f"{float(np.mean(bins[k])) / T:.4g} Hz"
                             + (" (it is constant)" if np.all(np.ptp(np.concatenate(cx),
                                                                     axis=None) == 0) else "")
                             + "; is it the periodic stimulus of this cycle length?")
    H = Gxy / Gxx
    with np.errstate(invalid="ignore", divide="ignore"):
        coh = np.where(Gyy > 0, np.abs(Gxy) ** 2 / (Gxx * Gyy), 0.0)
    coh = np.clip(coh, 0.0, 1.0)
    averages = np.array([n_cycles * b.size for b in bins])
    variance, dof, covariance = band_variance(X, Y, bins)
    r = confidence_radius(coh, averages, ci)
    gain = np.abs(H)
    phase = np.degrees(np.unwrap(np.angle(H)))
    gain_ci = np.stack([np.maximum(gain * (1 - r), 0.0), gain * (1 + r)], axis=1)
    half = np.where(r >= 1, 180.0, np.degrees(np.arcsin(np.minimum(r, 1.0))))
    phase_ci = np.stack([phase - half, phase + half], axis=1)
    est = FRFEstimate(band_frequencies(chosen, T / step), H, gain, phase, coh, gain_ci,
                      phase_ci,
                      averages, chosen, int(n_cycles), T,
                      np.concatenate(cx).mean(axis=0), np.concatenate(cy).mean(axis=0),
                      tuple(b / T for b in bins), tuple(Gxx_h[b] for b in bins),
                      variance, dof, float(response_sign), covariance)
    warning = sign_warning(est)
    return replace(est, warnings=(warning,)) if warning else est


#: Largest RMS cycle-to-cycle change of the stimulus, relative to √2 × its RMS about its
#: mean (what an unrelated next cycle gives), for it to count as periodic in the cycle
#: length (ours: a measured tilt with sensor noise repeats within a few %, a wrong cycle
#: length gives about 1, a PRTS's half cycle about 1.4). [-]
MAX_CYCLE_CHANGE = 0.25


def cycle_change(cycles: list[np.ndarray]) -> float:
    """The RMS change of a stimulus from each cycle to the next within a trial, relative to
    √2 × its RMS about its mean (0: it repeats exactly; about 1: unrelated cycles). [-]"""
    diffs = [np.diff(c, axis=0).ravel() for c in cycles if c.shape[0] >= 2]
    if not diffs:
        return 0.0
    every = np.concatenate([c.ravel() for c in cycles])
    spread = float(np.sqrt(np.mean((every - every.mean()) ** 2)))
    if spread == 0:
        return 0.0  # a constant stimulus: refused for its missing power
    d = np.concatenate(diffs)
    return float(np.sqrt(np.mean(d ** 2))) / (np.sqrt(2.0) * spread)


def repeat_period(x: np.ndarray, sample_rate: float) -> float | None:
    """The period [s] a stimulus repeats with, from its autocorrelation (the first lag,
    after it has fallen below 0.5, where it peaks above 0.9 and the record holds two such
    periods that repeat within :data:`MAX_CYCLE_CHANGE`); None when none is found."""
    x = np.asarray(x, dtype=float) - float(np.mean(x))
    n = x.size
    if n < 16 or not np.any(x):
        return None
    spec = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(np.abs(spec) ** 2)[:n // 2 + 1]
    e = np.cumsum(x ** 2)
    lag = np.arange(acf.size)
    head = e[n - 1 - lag]  # energy of x[:n - lag]
    tail = e[-1] - np.concatenate([[0.0], e[:acf.size - 1]])  # energy of x[lag:]
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.where(head * tail > 0, acf / np.sqrt(head * tail), 0.0)
    low = np.flatnonzero(r < 0.5)
    if not low.size:
        return None
    high = np.flatnonzero((r >= 0.9) & (lag > low[0]))
    if not high.size:
        return None
    start = int(high[0])
    end = start
    while end + 1 < r.size and r[end + 1] >= 0.9:
        end += 1
    P = start + int(np.argmax(r[start:end + 1]))
    whole = (n // P) * P
    if whole // P < 2 or cycle_change([x[:whole].reshape(-1, P)]) > MAX_CYCLE_CHANGE:
        return None
    return P / sample_rate


def band_cycle_change(cycles: list[np.ndarray], bins: np.ndarray) -> float:
    """:func:`cycle_change` over the analysed DFT bins only (the bands' harmonics of the cycle
    length): broadband sensor noise on a periodic stimulus counts only by its share in
    those bins, while a wrong cycle length changes them from cycle to cycle. [-]"""
    steps, power = [], []
    for c in cycles:
        spectra = np.fft.rfft(c, axis=1)[:, bins]
        power.append(np.sum(np.abs(spectra) ** 2, axis=1))
        if c.shape[0] >= 2:
            steps.append(np.sum(np.abs(np.diff(spectra, axis=0)) ** 2, axis=1))
    if not steps:
        return 0.0
    total = float(np.mean(np.concatenate(power)))
    if total == 0:
        return 0.0  # no power in the bands: refused with its own message
    return float(np.sqrt(np.mean(np.concatenate(steps)) / (2.0 * total)))


def check_repeats(cycles: list[np.ndarray], trials: list[np.ndarray], sample_rate: float,
                  cycle_length: float, bins: np.ndarray | None = None) -> None:
    """Refuse a stimulus that does not repeat from cycle to cycle (:func:`cycle_change`, or
    :func:`band_cycle_change` over ``bins``, above :data:`MAX_CYCLE_CHANGE`): the cycle
    length is not the stimulus's period, and the FRF would look plausible and be wrong. The
    period found by autocorrelation (:func:`repeat_period`), if any, is suggested."""
    change = cycle_change(cycles) if bins is None else band_cycle_change(cycles, bins)
    if change <= MAX_CYCLE_CHANGE:
        return
    found = repeat_period(max(trials, key=np.size), sample_rate)
    hint = (f"; it repeats every {found:.6g} s (autocorrelation)" if found is not None
            and abs(found - cycle_length) > 0.5 / sample_rate else "")
    raise ParameterError(f"the stimulus does not repeat every --cycle-length {cycle_length:g}"
                         f" s: its cycles differ by {100 * change:.0f} % of its RMS (at most "
                         f"{100 * MAX_CYCLE_CHANGE:.0f} %){hint}; give the stimulus's period "
                         "as --cycle-length")


def band_variance(X: np.ndarray, Y: np.ndarray, bins) -> tuple[np.ndarray, ...]:
    """var of each band's Ĥ, its degrees of freedom and the bands' covariance (B, B), from
    the scatter of the cycles' spectra ``X``, ``Y`` (C, bins) about the periodic response
    at the DFT bins about each harmonic (module notes)."""
    C, n = X.shape
    G = np.sum(np.abs(X) ** 2, axis=0)
    scale = max(float(G.max()), 1e-300)
    with np.errstate(invalid="ignore", divide="ignore"):
        fit = np.where(G > 1e-20 * scale, np.sum(np.conj(X) * Y, axis=0) / G, 0.0)
    periodic = np.where(G > 1e-20 * scale, fit * X, Y.mean(axis=0))
    s2 = np.sum(np.abs(Y - periodic) ** 2, axis=0) / (C - 1)
    least = int(math.ceil(POOLED_DOF / (2.0 * (C - 1))))
    top = n - 2  # bins 1 … n − 2: neither the mean nor the Nyquist bin

    def window(lo: int, hi: int) -> tuple[int, int]:
        while hi - lo + 1 < least and (lo > 1 or hi < top):
            lo, hi = (lo - 1 if lo > 1 else lo), (hi + 1 if hi < top else hi)
        return lo, hi

    from scipy.special import digamma

    # E[ln s²] = ln σ² + ψ(C − 1) − ln(C − 1) for s² ~ σ² χ²_{2(C−1)} / (2(C − 1))
    log_bias = float(digamma(C - 1) - math.log(C - 1))
    noise = {}  # σ² at each harmonic used: a power law in f fitted to ln s² about it
    for j in sorted({int(j) for b in bins for j in b}):
        lo, hi = window(j, j)
        k = np.arange(lo, hi + 1)
        ok = s2[k] > 0
        if ok.sum() < 3:
            noise[j] = s2[lo:hi + 1].mean()
            continue
        slope, level = np.polyfit(np.log(k[ok] / j), np.log(s2[k][ok]), 1)
        noise[j] = math.exp(level - log_bias)
    B = len(bins)
    cov = np.zeros((B, B))
    dof = []
    for a, ba in enumerate(bins):
        lo, hi = window(int(ba.min()), int(ba.max()))
        dof.append(2.0 * (C - 1) * (hi - lo + 1))
        for c in range(a, B):
            shared = set(map(int, ba)) & set(map(int, bins[c]))
            cov[a, c] = cov[c, a] = sum(G[j] * noise[j] for j in shared) / (
                G[ba].sum() * G[bins[c]].sum())
    return np.diag(cov).copy(), np.array(dof), cov


#: The sign warning's thresholds: the lowest band's phase within this of ±180° [deg] with
#: at least this coherence [-] (:func:`sign_warning`).
SIGN_WARNING_PHASE = 45.0
SIGN_WARNING_COHERENCE = 0.8


def sign_warning(est: FRFEstimate) -> str | None:
    """A one-line warning when the lowest band's phase lies within ``SIGN_WARNING_PHASE`` of
    ±180° with coherence at least ``SIGN_WARNING_COHERENCE``: a postural response follows a
    slow stimulus near 0°, so the response is then probably in the opposite sign
    convention; None otherwise."""
    phase = float(np.degrees(np.angle(est.frf[0])))
    if abs(phase) >= 180.0 - SIGN_WARNING_PHASE and est.coherence[0] >= SIGN_WARNING_COHERENCE:
        return (f"the lowest band ({est.frequency[0]:.3g} Hz) has phase {phase:.0f} deg with "
                f"coherence {est.coherence[0]:.2f}: the response sign "
                f"({int(est.response_sign):+d}) is probably the opposite of this recording's "
                "convention (check --response-sign, or response_sign in the API)")
    return None


def whole_cycles(stimulus: np.ndarray, response: np.ndarray, sample_rate: float,
                 cycle_length: float) -> tuple[np.ndarray, np.ndarray, bool]:
    """The two series without a last sample one past whole cycles (a record that includes
    its end point, as ``posturelab simulate`` writes), and whether it was dropped.

    Parameters
    ----------
    stimulus, response : numpy.ndarray, shape (T,)
        The series, sampled together. [rad or m]
    sample_rate : float
        Samples per second. [Hz]
    cycle_length : float
        The stimulus's cycle. [s]
    """
    per_cycle = sample_rate * cycle_length
    if per_cycle > 0 and abs(per_cycle - round(per_cycle)) < 1e-6 * per_cycle \
            and stimulus.size % round(per_cycle) == 1:
        return stimulus[:-1], response[:-1], True
    return stimulus, response, False


def sign_convention(sign: int) -> str:
    """One phrase stating the sign the response was taken with (−1: posturelab's tilt
    convention; +1: as recorded)."""
    return ("response × −1 (posturelab's tilt convention: sway forward positive, tilt "
            "toes-up positive, following the surface reads gain 1, phase 0)" if sign < 0
            else "response × +1 (as recorded)")
