"""Printed-versus-computed comparisons of the paper's numbers (Table II, J⁻¹H)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..linear.analysis import analyse, disturbance_sensitivity
from ..model.body import Body, paper_body
from ..model.muscles import STIFFNESS_CASES, paper_muscles
from .printed import (
    ERRATA,
    SENSITIVITY_PRINTED,
    TABLE_II_PRINTED,
    Erratum,
    match_printed_poles,
    printed_tolerance,
)

__all__ = ["PoleComparison", "Table2Row", "table2_comparison", "sensitivity_comparison"]

#: Table II entries known to disagree: (case, column index) -> erratum number.
TABLE_II_ERRATA: dict[tuple[str, int], int] = {("3", 2): 1, ("6b", 2): 2, ("3", 0): 7}


@dataclass(frozen=True)
class PoleComparison:
    """One Table II entry: printed text, our value, and whether they agree."""

    printed: str
    computed: complex
    tolerance: float
    agrees: bool
    erratum: int | None

    @property
    def printed_value(self) -> complex:
        """The printed pole as a number. [1/s]"""
        return complex(self.printed)


@dataclass(frozen=True)
class Table2Row:
    """A Table II row: a Table I case, its stiffness [N·m/rad], and six poles [1/s]."""

    case: str
    stiffness: tuple[float, ...]
    poles: tuple[PoleComparison, ...]
    stable: bool

    @property
    def agrees(self) -> bool:
        """True when every printed pole of the row is matched within its printed digits."""
        return all(p.agrees for p in self.poles)


def table2_comparison(body: Body | None = None, viscosity_ratio: float = 0.25) -> list[Table2Row]:
    """Table II as printed beside what the linearised paper model gives.

    Each printed pole is paired with the nearest computed pole; it agrees when
    both real and imaginary parts are within half a unit of the last printed
    digit.
    """
    body = paper_body() if body is None else body
    rows = []
    for case, printed in TABLE_II_PRINTED.items():
        res = analyse(body, paper_muscles(case, viscosity_ratio=viscosity_ratio))
        matched = match_printed_poles(printed, res.poles)
        entries = []
        for col, (text, value) in enumerate(zip(printed, matched, strict=True)):
            tol = printed_tolerance(text)
            pv = complex(text)
            ok = abs(pv.real - value.real) <= tol * (1 + 1e-9) and abs(
                pv.imag - value.imag
            ) <= tol * (1 + 1e-9)
            flag = TABLE_II_ERRATA.get((case, col))
            entries.append(PoleComparison(text, complex(value), tol, bool(ok), flag))
        rows.append(Table2Row(case, STIFFNESS_CASES[case], tuple(entries), res.stable))
    return rows


@dataclass(frozen=True)
class SensitivityComparison:
    """J(0)⁻¹H(0): printed and computed. [rad/m]"""

    printed: tuple[str, ...]
    computed: np.ndarray
    agrees: bool


def sensitivity_comparison(body: Body | None = None) -> SensitivityComparison:
    """The printed disturbance-severity vector beside ours, at upright."""
    body = paper_body() if body is None else body
    value = disturbance_sensitivity(body)
    ok = all(
        abs(complex(t).real - v) <= printed_tolerance(t)
        for t, v in zip(SENSITIVITY_PRINTED, value, strict=True)
    )
    return SensitivityComparison(SENSITIVITY_PRINTED, value, ok)


def erratum(number: int) -> Erratum:
    """The :class:`posturelab.paper.Erratum` with this number."""
    return next(e for e in ERRATA if e.number == number)
