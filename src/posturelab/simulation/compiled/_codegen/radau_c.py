"""Writes ``csrc/pl_radau.h``: the constants of Radau IIA of order 5 as scipy states them
(``scipy.integrate._ivp.radau``), which ``csrc/pl_radau.c`` uses as scipy's Radau does:
printed with every digit of their doubles, so that C and scipy step with the same numbers.
"""

from __future__ import annotations


def _numbers(values) -> str:
    return ", ".join(repr(float(v)) for v in values)


def header() -> str:
    """The text of ``csrc/pl_radau.h``."""
    from scipy.integrate._ivp import radau as scipy_radau

    def matrix(name: str, rows) -> list[str]:
        lines = [f"    {{{_numbers(row)}}}" for row in rows]
        return [f"static const double {name}[3][3] = {{"] + [
            line + ("," if k < 2 else "};") for k, line in enumerate(lines)]

    mu = complex(scipy_radau.MU_COMPLEX)
    return "\n".join([
        "/* Radau IIA of order 5: scipy's constants, GENERATED, do not edit.", " *",
        " * python -m posturelab.simulation.compiled._codegen writes this file from",
        " * scipy.integrate._ivp.radau (_codegen/radau_c.py); pl_radau.c includes it. */",
        "#ifndef PL_RADAU_H", "#define PL_RADAU_H", "",
        "/* the nodes of a step (0, c_1, c_2, 1): where its inputs are taken */",
        f"static const double NODES[4] = {{0.0, {_numbers(scipy_radau.C)}}};",
        "/* the eigenvalues of the inverse Radau matrix, μ_r and μ_c = MU_CRE + i·MU_CIM */",
        f"static const double MU_REAL = {float(scipy_radau.MU_REAL)!r};",
        f"static const double MU_CRE = {mu.real!r}, MU_CIM = {mu.imag!r};",
        "/* the weights of the embedded error estimate */",
        "static const double E1 = {}, E2 = {}, E3 = {};".format(
            *_numbers(scipy_radau.E).split(", ")),
        "/* the dense output Q = Zᵀ P (the collocation polynomial) */",
        *matrix("P", scipy_radau.P),
        "/* the transformation that diagonalises the inverse Radau matrix, and its inverse */",
        *matrix("T", scipy_radau.T), *matrix("TI", scipy_radau.TI),
        "", "#endif", ""])
