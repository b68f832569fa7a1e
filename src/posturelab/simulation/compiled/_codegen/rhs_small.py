"""Generates ``csrc/pl_rhs_small.c``: the right-hand side for N = 1, 2, 3 links as
straight-line C.

Run ``python -m posturelab.simulation.compiled._codegen`` to rewrite the file; a test
regenerates it and compares. The entries (J_ij, the centripetal terms, gravity and platform
load, saturation) are the formulas of :mod:`posturelab.model.dynamics` and
:mod:`posturelab.model.switched` printed through :mod:`.spec`, as in the general-N code of
``csrc/pl_model.c``, unrolled: for link i,

* τ_j = (T_K Θ + T_L Θ̇ + τ_delayed)_j, or its positive or negative limit while joint j
  saturates; U_i = τ_{i+1} − τ_i
* r_i = U_i − Σ_{j≠i} c_ij sin(θ_i − θ_j) θ̇_j² + a_i ((g + ÿ_d) sin θ_i − ẍ_d cos θ_i)
* J_ii = I_i + m_i k_i² + …, J_ij = c_ij cos(θ_j − θ_i); Θ̈ = adj(J) r / det J
* with the knee locked, Θ̈ − J⁻¹C (C·Θ̈)/(C·J⁻¹C), C = (−1, 1, 0).

The adjugates come from sympy (a development dependency), with common
subexpressions shared; the determinant is the first row's cofactor expansion.
"""

from __future__ import annotations

import sys
from pathlib import Path

TARGET = Path(__file__).resolve().parent.parent / "csrc" / "pl_rhs_small.c"
SIZES = (1, 2, 3)

HEADER = """/* Right-hand sides for N = 1, 2, 3 links: GENERATED, do not edit.
 *
 * python -m posturelab.simulation.compiled._codegen writes this file from the formulas of
 * posturelab.model (those of pl_rhs_general in pl_model.c, unrolled); a test regenerates
 * it and compares. */
#include "pl.h"
"""


def _printer():
    from sympy.printing.str import StrPrinter

    class Printer(StrPrinter):
        """C expressions with squares as products."""

        def _print_Pow(self, expr, rational=False):
            base, exp = expr.as_base_exp()
            if exp == 2:
                b = self._print(base)
                return f"{b}*{b}" if base.is_Symbol else f"({b})*({b})"
            raise ValueError(f"unexpected power {expr}")

        def _print_Integer(self, expr):
            return f"{int(expr)}.0"

    return Printer()


def _adjugate_lines(n: int, printer) -> tuple[list[str], list[list[str]]]:
    """C statements computing the adjugate m_ij of the symmetric J (entries j_ab, a <= b)."""
    import sympy as sp

    J = sp.Matrix(n, n, lambda i, j: sp.Symbol(f"j{min(i, j)}{max(i, j)}"))
    adj = J.adjugate()
    entries = [adj[i, j] for i in range(n) for j in range(n)]
    subs, reduced = sp.cse(entries, symbols=sp.numbered_symbols("q"), optimizations="basic")
    lines = [f"const double {printer.doprint(s)} = {printer.doprint(e)};" for s, e in subs]
    names = [[f"m{i}{j}" for j in range(n)] for i in range(n)]
    for k, expr in enumerate(reduced):
        lines.append(f"const double {names[k // n][k % n]} = {printer.doprint(expr)};")
    return lines, names


def _entry(expr, *links: int) -> str:
    """An entry formula on θ_i symbols printed with s[i], c[i] for sin θ_i, cos θ_i."""
    from .spec import c, symbols, trig_symbols

    return c(trig_symbols(expr, {symbols(f"th[{i}]"): (f"s[{i}]", f"c[{i}]") for i in links}))


def _coupling(n: int, i: int, j: int) -> str:
    from ....model.dynamics import coupling_formula
    from .spec import SYMPY, symbols

    return _entry(coupling_formula(symbols(f"bp[{2 * n + i * n + j}]"), symbols(f"th[{i}]"),
                                   symbols(f"th[{j}]"), SYMPY), i, j)


def _centripetal(n: int, i: int, j: int) -> str:
    from ....model.dynamics import centripetal_formula
    from .spec import SYMPY, symbols

    return _entry(centripetal_formula(symbols(f"bp[{2 * n + min(i, j) * n + max(i, j)}]"),
                                      symbols(f"th[{i}]"), symbols(f"th[{j}]"),
                                      symbols(f"w[{j}]"), SYMPY), i, j)


def _load(i: int) -> str:
    from ....model.dynamics import load_formula
    from .spec import SYMPY, symbols

    return _entry(load_formula(symbols(f"bp[{i}]"), symbols(f"th[{i}]"), *symbols("ga", "ax"),
                               SYMPY), i)


def _saturated(j: int, n: int) -> str:
    from ....model.switched import saturated_moment_formula
    from .spec import SYMPY, c, symbols

    return c(saturated_moment_formula(*symbols(f"t[{j}]", f"md->sat[{j}]", f"md->lim[{j}]",
                                               f"md->lim[{n + j}]"), SYMPY))


def _rhs_function(n: int, printer) -> str:
    L = [f"void pl_rhs{n}(const pl_model *md, const double *x, double *out, const double *inp, "
         "int locked)", "{",
         "    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + " + str(n * n) + ";",
         f"    double th[{n}], w[{n}], s[{n}], c[{n}], t[{n}], a[{n}], ax, ga;"]
    if n == 1:
        L.append("    (void)locked;")
    for i in range(n):  # θ_i, θ̇_i, sin θ_i and cos θ_i (about the step's start: pl_rotate)
        L.append(f"    th[{i}] = x[{i}];")
        L.append(f"    w[{i}] = x[{n + i}];")
        L.append(f"    pl_rotate(th[{i}], md->base[{i}], md->base[{n + i}], md->base[{2 * n + i}], "
                 f"&s[{i}], &c[{i}]);")
    L += ["    ax = inp[0];", f"    ga = bp[{2 * n + n * n}] + inp[1];"]
    for j in range(n):
        k_terms = " + ".join(f"tk[{j * n + k}] * th[{k}]" for k in range(n))
        l_terms = " + ".join(f"tl[{j * n + k}] * w[{k}]" for k in range(n))
        L.append(f"    t[{j}] = inp[{2 + j}] + ({k_terms}) + ({l_terms});")
        L.append(f"    t[{j}] = {_saturated(j, n)};")
    for i in range(n):
        rhs = f"t[{i + 1}] - t[{i}]" if i + 1 < n else f"-t[{i}]"
        L.append(f"    const double u{i} = {rhs};")
    for i in range(n):
        terms = [_centripetal(n, i, j) for j in range(n) if j != i]
        bterm = f" - ({' + '.join(terms)})" if terms else ""
        L.append(f"    const double r{i} = u{i}{bterm} + {_load(i)};")
    for i in range(n):
        L.append(f"    const double j{i}{i} = bp[{n + i}];")
        for j in range(i + 1, n):
            L.append(f"    const double j{i}{j} = {_coupling(n, i, j)};")
    lines, names = _adjugate_lines(n, printer)
    L += [f"    {line}" for line in lines]
    det = " + ".join(f"j{min(0, k)}{max(0, k)} * {names[k][0]}" for k in range(n))
    L.append(f"    const double inv_det = 1.0 / ({det});")
    for i in range(n):
        terms = " + ".join(f"{names[i][k]} * r{k}" for k in range(n))
        L.append(f"    a[{i}] = ({terms}) * inv_det;")
    if n >= 2:
        L.append("    if (locked) {  /* knee constraint C = (−1, 1, 0): "
                 "Θ̈ −= J⁻¹C (C·Θ̈)/(C·J⁻¹C) */")
        for i in range(n):
            L.append(f"        const double y{i} = {names[i][1]} - {names[i][0]};")
        L.append("        const double lam = (a[1] - a[0]) / (y1 - y0);")
        for i in range(n):
            L.append(f"        a[{i}] -= y{i} * lam;")
        L.append("    }")
    # the stores, all last: out and tau may not be read again, whatever they alias
    L += [f"    md->tau[{j}] = t[{j}];" for j in range(n)]
    L += [f"    out[{i}] = w[{i}];" for i in range(n)]
    L += [f"    out[{n + i}] = a[{i}];" for i in range(n)]
    L.append("}")
    return "\n".join(L) + "\n"


def generate() -> str:
    """The text of ``csrc/pl_rhs_small.c``."""
    printer = _printer()
    return HEADER + "".join("\n" + _rhs_function(n, printer) for n in SIZES)


def main() -> int:
    """Write ``csrc/pl_rhs_small.c``."""
    TARGET.write_text(generate(), encoding="utf-8")
    print(f"wrote {TARGET}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
