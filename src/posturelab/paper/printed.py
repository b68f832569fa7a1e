"""The numbers (and figure captions) the paper prints, with their sources, and our errata.

These are *data*, transcribed from ``paper/ankle-strategy-paper.txt``; the
tests compare our computations against them, and the report shows both side
by side. Nothing here is computed by posturelab.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "TABLE_II_PRINTED",
    "TABLE_II_SOURCE",
    "SENSITIVITY_PRINTED",
    "SENSITIVITY_SOURCE",
    "BACKWARD_INITIAL_STATE",
    "BACKWARD_INITIAL_STATE_SOURCE",
    "Erratum",
    "ERRATA",
    "FIGURE_CAPTIONS",
    "printed_decimals",
    "match_printed_poles",
]

TABLE_II_SOURCE = ("Table II, poles of the linearized system: the seven cases of Table I and "
                   "the variants 6a and 6b of case 6 (nine rows)")

#: Table II as printed: one string per pole, in the paper's column order.
#: Kept as text so the number of printed digits sets each test tolerance.
TABLE_II_PRINTED: dict[str, tuple[str, ...]] = {
    "1": ("-554.04", "-88.94", "-1.60+0.79j", "-1.60-0.79j", "-3.3", "-3.62"),
    "2": ("-481.02", "-87.25", "+1.17", "-3.61", "-3.01+0.11j", "-3.01-0.11j"),
    "3": ("-575.417", "-90.56", "-0.90", "-3.64", "-2.95+0.14j", "-2.95-0.14j"),
    "4": ("-391.20", "-93.36", "-3.64", "-2.75", "-2.23+1.39j", "-2.23-1.39j"),
    "5": ("-320.97", "-90.05", "-3.64", "+1.86", "-3.12+0.76j", "-3.12-0.76j"),
    "6": ("-390.68", "-77.24", "-3.64", "+2.11", "-3.23+0.81j", "-3.23-0.81j"),
    "6a": ("-513.52", "-91.56", "-3.77", "+1.55", "-3.19+0.83j", "-3.19-0.83j"),
    "6b": ("-418.34", "-132.57", "-3.26", "+1.75", "-3.26+0.69j", "-3.26-0.69j"),
    "7": ("-469.46", "-53.90", "-3.46", "-2.67", "-3.18+2.00j", "-3.18-2.00j"),
}

SENSITIVITY_SOURCE = "Section VI (Discussion), the disturbance-severity vector J(Θ)⁻¹H(Θ)"
#: J(0)⁻¹H(0) as printed. [rad/m]
SENSITIVITY_PRINTED: tuple[str, ...] = ("2.5580", "-0.0654", "0.0027")

BACKWARD_INITIAL_STATE_SOURCE = "Section V.B, backward platform motion, initial state"
#: [θ1, θ2, θ3, θ̇1, θ̇2, θ̇3] as printed. [rad], [rad/s]
BACKWARD_INITIAL_STATE: tuple[float, ...] = (0.1, -0.1, 0.1, 2.5580, -0.0654, 0.0027)


def printed_decimals(text: str) -> int:
    """Number of decimals printed in ``text`` (of the real part for a complex entry)."""
    real = text.replace("j", "")
    # split off an imaginary part "+0.79" / "-0.79" after the first character
    for k in range(1, len(real)):
        if real[k] in "+-":
            real = real[:k]
            break
    return len(real.split(".")[1]) if "." in real else 0


def printed_tolerance(text: str) -> float:
    """Half a unit of the last printed digit: the tolerance a printed number implies."""
    return 0.5 * 10.0 ** (-printed_decimals(text))


def match_printed_poles(printed: tuple[str, ...], computed: np.ndarray) -> np.ndarray:
    """Pair each printed pole with the nearest computed one (a one-to-one matching).

    Returns
    -------
    numpy.ndarray of complex
        The computed poles re-ordered to stand beside ``printed``. [1/s]
    """
    from itertools import permutations

    p = np.array([complex(s) for s in printed])
    c = np.asarray(computed, dtype=complex)
    if len(p) <= 8:
        best = min(
            permutations(range(len(c))),
            key=lambda perm: float(np.sum(np.abs(p - c[list(perm)]) / (1 + np.abs(p)))),
        )
        return c[list(best)]
    raise ValueError("too many poles to match")  # pragma: no cover


@dataclass(frozen=True)
class Erratum:
    """A place where the printed paper disagrees with a derivation or with itself."""

    number: int
    where: str
    printed: str
    derived: str
    explanation: str


ERRATA: tuple[Erratum, ...] = (
    Erratum(
        1, "Table II, case 3, third pole", "-0.90", "-0.092",
        "The linearised system gives -0.092 1/s, ten times slower than printed; this slow "
        "mode explains Fig. 10's slow recovery.",
    ),
    Erratum(
        2, "Table II, case 6b, third pole", "-3.26", "-3.752",
        "The printed value repeats the real part of the complex pair beside it.",
    ),
    Erratum(
        3, "Equation (1), vertical platform term", "(ÿ_d − g) G", "−(g + ÿ_d) G",
        "With y up a Lagrangian derivation gives −(g + ÿ_d)G on the left-hand side; the "
        "paper's own text (upward acceleration needs more anti-gravity effort) agrees.",
    ),
    Erratum(
        4, "Section V.C, 'the instability of the biped in Case 3'", "case 3", "case 2",
        "The unstable forward case is case 2 (Fig. 9); case 3 is stable (Fig. 10).",
    ),
    Erratum(
        5, "Section V.B, initial rates", "J⁻¹H at upright: [2.5580, -0.0654, 0.0027]",
        "J⁻¹H at [0.1, -0.1, 0.1]: [2.268, 0.291, -0.071]",
        "The initial rates use J⁻¹H at upright while the initial posture is flexed; "
        "posturelab reproduces the paper's choice and offers the exact one.",
    ),
    Erratum(
        6, "Section V.A, Loram and Lakie's ankle stiffness", "91 N-m",
        "91 ± 23 % of mgh (≈ 513 N·m/rad for this body, mgh ≈ 564 N·m/rad)",
        "Loram and Lakie (2002) report intrinsic stiffness as a fraction of the load "
        "stiffness mgh, not in N·m/rad.",
    ),
    Erratum(
        7, "Table II, case 3, first pole", "-575.417", "-575.405",
        "The only pole printed to three decimals differs from the linearised system in "
        "the fifth significant digit (2e-5 relative); the other poles of the row agree.",
    ),
)

#: The paper's figure captions (Section V), transcribed from paper/ankle-strategy-paper.txt.
FIGURE_CAPTIONS: dict[int, str] = {
    3: "The trajectories of motion: the three angles and the three angular velocities as "
       "functions of time in a backward platform motion.",
    4: "The spatial trajectories of motion: the angles θ2 and θ3 as functions of θ1 in a "
       "backward platform motion - a forward subject sway. All angles seem to linearly depend "
       "on one another, and the knee gets locked at the point of maximum excursion forward.",
    5: "The torque activity at the three joints and the gastrocnemius as functions of time - "
       "all torques are in Newton-meters",
    6: "The quadriceps two-jointed muscle activity as a function of time",
    7: "The phase plane portrait of the horizontal motion of the center of gravity - velocity "
       "versus position - in a backward platform motion, i.e., in a forward sway.",
    8: "The phase plane portrait of the horizontal motion of the center of gravity - velocity "
       "versus position in forward platform disturbance. Artificial antagonistic "
       "gastrocnemius is assumed. In reality, the tibialis anterior would compensate for the "
       "artificial gastrocnemius muscle introduced here, because the knees are locked and θ1 "
       "and θ2 are equal.",
    9: "The phase plane portrait of the horizontal motion of the center of gravity - velocity "
       "versus position - in forward platform disturbance. The system is unstable, and fall "
       "is inevitable. It is possible that a much larger tibialis anterior force would have "
       "prevented the fall.",
    10: "The phase plane portrait of the horizontal motion of the center of gravity - velocity "
        "versus position in forward platform disturbance with no gastrocnemius, but larger "
        "ankle stiffness. The system is recovering from the disturbance but more slowly. A "
        "larger tibialis anterior - soleus force pair would implement this case.",
}
