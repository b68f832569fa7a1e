"""Dual-stimulus trials: a surface tilt and a visual-scene tilt in one trial, and both FRFs.

Peterka's independent-channel model (Peterka 2002, J Neurophysiol 88:1097–1118) weights the
proprioceptive, visual and graviceptive orientation cues by W_p, W_v and 1 − W_p − W_v. A
surface tilt alone measures W_p (and the visual weight only through what is left of 1); a
visual-scene tilt alone measures W_v. Peterka's group gave surface and visual-surround
stimuli in separate and in combined tests (Cenciarini and Peterka 2006, J Neurophysiol
95:2733; the "central sensorimotor integration" tests of Peterka, Murchison, Parrington,
Fino and King 2018, Front Neurol 9:1045, PMC6300494, which rotate the stance surface and/or
the visual surround with cyclically repeated pseudorandom stimuli). Here both stimuli run in
one trial and each FRF is estimated from it.

**How the two stimuli are made separable.** The response of a linear system to two periodic
inputs is the sum of the two responses; at a frequency where only one input has power, the
cross-spectrum with that input is its FRF alone. posturelab therefore excites the two inputs
on disjoint sets of DFT bins of a common cycle T — the "zippered" (interleaved-frequency)
multisine design for multi-input FRF measurement (Dobrowiecki and Schoukens, "Measuring linear
approximation to weakly nonlinear MIMO systems", IFAC World Congress 2005; the MUMI toolbox,
Csurcsia 2021, Software Impacts 10:100192, doi:10.1016/j.simpa.2021.100192). A PRTS has power
only at the odd harmonics of its own cycle (its second half-cycle is the negative of its
first), so a PRTS of cycle T excites the bins 1, 3, 5, … of T and a PRTS of cycle T/2 (the
same shift register with half the state duration) the bins 2, 6, 10, …: no bin is shared, at
any amplitude, and the two are uncorrelated over every whole cycle T. :func:`dual_prts` makes
that pair (posturelab's choice of PRTS pair, after the zippered-multisine principle; the
sources above used separate or combined stimuli, not this pair). Any two periodic stimuli
whose harmonics m₁(2k − 1) and m₂(2k − 1) of T are disjoint work (m the stimulus's
*harmonic step*: it repeats every T/m); steps 1 and 3 share bins (3, 9, …) and are refused.

Each FRF is then the one-input estimate of :func:`.estimate.estimate_frf` at its own
stimulus's harmonics (``harmonic_step``), with its bands numbered in that stimulus's own odd
harmonics; the other stimulus's response is periodic in T, so it adds nothing to the
cycle-to-cycle scatter from which the weights of a fit are estimated.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..errors import ParameterError
from .estimate import FRFEstimate, estimate_frf

__all__ = ["harmonic_step", "estimate_frfs", "dual_prts", "read_trial_frfs", "input_of",
           "STIMULUS_INPUTS", "stimulus_columns"]

#: The model input of each stimulus column posturelab writes. [-]
STIMULUS_INPUTS = {"tilt": "tilt", "visual_tilt": "visual-tilt"}
#: The share of a stimulus's power that must lie at odd multiples of its lowest harmonic
#: (a measured stimulus carries some noise at every bin). [-]
_PURITY = 0.99
#: A bin is the stimulus's lowest harmonic from this share of its largest bin's power on. [-]
_LOWEST = 1e-3


def input_of(column: str) -> str:
    """The model input (``tilt``, ``visual-tilt``) a stimulus column is: ``visual_tilt`` or a
    column whose name starts with ``visual`` is the scene's, any other a surface tilt."""
    name = column.strip().lower()
    return "visual-tilt" if name.startswith("visual") else "tilt"


def harmonic_step(stimulus, sample_rate: float, cycle_length: float) -> int:
    """m: the stimulus's power over cycles of ``cycle_length`` T [s] lies at the DFT bins
    m·(2k − 1) (a PRTS of cycle T/m). ``sample_rate`` [Hz].

    Raises
    ------
    ParameterError
        A record shorter than a cycle, a stimulus without power, or one whose power is not
        (to 99 %) at the odd multiples of its lowest harmonic.
    """
    x = np.asarray(stimulus, dtype=float)
    L = int(round(sample_rate * cycle_length))
    if L < 4 or x.size < L:
        raise ParameterError(f"the stimulus has {x.size} samples, less than one cycle of "
                             f"{cycle_length:g} s")
    mean_cycle = x[:x.size // L * L].reshape(-1, L).mean(axis=0)
    power = np.abs(np.fft.rfft(mean_cycle)) ** 2
    power[0] = 0.0
    total = power.sum()
    if not total > 0:
        raise ParameterError("the stimulus has no power at any harmonic of the cycle")
    lowest = int(np.argmax(power > _LOWEST * power.max()))
    odd = np.arange(lowest, power.size, 2 * lowest)
    if power[odd].sum() < _PURITY * total:
        raise ParameterError(f"the stimulus's power is not at the odd multiples of its lowest "
                             f"harmonic ({lowest / cycle_length:g} Hz): not a PRTS of cycle "
                             f"{cycle_length:g}/{lowest} s")
    return lowest


def estimate_frfs(stimuli: Mapping[str, np.ndarray], response, sample_rate: float,
                  cycle_length: float, *, steps: Mapping[str, int] | None = None,
                  discard_cycles: int = 0, bands="peterka", response_sign: float = 1.0,
                  ci: str = "periodic") -> dict[str, FRFEstimate]:
    """The FRF of ``response`` to each of several simultaneous periodic ``stimuli`` (module
    notes), each estimated at its own harmonics over cycles of ``cycle_length`` T [s].

    Parameters
    ----------
    stimuli : mapping of name -> array_like, shape (S,)
        The stimuli, sampled with the response. [rad]
    response : array_like, shape (S,)
        [rad]
    sample_rate : float
        [Hz]
    cycle_length : float
        T, a whole cycle of every stimulus. [s]
    steps : mapping of name -> int, optional
        Each stimulus's harmonic step (default: :func:`harmonic_step` of its record).
    discard_cycles, bands, response_sign, ci
        As for :func:`.estimate.estimate_frf`.

    Returns
    -------
    dict of name -> FRFEstimate

    Raises
    ------
    ParameterError
        Two stimuli whose harmonics share a bin (not separable in one trial).
    """
    if not stimuli:
        raise ParameterError("give at least one stimulus")
    found = {name: (int(steps[name]) if steps and name in steps
                    else harmonic_step(x, sample_rate, cycle_length))
             for name, x in stimuli.items()}
    names = list(found)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            ma, mb = found[a], found[b]
            # m_a(2j − 1) = m_b(2k − 1) has a solution iff the odd parts of the steps'
            # ratio are both odd: the steps have the same power of 2
            if _twos(ma) == _twos(mb):
                shared = ma * mb // math.gcd(ma, mb)
                raise ParameterError(
                    f"the stimuli {a!r} and {b!r} share harmonics (first at "
                    f"{shared / cycle_length:g} Hz; harmonic steps {ma} and {mb} of a "
                    f"{cycle_length:g} s cycle): their FRFs cannot be told apart in one trial "
                    "(give one a PRTS of half the other's cycle)")
    return {name: estimate_frf(stimuli[name], response, sample_rate, cycle_length,
                               discard_cycles=discard_cycles, bands=bands,
                               response_sign=response_sign, ci=ci, harmonic_step=found[name])
            for name in names}


def _twos(m: int) -> int:
    """The power of 2 in m."""
    return (m & -m).bit_length() - 1


def dual_prts(surface_amplitude: float, visual_amplitude: float,
              sequence: str = "posturelab-80"):
    """A surface and a visual-scene PRTS that do not share a harmonic (module notes): the
    named ``sequence`` with its own state duration for the surface (cycle T) and with half of
    it for the scene (cycle T/2), each with its peak-to-peak amplitude [rad]. Returns
    (surface, visual) :class:`~posturelab.model.tilt.PRTSTilt`."""
    from ..model.tilt import PRTSTilt, get_prts_sequence

    seq = get_prts_sequence(sequence)
    surface = PRTSTilt(surface_amplitude, seq.state_duration, seq.registers, seq.taps,
                       seq.seed)
    visual = PRTSTilt(visual_amplitude, seq.state_duration / 2, seq.registers, seq.taps,
                      seq.seed)
    return surface, visual


def read_trial_frfs(path, stimuli, response: str, cycle_length: float, *,
                    discard_cycles: int = 0, response_sign: int = -1, bands="peterka",
                    ci: str = "periodic", **recording
                    ) -> tuple[float, dict[str, FRFEstimate], bool]:
    """Each stimulus column's FRF from one trial CSV (:func:`estimate_frfs`): ``stimuli``
    the column names (tilts [rad]), ``response`` the response column, ``cycle_length`` the
    common cycle [s]; ``recording`` are :func:`posturelab.recordings.table.read_recording`'s
    options (resampling, declared units, the cut to whole cycles). Returns the sample rate
    [Hz], the FRFs by column and whether the record's end point (one sample past whole
    cycles) was left out."""
    from .._validation import float_in_range
    from .data import read_series_csv
    from .estimate import whole_cycles

    float_in_range("--cycle-length [s]", cycle_length, 1e-3, 1e5, unit="s")
    names = [s.strip().lower() for s in stimuli]
    resp = response.strip().lower()
    fs, cols = read_series_csv(path, [*names, resp], {n: ("rad",) for n in names},
                               kinds={**dict.fromkeys(names, "angle"), resp: "angle"},
                               cycle_length=cycle_length, **recording)
    x, trimmed = {}, False
    for n in names:
        x[n], y, trimmed = whole_cycles(cols[n], cols[resp], fs, cycle_length)
    return fs, estimate_frfs(x, y, fs, cycle_length, discard_cycles=discard_cycles,
                             bands=bands, response_sign=response_sign, ci=ci), trimmed


def stimulus_columns(path) -> list[str]:
    """The stimulus columns of :data:`STIMULUS_INPUTS` a trial CSV's header has, in that
    order (its first row only is read)."""
    from pathlib import Path

    from .._files import csv_rows, read_text
    from ..recordings.columns import MAX_ROWS, _name, _refuse_other_separators

    if Path(path).suffix.lower() == ".c3d":  # (a C3D's channels are named by --stimulus)
        return []
    first = next(csv_rows(read_text(Path(path), "data file"), repr(str(path)),
                          max_rows=MAX_ROWS), None)
    if first:
        _refuse_other_separators(first[1], repr(str(path)))
    names = {_name(h) for h in (first[1] if first else [])}
    return [c for c in STIMULUS_INPUTS if c in names]
