"""The symbolic specification the compiled engine is generated from (a development tool:
it needs sympy, which the installed package does not).

The model's formulas are written once, in :mod:`posturelab.model` (the entries of the
equation of motion in :mod:`posturelab.model.dynamics`, the disturbances' and tilts' terms in
:mod:`~posturelab.model.platform` and :mod:`~posturelab.model.tilt`, the inputs, the event
values and the saturation in :mod:`posturelab.model.switched`), as functions over a math
namespace ``xp``. The reference engine passes numpy; here :data:`SYMPY` passes sympy, so
that the same functions return expressions, which :func:`c` prints as C.

:func:`equation_of_motion` assembles J(Θ), BΘ̇, G and H of an N-link chain from the same
entry formulas the C is generated from; ``tests/test_symbolic.py`` compares them with an
independent derivation from the chain's Lagrangian.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.c import C99CodePrinter


class _SympyMath:
    """The math namespace of the model's formulas, on sympy expressions."""

    sin = staticmethod(sp.sin)
    cos = staticmethod(sp.cos)
    abs = staticmethod(sp.Abs)
    minimum = staticmethod(sp.Min)
    maximum = staticmethod(sp.Max)
    not_equal = staticmethod(sp.Ne)

    @staticmethod
    def where(condition, a, b):
        return sp.Piecewise((a, condition), (b, True))


#: The sympy namespace for the model's formulas.
SYMPY = _SympyMath()


def symbols(*names: str):
    """Real sympy symbols whose names are C expressions (``"bp[i]"``, ``"y[idx]"``)."""
    out = tuple(sp.Symbol(name, real=True) for name in names)
    return out if len(out) > 1 else out[0]


class _Printer(C99CodePrinter):
    """C with squares as products, ternaries on one line and π as a literal."""

    def _print_Pow(self, expr):
        base, exp = expr.as_base_exp()
        if exp == 2:
            b = self._print(base)
            return f"({b} * {b})" if base.is_Symbol else f"(({b}) * ({b}))"
        if exp == -1:
            return f"1.0 / {self.parenthesize(base, 50)}"
        return super()._print_Pow(expr)

    def _print_Piecewise(self, expr):
        (a, cond), (b, _) = expr.args
        return f"(({self._print(cond)}) ? ({self._print(a)}) : ({self._print(b)}))"

    def _print_Pi(self, expr):
        return "3.14159265358979323846"

    def _print_Integer(self, expr):
        return f"{int(expr)}.0"

    def _print_Symbol(self, expr):
        return expr.name


_PRINTER = _Printer()


def c(expr) -> str:
    """An expression of the specification as C."""
    return _PRINTER.doprint(sp.sympify(expr))


def trig_symbols(expr, angles: dict):
    """``expr`` with sin and cos of differences expanded and sin θ, cos θ of each angle in
    ``angles`` (symbol -> (sin name, cos name)) replaced by those names."""
    expr = sp.expand_trig(expr)
    subs = {}
    for angle, (s, co) in angles.items():
        subs[sp.sin(angle)] = symbols(s)
        subs[sp.cos(angle)] = symbols(co)
    return expr.xreplace(subs)


def equation_of_motion(n: int):
    """J(Θ), BΘ̇, G, H of an N-link chain, assembled from the entry formulas of
    :mod:`posturelab.model.dynamics` on symbols θ_i, θ̇_i, c_ij, J_ii and a_i.

    Returns
    -------
    (J, velocity_terms, G, H, symbols) : sympy matrices and a dict of the symbols
        ``theta``, ``omega``, ``inertia`` (J_ii), ``coupling`` (c_ij, i < j) and
        ``gravity_coefficient`` (a_i).
    """
    from ....model.dynamics import centripetal_formula, coupling_formula, load_formula

    theta = sp.symbols(f"theta0:{n}", real=True)
    omega = sp.symbols(f"omega0:{n}", real=True)
    inertia = sp.symbols(f"J0:{n}", positive=True)
    a = sp.symbols(f"a0:{n}", real=True)
    cpl = {(i, j): sp.Symbol(f"c{min(i, j)}{max(i, j)}", real=True)
           for i in range(n) for j in range(n) if i != j}
    J = sp.Matrix(n, n, lambda i, j: inertia[i] if i == j
                  else coupling_formula(cpl[i, j], theta[i], theta[j], SYMPY))
    B = sp.Matrix([sum((centripetal_formula(cpl[i, j], theta[i], theta[j], omega[j], SYMPY)
                        for j in range(n) if j != i), sp.S.Zero) for i in range(n)])
    G = sp.Matrix([load_formula(a[i], theta[i], 1, 0, SYMPY) for i in range(n)])
    H = sp.Matrix([-load_formula(a[i], theta[i], 0, 1, SYMPY) for i in range(n)])
    return J, B, G, H, {"theta": theta, "omega": omega, "inertia": inertia,
                        "coupling": cpl, "gravity_coefficient": a}
