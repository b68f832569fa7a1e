"""Experiment design: the standard errors a PRTS tilt experiment will give, before running it.

For a PRTS tilt of peak-to-peak amplitude A [rad], state duration Δ [s] and C analysed
cycles, recorded at f_s [Hz] (L = f_s·T samples per cycle of T [s]), posturelab's estimate
(:mod:`.estimate`) takes each cycle's DFT X_cj, Y_cj at the odd harmonics j and forms each
band's Ĥ_b = Σ_{j∈b} Σ_c X̄_cj Y_cj / Σ_{j∈b} Σ_c |X_cj|². The stimulus is the same every
cycle, X_cj = X_j; the response is Y_cj = H_j X_j + N_cj with N_cj the DFT of the noise in
cycle c, zero-mean, independent between cycles and between harmonics, circular complex normal
with E|N_cj|² = S_j. Then (the least-squares FRF estimate of a periodic excitation averaged
over periods: Pintelon and Schoukens, *System Identification: A Frequency Domain Approach*,
2nd ed., Wiley-IEEE 2012, ch. 2, the variance of the averaged DFT spectra, σ²/P over P
periods; as :mod:`.estimate` uses for its weights)

    Ĥ_b − H_b = Σ_j X̄_j Σ_c N_cj / (C Σ_j |X_j|²)
    V_ab = E[(Ĥ_a − H_a)(Ĥ_b − H_b)*] = Σ_{j∈a∩b} |X_j|² S_j / (C Σ_{j∈a}|X_j|² Σ_{j∈b}|X_j|²)

(bands that share harmonics are correlated; V is real). Each part, real and imaginary, has
covariance V/2, the two independent, which is the noise model the fit (:mod:`.fit`) weights
by. The noise at each harmonic f_j, for a record sampled at f_s (E|DFT|² = L × the discrete
spectral density; the response's spectrum taken below the Nyquist frequency, without
aliasing):

* **sensor noise**, white of standard deviation σ_s [rad] on the recorded angle (added after
  the run, as :func:`~.experiment.prts_experiment` does): S_j = L σ_s²;
* **motor noise**, a random torque of standard deviation σ_m [N·m] per joint
  (:class:`~posturelab.model.noise.MotorNoise`: AR(1) samples at f_m with a = exp(−2π
  f_c/f_m), a = 0 without a cutoff, splined in between), through the closed loop: the
  output y = c·Θ with Δ(s)Θ = Eᵀn (Δ the loop's characteristic matrix,
  :meth:`~posturelab.linear.system.LinearSystem.characteristic_matrix`, E the joint-angle
  matrix), so S_j = L f_s Σ_joints σ_m² |c·Δ⁻¹Eᵀe_joint|² (1 − a²) / (f_m |1 − a
  e^{−2πi f_j/f_m}|²) (the torque's spectral density; the spline between its samples taken
  as the identity below a few Hz).

**Fisher information.** With the band FRF of the model averaged over each band's harmonics
with the stimulus's power (as the fit does), H_b(θ), and D = ∂H/∂θ (B × K, complex), the
information of the real and imaginary parts is

    𝓘 = Dᵣᵀ (V/2)⁻¹ Dᵣ + Dᵢᵀ (V/2)⁻¹ Dᵢ = 2 Re(Dᴴ V⁻¹ D)

and the predicted standard errors are √diag(𝓘⁻¹) (the Cramér–Rao bound, which the weighted
least-squares fit attains to first order under Gaussian noise: Pintelon and Schoukens 2012,
ch. 7 and 9). 𝓘 ∝ C A², so every error falls as 1/(A √C) at a fixed state duration (under
the linear model: a larger amplitude also changes what people do, Peterka 2002's
reweighting, which the prediction does not know). A parameter the FRF does not depend on, or
a set the bands cannot separate (𝓘 singular: condition number above 1e12), gets an infinite
error.

**Derivatives** are central differences of the exact model FRF (step 1e-5 of the value, or
of a floor on the parameter's scale, one-sided at a bound of the parameter's range), error
O(h²) ≈ 1e-10 relative. The complex-step method (Martins, Sturdza and Alonso 2003, ACM TOMS
29:245–262) needs a function real for real arguments; the FRF is complex already, and
separating ∂Re H from ∂Im H would need a second imaginary unit (multicomplex numbers) through
the model's linear algebra. The tests compare the differences with the analytic
derivatives of the one-link FRF in closed form.

**Optimising** the design (amplitude, state duration, cycles) under a time budget is
:mod:`posturelab.frequency.design_search`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validation import float_in_range
from ..errors import ParameterError
from ..model.body import Body
from ..model.muscles import MuscleSet
from ..model.tilt import PRTSTilt

__all__ = ["DesignPrediction", "predict_errors", "band_noise_covariance", "model_band_frf",
           "frf_derivatives", "motor_noise_gain", "MAX_CYCLES",
           "MAX_CYCLE_SAMPLES"]

#: Most cycles a design may have. [-]
MAX_CYCLES = 10_000
#: Most samples per cycle (f_s × T) a design may have. [-]
MAX_CYCLE_SAMPLES = 200_000
#: Relative step of the central differences (module notes). [-]
RELATIVE_STEP = 1e-5
#: Largest condition number of the Fisher information taken as invertible. [-]
MAX_CONDITION = 1e12

_ROWS = {"stiffness": 0, "viscosity": 1, "active_stiffness": 2, "active_viscosity": 3}
#: The smallest scale of a parameter's difference step. [its unit]
_STEP_FLOOR = {"stiffness": 1.0, "viscosity": 1.0, "active_stiffness": 1.0,
               "active_viscosity": 1.0, "feedback_delay": 1e-3, "proprioceptive_weight": 1e-3,
               "visual_weight": 1e-3}


@dataclass(frozen=True, eq=False)  # (its arrays: a field-wise == would raise)
class DesignPrediction:
    """What :func:`predict_errors` predicts.

    Attributes
    ----------
    names : tuple of str
        The free parameters (the parameter table's spelling).
    values : numpy.ndarray, shape (K,)
        Their values in the model. [their units]
    standard_errors : numpy.ndarray, shape (K,)
        √diag(𝓘⁻¹), inf for a parameter the experiment cannot determine. [their units]
    fisher : numpy.ndarray, shape (K, K)
        𝓘 (module notes). [1 / (unit_i unit_j)]
    frequency : numpy.ndarray, shape (B,)
        Band frequencies. [Hz]
    frf : numpy.ndarray of complex, shape (B,)
        The model's band FRF. [-]
    band_covariance : numpy.ndarray, shape (B, B)
        V, E[(Ĥ_a − H_a)(Ĥ_b − H_b)*]. [-]
    tilt : PRTSTilt
        The stimulus: its ``amplitude`` (peak to peak) [rad], ``state_duration`` and
        ``cycle_length`` [s] read through the prediction.
    cycles, discard : int
        Cycles analysed and run before them. [-]
    sensor_noise : float
        [rad]
    motor_noise : str
        Its description, or "none".
    stimulus : {"tilt", "visual-tilt"}
        What the PRTS moves: the support surface or the visual scene.
    """

    names: tuple[str, ...]
    values: np.ndarray
    standard_errors: np.ndarray
    fisher: np.ndarray = field(repr=False)
    frequency: np.ndarray = field(repr=False)
    frf: np.ndarray = field(repr=False)
    band_covariance: np.ndarray = field(repr=False)
    tilt: PRTSTilt
    cycles: int
    discard: int
    sensor_noise: float
    motor_noise: str
    stimulus: str

    @property
    def amplitude(self) -> float:
        """The tilt's peak-to-peak amplitude. [rad]"""
        return float(self.tilt.amplitude)

    @property
    def state_duration(self) -> float:
        """The tilt's state duration. [s]"""
        return float(self.tilt.state_duration)

    @property
    def cycle_length(self) -> float:
        """The tilt's cycle. [s]"""
        return float(self.tilt.cycle)

    @property
    def duration(self) -> float:
        """(cycles + discard) × cycle length. [s]"""
        return self.cycle_length * (self.cycles + self.discard)

    def to_dict(self) -> dict:
        """Plain-Python summary (JSON-safe: an infinite error is null)."""
        from ..parameters import unit

        def num(v):
            return float(v) if math.isfinite(v) else None

        return {
            "parameters": {n: {"value": float(v), "standard_error": num(s),
                               "relative_error": num(s / abs(v)) if v else None,
                               "unit": unit(n)}
                           for n, v, s in zip(self.names, self.values, self.standard_errors,
                                              strict=True)},
            "design": {"amplitude": self.amplitude, "state_duration": self.state_duration,
                       "cycle_length": self.cycle_length, "cycles": self.cycles,
                       "discard": self.discard, "duration": self.duration,
                       "sensor_noise": self.sensor_noise, "motor_noise": self.motor_noise,
                       "stimulus": self.stimulus},
            "bands": {"frequency": [float(f) for f in self.frequency],
                      "frf_se": [float(math.sqrt(v)) for v in np.diag(self.band_covariance)]},
        }


def _check_design(tilt, cycles: int, discard: int, sample_rate: float):
    if not isinstance(tilt, PRTSTilt):
        raise ParameterError("the tilt must be a PRTS (a periodic stimulus: prts:AMPLITUDE_RAD"
                             "[:STATE_DURATION_S][:SEQUENCE])")
    for name, value, least in (("cycles", cycles, 2), ("discard", discard, 0)):
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or not (
                least <= value <= MAX_CYCLES):
            raise ParameterError(f"{name} must be an integer in [{least}, {MAX_CYCLES}], got "
                                 f"{value!r}")
    fs = float_in_range("sample_rate [Hz]", sample_rate, 1.0, 1e5, unit="Hz")
    L = fs * tilt.cycle
    if abs(L - round(L)) > 1e-6 * L:
        raise ParameterError(f"the cycle of {tilt.cycle:g} s is {L:g} samples at {fs:g} Hz, not a "
                             "whole number: choose a state duration that is a whole number of "
                             "samples")
    if L > MAX_CYCLE_SAMPLES:
        raise ParameterError(f"a cycle of {tilt.cycle:g} s at {fs:g} Hz is {L:.0f} samples; at "
                             f"most {MAX_CYCLE_SAMPLES:,} (lower the sample rate)")
    return fs, int(round(L))


def _stimulus_spectrum(tilt, fs: float, L: int, bands) -> tuple[list, np.ndarray]:
    """The bins of each band's harmonics and |X_j|² of one cycle at every bin."""
    from .bands import resolve_bands, sequence_bands

    t = np.arange(L) / fs
    X = np.fft.rfft(tilt.angle(t))
    wanted = sequence_bands(tilt) if bands is None else bands
    _check_harmonics(tilt, fs, L, wanted)
    chosen = resolve_bands(wanted, L // 4)
    return chosen, np.abs(X) ** 2


def _check_harmonics(tilt, fs: float, L: int, bands) -> None:
    """Refuse, in the user's terms, a stimulus whose cycle at ``fs`` [Hz] (``L`` samples)
    has too few odd harmonics below a quarter of the samples for the bands (a band listing
    a non-number is left to :func:`posturelab.frequency.bands.resolve_bands`)."""
    try:
        needed = max(int(k) for band in bands for k in band)
    except (TypeError, ValueError):
        return
    if needed <= L // 4:
        return
    states = max(round(tilt.cycle / tilt.state_duration), 1)
    least = math.ceil(4 * needed / states) / fs  # whole samples per state
    raise ParameterError(
        f"the PRTS state duration {tilt.state_duration:g} s makes a {tilt.cycle:g} s cycle, "
        f"{L} samples at {fs:g} Hz: it resolves {L // 4} odd harmonic(s) (up to "
        f"{(2 * (L // 4) - 1) / tilt.cycle:.4g} Hz; Nyquist {fs / 2:g} Hz) but the bands "
        f"need {needed} (up to {(2 * needed - 1) / tilt.cycle:.4g} Hz); give a state duration "
        f">= {least:.4g} s (or a higher --sample-rate)")


def _system(body, muscles, feedback_delay, proprioceptive_weight):
    from ..linear.system import linear_system

    active = muscles.has_active_feedback
    return linear_system(body, muscles, stiffness=muscles.stiffnesses,
                         viscosity=muscles.viscosities,
                         active_stiffness=muscles.active_stiffnesses if active else None,
                         active_viscosity=muscles.active_viscosities if active else None,
                         delay=feedback_delay, proprioceptive_weight=proprioceptive_weight)


def motor_noise_gain(body: Body, muscles: MuscleSet, frequencies, *, output: str = "com_angle",
                     feedback_delay: float = 0.0, proprioceptive_weight: float = 1.0
                     ) -> np.ndarray:
    """|c·Δ⁻¹Eᵀe_joint|², the output's power per unit torque at each joint (module notes).

    Returns
    -------
    numpy.ndarray, shape (F, N)
        [(rad / (N·m))²]
    """
    from .model import output_vector

    f = np.asarray(frequencies, dtype=float)
    c = output_vector(body, output)
    system = _system(body, muscles, feedback_delay, proprioceptive_weight)
    s = (2j * np.pi * f)[None, :]
    D = system.characteristic_matrix(s)[0]  # (F, N, N)
    n = body.n_links
    E = np.eye(n) - np.eye(n, k=-1)  # joint angle j = θ_j − θ_{j−1}
    with np.errstate(all="ignore"):
        G = np.linalg.solve(D, np.broadcast_to(E.T, D.shape))  # (F, N, joints)
    return np.abs(np.einsum("n,fnj->fj", c, G)) ** 2


def _motor_noise_power(body, muscles, motor_noise, harmonics, fs: float, L: int,
                       **model) -> np.ndarray:
    """E|N_j|² of the motor noise's sway over one cycle's window (module notes): the
    autocovariance r[k] of the sampled output from its spectral density on a grid of 8L
    frequencies (inverse FFT), then Σ_{|k|<L} (L − |k|) r[k] e^{−iω_j k}. [rad²]"""
    sigma = motor_noise.per_joint(body.n_links)
    fm = motor_noise.sample_rate
    a = 0.0 if motor_noise.cutoff is None else math.exp(-2 * np.pi * motor_noise.cutoff / fm)
    N = 8 * L
    f = np.arange(N // 2 + 1) * fs / N
    f[0] = 0.5 * f[1]  # (the spectrum is smooth at 0: taken half a step up)
    shape = (1 - a * a) / (fm * np.abs(1 - a * np.exp(-2j * np.pi * f / fm)) ** 2)
    density = fs * shape * (motor_noise_gain(body, muscles, f, **model) @ sigma ** 2)
    if not np.all(np.isfinite(density)):
        raise ParameterError("the motor noise's path through the loop is not finite at some "
                             "frequency (a loop unstable or on the edge at this delay)")
    r = np.fft.irfft(density, N)[:L]  # r[k] = (1/N) Σ_m P(ω_m) e^{iω_m k}, k = 0 … L − 1
    k = np.arange(L)
    taper = (L - k) * r
    taper[1:] *= 2.0
    omega = 2 * np.pi * np.asarray(harmonics, dtype=float) / L
    return np.cos(np.outer(omega, k)) @ taper


def band_noise_covariance(body: Body, muscles: MuscleSet, tilt, cycles: int, *,
                          sensor_noise: float = 0.0, motor_noise=None,
                          sample_rate: float = 100.0, output: str = "com_angle",
                          feedback_delay: float = 0.0, proprioceptive_weight: float = 1.0,
                          bands=None) -> dict:
    """V, the covariance of the estimated band FRFs of a PRTS experiment (module notes).

    Parameters
    ----------
    body, muscles
        The model (for the motor noise's path through the loop).
    tilt : PRTSTilt
    cycles : int
        Cycles analysed. [-]
    sensor_noise : float
        σ_s, white noise on the recorded angle. [rad]
    motor_noise : MotorNoise, optional
        The torque noise per joint. [N·m]
    sample_rate : float
        f_s of the record. [Hz]
    output, feedback_delay, proprioceptive_weight
        As for :func:`posturelab.frequency.model_frf`.
    bands
        As for :func:`posturelab.frequency.estimate_frf`; default: the tilt's sequence's.

    Returns
    -------
    dict
        ``covariance`` (B, B), ``bands``, ``harmonic_frequency`` and ``harmonic_weight`` (per
        band, its harmonics [Hz] and C|X_j|²), ``noise`` (S_j at each band's harmonics
        [rad²]) and ``frequency`` (B,) [Hz].
    """
    from ..model.noise import MotorNoise
    from .bands import band_frequencies

    fs, L = _check_design(tilt, cycles, 0, sample_rate)
    sensor_noise = float_in_range("sensor_noise [rad]", sensor_noise, 0.0, 1.0, unit="rad")
    if motor_noise is not None and not isinstance(motor_noise, MotorNoise):
        raise ParameterError("motor_noise must be a MotorNoise or None")
    chosen, power = _stimulus_spectrum(tilt, fs, L, bands)
    bins = [np.array([2 * k - 1 for k in band]) for band in chosen]
    used = np.array(sorted({int(j) for b in bins for j in b}))
    S = np.full(used.size, L * sensor_noise ** 2)
    if motor_noise is not None:
        S = S + _motor_noise_power(body, muscles, motor_noise, used, fs, L,
                                   output=output, feedback_delay=feedback_delay,
                                   proprioceptive_weight=proprioceptive_weight)
    if not np.all(np.isfinite(S)):
        raise ParameterError("the motor noise's path through the loop is not finite at some "
                             "harmonic (a loop unstable or on the edge at this delay)")
    noise = dict(zip(used.tolist(), S, strict=True))
    G = cycles * power
    B = len(bins)
    cov = np.zeros((B, B))
    for a_, ba in enumerate(bins):
        for b_ in range(a_, B):
            shared = set(map(int, ba)) & set(map(int, bins[b_]))
            cov[a_, b_] = cov[b_, a_] = sum(G[j] * noise[j] for j in shared) / (
                G[ba].sum() * G[bins[b_]].sum())
    if np.any(np.diag(cov) <= 0):
        raise ParameterError("give some noise (--sensor-noise or --motor-noise): without any "
                             "the errors are zero")
    return {"covariance": cov, "bands": chosen, "frequency": band_frequencies(chosen, tilt.cycle),
            "harmonic_frequency": tuple(b / tilt.cycle for b in bins),
            "harmonic_weight": tuple(G[b] for b in bins),
            "noise": tuple(np.array([noise[int(j)] for j in b]) for b in bins)}


def _specs(muscles: MuscleSet, free) -> tuple[list, list]:
    from .fit import check_fit_request

    names, _, specs, _, _ = check_fit_request(muscles, list(free))
    for base, _j in specs:
        if base not in _STEP_FLOOR:
            raise ParameterError(f"design cannot yet differentiate the model in {base!r}; it "
                                 f"takes {', '.join(_STEP_FLOOR)}")
    return names, specs


def _values(muscles, specs, feedback_delay, proprioceptive_weight,
            visual_weight: float = 0.0) -> np.ndarray:
    base = np.stack([muscles.stiffnesses, muscles.viscosities, muscles.active_stiffnesses,
                     muscles.active_viscosities])
    scalars = {"feedback_delay": feedback_delay, "proprioceptive_weight": proprioceptive_weight,
               "visual_weight": visual_weight}
    out = []
    for b, j in specs:
        out.append(scalars[b] if b in scalars else float(base[_ROWS[b], j]))
    return np.array(out, dtype=float)


def model_band_frf(body: Body, muscles: MuscleSet, specs, values, harmonic_frequency,
                   harmonic_weight, *, output: str = "com_angle", feedback_delay: float = 0.0,
                   proprioceptive_weight: float = 1.0, visual_weight: float = 0.0,
                   input: str = "tilt") -> np.ndarray:
    """The model's band FRFs for M sets of the parameters ``specs`` (base name, pair index),
    averaged over each band's harmonics with the stimulus's power, as the fit does.

    Parameters
    ----------
    values : array_like, shape (M, K)
        [their units]
    harmonic_frequency, harmonic_weight : sequence of numpy.ndarray
        Per band, its harmonics [Hz] and their stimulus power [rad²].
    output, feedback_delay, proprioceptive_weight, visual_weight, input
        As for :func:`posturelab.frequency.model.model_frf_batch` (``input`` "tilt" or
        "visual-tilt": what the PRTS moves; [s], [-], [-]).

    Returns
    -------
    numpy.ndarray of complex, shape (M, B)
    """
    from .model import model_frf_batch

    values = np.atleast_2d(np.asarray(values, dtype=float))
    M = values.shape[0]
    gains = np.repeat(np.stack([muscles.stiffnesses, muscles.viscosities,
                                muscles.active_stiffnesses,
                                muscles.active_viscosities])[None], M, axis=0)
    tau = np.full(M, float(feedback_delay))
    w = np.full(M, float(proprioceptive_weight))
    wv = np.full(M, float(visual_weight))
    for k, (b, j) in enumerate(specs):
        if b == "feedback_delay":
            tau = values[:, k].copy()
        elif b == "proprioceptive_weight":
            w = values[:, k].copy()
        elif b == "visual_weight":
            wv = values[:, k].copy()
        else:
            gains[:, _ROWS[b], j] = values[:, k]
    active = muscles.has_active_feedback or any(b.startswith("active") for b, _ in specs)
    f = np.concatenate(harmonic_frequency)
    H = model_frf_batch(body, muscles, f, gains[:, 0], gains[:, 1],
                        gains[:, 2] if active else None, gains[:, 3] if active else None,
                        tau, w, output=output, input=input, visual_weight=wv)
    out, start = [], 0
    for weight in harmonic_weight:
        out.append(H[:, start:start + weight.size] @ weight / weight.sum())
        start += weight.size
    return np.stack(out, axis=1)


def frf_derivatives(body: Body, muscles: MuscleSet, specs, values, harmonic_frequency,
                    harmonic_weight, **model) -> np.ndarray:
    """D = ∂H_b/∂θ_k by central differences of the exact band FRF (module notes; one-sided
    at a bound of a parameter's range), shape (B, K), complex."""
    from ..parameters import QUANTITIES

    values = np.asarray(values, dtype=float)
    K = values.size
    steps = np.array([RELATIVE_STEP * max(abs(v), _STEP_FLOOR[b])
                      for v, (b, _) in zip(values, specs, strict=True)])
    up = np.repeat(values[None], K, axis=0)
    down = up.copy()
    for k, (b, _) in enumerate(specs):
        q = QUANTITIES[b]
        up[k, k] = min(values[k] + steps[k], q.high)
        down[k, k] = max(values[k] - steps[k], q.low)
    H = model_band_frf(body, muscles, specs, np.concatenate([up, down]), harmonic_frequency,
                       harmonic_weight, **model)
    return ((H[:K] - H[K:]) / (np.diag(up) - np.diag(down))[:, None]).T


def _errors(fisher: np.ndarray) -> np.ndarray:
    """√diag(𝓘⁻¹), inf where 𝓘 cannot separate the parameters (module notes)."""
    K = fisher.shape[0]
    d = np.sqrt(np.maximum(np.diag(fisher), 0.0))
    se = np.full(K, np.inf)
    seen = d > 1e-300
    if not seen.any():
        return se
    scaled = fisher[np.ix_(seen, seen)] / np.outer(d[seen], d[seen])
    if np.linalg.cond(scaled) > MAX_CONDITION:
        return se
    inv = np.linalg.inv(scaled) / np.outer(d[seen], d[seen])
    se[seen] = np.sqrt(np.maximum(np.diag(inv), 0.0))
    return se


def _fisher(D: np.ndarray, V: np.ndarray) -> np.ndarray:
    """2 Re(Dᴴ V⁻¹ D) (module notes)."""
    from scipy.linalg import cho_factor, cho_solve

    factor = cho_factor(V)
    return 2.0 * (D.real.T @ cho_solve(factor, D.real) + D.imag.T @ cho_solve(factor, D.imag))


def _check_stable(body: Body, muscles: MuscleSet, feedback_delay: float) -> None:
    """Refuse a loop that is not stable about upright at its delay (no measurable FRF)."""
    from ..linear.verdict import upright_verdict

    verdict = upright_verdict(body, muscles, feedback_delay)
    if verdict.side(engaged=True).status != "stable":
        raise ParameterError(f"the loop is {verdict.describe()}: its FRF is not measurable "
                             "(a periodic-stimulus experiment would fall); change the gains or "
                             "the feedback delay")


def _model_options(feedback_delay, proprioceptive_weight, output) -> dict:
    from ..parameters import check_value

    check_value("feedback_delay", feedback_delay)
    check_value("proprioceptive_weight", proprioceptive_weight)
    return {"output": output, "feedback_delay": float(feedback_delay),
            "proprioceptive_weight": float(proprioceptive_weight)}


def predict_errors(body: Body, muscles: MuscleSet, free, *, tilt=None, cycles: int = 5,
                   discard: int = 1, sensor_noise: float = 0.0, motor_noise=None,
                   sample_rate: float = 100.0, output: str = "com_angle",
                   feedback_delay: float = 0.0, proprioceptive_weight: float = 1.0,
                   bands=None, input: str = "tilt",
                   visual_weight: float = 0.0) -> DesignPrediction:
    """The standard errors a PRTS experiment will give the ``free`` parameters (module notes).

    Parameters
    ----------
    body, muscles
        The model: its gains are the parameters' true values.
    free : sequence of str
        Parameter names as for :func:`posturelab.frequency.fit.fit_frf`.
    tilt : PRTSTilt, optional
        Default: ``PRTSTilt.named("posturelab-80", 0.035)``.
    cycles, discard : int
        Cycles analysed, and run before them (they count in the duration only). [-]
    sensor_noise : float
        σ_s on the recorded angle. [rad]
    motor_noise : MotorNoise, optional
        [N·m]
    sample_rate : float
        [Hz]
    output, feedback_delay, proprioceptive_weight, bands
        As for :func:`posturelab.frequency.experiment.prts_experiment`.
    input : {"tilt", "visual-tilt"}
        What ``tilt`` moves: the support surface (default) or the visual scene, whose
        FRF carries W_v (:mod:`posturelab.model.visual`; the noise's path is the same loop).
    visual_weight : float
        W_v, with W + W_v <= 1. [-]

    Returns
    -------
    DesignPrediction
    """
    if not isinstance(body, Body) or not isinstance(muscles, MuscleSet):
        raise ParameterError("predict_errors needs a Body and a MuscleSet")
    tilt = PRTSTilt.named("posturelab-80", 0.035) if tilt is None else tilt
    _check_design(tilt, cycles, discard, sample_rate)
    _check_stable(body, muscles, feedback_delay)
    model = _model_options(feedback_delay, proprioceptive_weight, output)
    frf_model = {**model, **_input_options(input, proprioceptive_weight, visual_weight)}
    names, specs = _specs(muscles, free)
    noise = band_noise_covariance(body, muscles, tilt, int(cycles), sensor_noise=sensor_noise,
                                  motor_noise=motor_noise, sample_rate=sample_rate,
                                  bands=bands, **model)
    values = _values(muscles, specs, feedback_delay, proprioceptive_weight,
                     frf_model["visual_weight"])
    hf, hw = noise["harmonic_frequency"], noise["harmonic_weight"]
    D = frf_derivatives(body, muscles, specs, values, hf, hw, **frf_model)
    fisher = _fisher(D, noise["covariance"])
    H = model_band_frf(body, muscles, specs, values, hf, hw, **frf_model)[0]
    return DesignPrediction(
        tuple(names), values, _errors(fisher), fisher, noise["frequency"], H,
        noise["covariance"], tilt, int(cycles), int(discard), float(sensor_noise),
        "none" if motor_noise is None else motor_noise.describe(), frf_model["input"])


def _input_options(input: str, proprioceptive_weight, visual_weight) -> dict:
    """What the PRTS moves and W_v, checked (W + W_v <= 1, naming both)."""
    from ..parameters import check_weights

    if input not in ("tilt", "visual-tilt"):
        raise ParameterError(f"input must be tilt or visual-tilt, got {input!r}"[:200])
    return {"input": input,
            "visual_weight": check_weights(proprioceptive_weight, visual_weight)}
