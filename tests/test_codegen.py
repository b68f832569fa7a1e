"""The compiled engine's generated files: each is what the generator writes now from the one
statement of the model (regenerate them all with
``python -m posturelab.simulation.compiled._codegen``), and each says so in its first lines."""

import numpy as np
import pytest

pytest.importorskip("sympy")

from posturelab.simulation.compiled import _codegen  # noqa: E402

OUTPUTS = _codegen.outputs()


@pytest.mark.parametrize("path", list(OUTPUTS), ids=lambda p: p.name)
def test_generated_file_is_up_to_date(path):
    assert path.read_text(encoding="utf-8") == OUTPUTS[path](), (
        f"{path.name} is stale: run python -m posturelab.simulation.compiled._codegen")


@pytest.mark.parametrize("path", list(OUTPUTS), ids=lambda p: p.name)
def test_generated_file_says_so_in_its_first_lines(path):
    head = "\n".join(path.read_text(encoding="utf-8").splitlines()[:3])
    assert "GENERATED, do not edit" in head


def test_every_c_source_is_generated_or_written_by_hand_not_both():
    """The generated C files are the ones the generator lists; no hand-written file says it
    is generated."""
    csrc = _codegen.CSRC
    generated = {p.name for p in OUTPUTS if p.parent == csrc}
    for path in sorted(csrc.iterdir()):
        says = "GENERATED, do not edit" in "\n".join(path.read_text(encoding="utf-8")
                                                      .splitlines()[:3])
        assert says == (path.name in generated), path.name


def _formulas():
    """(name, function, number of arguments, takes xp) of every formula the C is generated
    from."""
    import inspect

    from posturelab.model import dynamics, kinematics, platform, switched, tilt

    funcs = [switched.pair_torque_formula, switched.pull_value_formula,
             switched.saturated_moment_formula, switched.tilt_pair_torque_formula,
             tilt.axis_acceleration_formula, platform.windowed_sine_formula,
             platform.sine_formula, tilt.sine_tilt_formula, tilt.raised_cosine_tilt_formula,
             tilt.cubic_formula, dynamics.coupling_formula, dynamics.centripetal_formula,
             dynamics.load_formula, kinematics.cog_acceleration_terms_formula,
             *{id(f): f for f in switched.EVENT_VALUES.values()}.values()]
    for f in funcs:
        params = [p for p in inspect.signature(f).parameters if p != "xp"]
        yield f.__name__, f, params, "xp" in inspect.signature(f).parameters


@pytest.mark.parametrize("name,formula,params,takes_xp", list(_formulas()),
                         ids=[f[0] for f in _formulas()])
def test_a_formula_means_the_same_on_numpy_and_on_sympy(name, formula, params, takes_xp, rng):
    """Each formula of the model, evaluated with numpy (the reference engine) and built on
    sympy symbols (the generated C) then evaluated, gives the same numbers: the one statement
    reads the same in both (a comparison written with Python's != or a branch on a value
    would not)."""
    import sympy as sp

    from posturelab.simulation.compiled._codegen.spec import SYMPY

    symbols = sp.symbols(" ".join(f"v{i}" for i in range(len(params))), real=True, seq=True)
    symbolic = formula(*symbols, xp=SYMPY) if takes_xp else formula(*symbols)
    symbolic = symbolic if isinstance(symbolic, tuple) else (symbolic,)
    evaluate = sp.lambdify(symbols, symbolic, "math")
    for _ in range(50):
        values = rng.normal(0.0, 2.0, len(params))
        if "saturation" in params:
            values[params.index("saturation")] = rng.choice([-1.0, 0.0, 1.0])
        numeric = formula(*values)
        numeric = numeric if isinstance(numeric, tuple) else (numeric,)
        np.testing.assert_allclose(np.array(evaluate(*values), dtype=float),
                                   np.array(numeric, dtype=float), rtol=1e-12, atol=1e-12)


def test_a_switch_means_the_same_on_numpy_and_on_sympy():
    """What each switch sets (the generated pl_apply_switch prints these on sympy symbols)
    equals what the reference engine sets, including a stretch rate of exactly zero."""
    import sympy as sp

    from posturelab.model import switched
    from posturelab.simulation.compiled._codegen.spec import SYMPY

    rate, side, shank, stop = sp.symbols("rate side shank stop", real=True)
    for kind, effect in switched.SWITCH_EFFECTS.items():
        for r, s in [(-0.3, 1.0), (0.0, -1.0), (0.7, 1.0)]:
            if effect == "active":
                symbolic = switched.pair_activity_after(kind, rate, SYMPY.where)
                assert float(sp.sympify(symbolic).subs(rate, r)) == \
                    switched.pair_activity_after(kind, r)
            elif effect == "saturation":
                symbolic = switched.saturation_after(kind, side)
                assert float(sp.sympify(symbolic).subs(side, s)) == \
                    switched.saturation_after(kind, s)
    assert float(switched.knee_angle_at_stop(shank, stop).subs({shank: 0.1, stop: -0.2})) \
        == switched.knee_angle_at_stop(0.1, -0.2)
