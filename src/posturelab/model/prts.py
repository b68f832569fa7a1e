"""Pseudorandom ternary sequences (PRTS) of surface velocities for :class:`.tilt.PRTSTilt`:
shift registers over GF(3), the named sequences with their sources.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, UnknownNameError

__all__ = ["prts_sequence", "PRTSSequence", "PRTS_SEQUENCES", "DEFAULT_PRTS",
           "get_prts_sequence", "PETERKA_2002_CITATION"]

PETERKA_2002_CITATION = (
    "Peterka RJ (2002) Sensorimotor integration in human postural control. "
    "J Neurophysiol 88:1097–1118 (242-state PRTS, 0.25 s per state, 60.5 s cycle)"
)


def prts_sequence(registers: int, taps: tuple[int, ...], seed: tuple[int, ...]) -> np.ndarray:
    """One period of a pseudorandom ternary sequence from a shift register over GF(3).

    The register holds ``registers`` digits in {0, 1, 2}; each step the new digit is
    Σ taps[i] · register[i] (mod 3), the register shifts by one, and the digit that leaves
    it is the output. Digits map to the values 0 → 0, 1 → +1, 2 → −1. With a primitive
    feedback polynomial the period is 3^registers − 1 and the sequence sums to zero.

    Parameters
    ----------
    registers : int
        1 … 8. [-]
    taps : tuple of int
        One coefficient in {0, 1, 2} per register (the oldest digit first). [-]
    seed : tuple of int
        The register's start, digits in {0, 1, 2}, not all zero. [-]

    Returns
    -------
    numpy.ndarray, shape (period,)
        Values in {−1, 0, 1}. [-]
    """
    if isinstance(registers, bool) or not isinstance(registers, int) or not 1 <= registers <= 8:
        raise ParameterError(f"PRTS registers must be an integer in [1, 8], got {registers!r}")
    for name, digits in (("taps", taps), ("seed", seed)):
        if len(digits) != registers or any(d not in (0, 1, 2) for d in digits):
            raise ParameterError(f"PRTS {name} must be {registers} digits in {{0, 1, 2}}, "
                                 f"got {tuple(digits)!r}")
    if not any(seed):
        raise ParameterError("PRTS seed must not be all zeros")
    state = list(seed)
    out = []
    start = tuple(state)
    for _ in range(3**registers):
        new = sum(t * s for t, s in zip(taps, state, strict=True)) % 3
        out.append(state[0])
        state = state[1:] + [new]
        if tuple(state) == start:
            break
    values = np.array([0.0, 1.0, -1.0])[np.array(out)]
    return values


#: posturelab's own 80-state register: new = x_{k−4} + x_{k−3} (mod 3), from the primitive
#: polynomial x⁴ + 2x + 2 over GF(3) (a test checks that its period is 80), started at
#: (1, 0, 0, 0). Not a published sequence (see :data:`PRTS_SEQUENCES`).
POSTURELAB_80_TAPS = (1, 1, 0, 0)
POSTURELAB_80_SEED = (1, 0, 0, 0)
#: Former names of the two above (they are posturelab's, not Peterka's). [-]
PETERKA_TAPS, PETERKA_SEED = POSTURELAB_80_TAPS, POSTURELAB_80_SEED


def peterka_register(feedback: tuple[int, ...], seed: tuple[int, ...]) -> tuple[tuple, tuple]:
    """The ``taps`` and ``seed`` of :func:`prts_sequence` for a register written as in
    Peterka's Matlab generator ``pseudogen3(n, feedback, seed, …)``: the register newest
    digit first, each step's new digit Σ feedback_i · register_i (mod 3) shifted in at the
    front and output (as a Matlab script that follows Peterka 2002 writes it out:
    ``Output = mod(Reg(3)−Reg(4)−Reg(5), 3); Reg(2:5) = Reg(1:4); Reg(1) = Output``).
    The output starts with the first new digit. [-]"""
    taps = tuple(int(f) % 3 for f in reversed(feedback))
    reg, first = list(seed), []
    for _ in range(len(seed)):  # the first n new digits are the register that outputs them
        new = sum(f * r for f, r in zip(feedback, reg, strict=True)) % 3
        reg = [new] + reg[:-1]
        first.append(new)
    return taps, tuple(first)


@dataclass(frozen=True)
class PRTSSequence:
    """A named PRTS: its shift register, its state duration and where it comes from.

    Attributes
    ----------
    name : str
    registers : int
        Register length n; the sequence has 3ⁿ − 1 states. [-]
    taps, seed : tuple of int
        As for :func:`prts_sequence`. [-]
    state_duration : float
        Time per state. [s]
    citation : str
        The source, and what of it is posturelab's own.
    """

    name: str
    registers: int
    taps: tuple[int, ...]
    seed: tuple[int, ...]
    state_duration: float
    citation: str

    @property
    def states(self) -> int:
        """3ⁿ − 1. [-]"""
        return 3 ** self.registers - 1

    @property
    def cycle(self) -> float:
        """states × state_duration. [s]"""
        return self.states * self.state_duration


_COMTEST_TAPS, _COMTEST_SEED = peterka_register((0, 0, -1, 1), (0, 0, 0, 1))
_PETERKA_242_TAPS, _PETERKA_242_SEED = peterka_register((0, 0, 1, -1, -1), (2, 0, 2, 0, 2))

#: The named sequences. Sources (found with posturelab's search tool; see each citation):
#: the COMTEST analysis code github.com/VittorioFreiburg/COMTEST, ANALYSIS/MATLAB/PRTS2012.m
#: and PRTS2020.m ("Calc of the theoretical stimulus": pseudogen3(4, [0 0 −1 1], [0 0 0 1],
#: 25) at 100 samples/s, 80 × 25 samples per cycle); for the 242-state register, Matlab
#: code of Peterka's group and of others that follow Peterka 2002 (pseudogen3(5,
#: [0 0 1 −1 −1], [2 0 2 0 2], …) "% 242 state sequence"; a script that cites the paper
#: gives [2 0 2 0 2] as "the given initial sequence from the paper").
PRTS_SEQUENCES: dict[str, PRTSSequence] = {
    "posturelab-80": PRTSSequence(
        "posturelab-80", 4, POSTURELAB_80_TAPS, POSTURELAB_80_SEED, 0.25,
        "posturelab's own 80-state sequence (register x⁴ + 2x + 2 over GF(3), seed 1000), "
        "0.25 s per state, 20 s cycle: the length, state time and 11-band analysis of the "
        "80-state PRTS of the Eurobench COMTEST protocol (Lippi, Mergner et al.; "
        "github.com/VittorioFreiburg/COMTEST, ANALYSIS/MATLAB/PRTS2020.m), not its register "
        "(that is 'comtest-80'); not Peterka 2002's (that is 'peterka-2002-242')"),
    "comtest-80": PRTSSequence(
        "comtest-80", 4, _COMTEST_TAPS, _COMTEST_SEED, 0.25,
        "The 80-state PRTS of the Eurobench COMTEST protocol's analysis code (Lippi, Mergner "
        "et al.; github.com/VittorioFreiburg/COMTEST, ANALYSIS/MATLAB/PRTS2012.m, "
        "PRTS2020.m: pseudogen3(4, [0 0 −1 1], [0 0 0 1], 25) at 100 samples/s, i.e. 0.25 s "
        "per state, 20 s cycle); the register as posturelab reads pseudogen3's arguments "
        "(peterka_register), and the cycle's start where the register's does (COMTEST "
        "shifts its copy by 912 samples)"),
    "peterka-2002-242": PRTSSequence(
        "peterka-2002-242", 5, _PETERKA_242_TAPS, _PETERKA_242_SEED, 0.25,
        PETERKA_2002_CITATION + "; the register pseudogen3(5, [0 0 1 −1 −1], [2 0 2 0 2]) "
        "as Matlab code of Peterka's group and of others following the paper writes it "
        "(peterka_register), not checked here against the paper's own appendix"),
}
#: The sequence of ``--tilt prts:A`` and of :meth:`PRTSTilt.named` without a name.
DEFAULT_PRTS = "posturelab-80"


def get_prts_sequence(name: str) -> PRTSSequence:
    """The named sequence :data:`PRTS_SEQUENCES` [name].

    Raises
    ------
    UnknownNameError
        Naming the known sequences.
    """

    key = str(name).strip().lower()
    if key not in PRTS_SEQUENCES:
        raise UnknownNameError(f"unknown PRTS sequence {name!r}; known sequences: "
                               f"{', '.join(PRTS_SEQUENCES)}")
    return PRTS_SEQUENCES[key]
