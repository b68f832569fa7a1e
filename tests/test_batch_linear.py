"""Batched linear stability (posturelab.linear.batch) against the single-case path.

Independent references: posturelab.linear.analyse (numpy eigvals of the 6×6
state matrix), numpy.poly of that matrix, and the analytic roots of the
one-link pendulum J s² + v s + (k − g a) = 0.

Tolerances: poles within 1e-8 · max(1, |λ|) [1/s] of eigvals (the module's
stated accuracy); characteristic coefficients within 1e-10 of the largest
coefficient; stable flags identical.
"""

import numpy as np
import pytest

from posturelab.errors import ParameterError, UnknownNameError
from posturelab.linear import analyse, sorted_poles
from posturelab.linear.batch import (
    GRID_PARAMETERS,
    STABILITY_MARGIN,
    BodyArrays,
    ParameterRange,
    batch_analyse,
    batch_stable,
    characteristic_polynomials,
    parameter_grid,
    stability_map,
)
from posturelab.model.body import Body, paper_body
from posturelab.model.muscles import (
    PAPER_PAIR_NAMES,
    STIFFNESS_CASES,
    MusclePair,
    MuscleSet,
    paper_muscles,
)

POLE_RTOL = 1e-8
CASES = list(STIFFNESS_CASES)
TABLE_I = np.array([STIFFNESS_CASES[c] for c in CASES])


def pole_error(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a − b| / max(1, |b|) over matched (sorted) poles. [-]"""
    return float(np.max(np.abs(a - b) / np.maximum(1.0, np.abs(b))))


@pytest.fixture(scope="module")
def random_sets():
    """~200 random parameter sets (seeded): stiffness [N·m/rad], viscosity ratio [s]."""
    rng = np.random.default_rng(20261122)
    stiffness = rng.uniform(0.0, 1500.0, (200, 5))
    stiffness[rng.random((200, 5)) < 0.15] = 0.0  # some pairs switched off, as in Table I
    ratio = rng.uniform(0.02, 0.6, 200)
    return stiffness, ratio


def test_table_i_cases_match_single_case(body):
    """Table I (all nine cases, ratio 0.25): poles and flags equal linear.analyse."""
    res = batch_analyse(TABLE_I, 0.25, keep_poles=True)
    flags = batch_stable(TABLE_I, 0.25)
    for i, case in enumerate(CASES):
        single = analyse(body, paper_muscles(case))
        assert pole_error(res.poles[i], single.poles) < POLE_RTOL, case
        assert res.stable[i] == single.stable == flags[i], case
        assert res.max_real_part[i] == pytest.approx(single.max_real_part, abs=1e-9)


def test_random_sets_match_single_case(body, random_sets):
    """~200 random sets: poles within 1e-8 relative of eigvals, flags identical."""
    stiffness, ratio = random_sets
    res = batch_analyse(stiffness, ratio, keep_poles=True)
    flags = batch_stable(stiffness, ratio)
    assert 0.1 < res.stable.mean() < 0.95  # both kinds present
    for i in range(len(ratio)):
        single = analyse(body, paper_muscles(stiffness=stiffness[i], viscosity_ratio=ratio[i]))
        assert pole_error(res.poles[i], single.poles) < POLE_RTOL, i
        assert res.stable[i] == single.stable == flags[i], i
        scale = max(1.0, np.abs(single.poles).max())
        assert res.max_real_part[i] == pytest.approx(single.max_real_part, abs=POLE_RTOL * scale)


def test_poles_sorted_and_conjugate_exact(random_sets):
    """Poles come sorted like linear.sorted_poles, with exact conjugate pairs."""
    stiffness, ratio = random_sets
    poles = batch_analyse(stiffness, ratio, keep_poles=True).poles
    np.testing.assert_array_equal(poles, sorted_poles(poles))
    for row in poles:
        np.testing.assert_array_equal(np.sort_complex(row), np.sort_complex(row.conj()))


def test_per_pair_viscosity_equals_ratio(random_sets):
    """pair_viscosity = ratio × stiffness gives the same result as the ratio form."""
    stiffness, ratio = random_sets
    a = batch_analyse(stiffness, ratio, keep_poles=True)
    b = batch_analyse(stiffness, pair_viscosity=ratio[:, None] * stiffness, keep_poles=True)
    np.testing.assert_allclose(b.poles, a.poles, rtol=0, atol=1e-9 * np.abs(a.poles).max())
    np.testing.assert_array_equal(a.stable, b.stable)


def test_characteristic_polynomial_equals_det_j_times_numpy_poly(body):
    """c(s) = det(J0)·det(sI − A): compare with numpy.poly of the state matrix."""
    coef = characteristic_polynomials(TABLE_I, 0.25)
    for i, case in enumerate(CASES):
        A = analyse(body, paper_muscles(case)).state_matrix
        ref = np.poly(A)[::-1] * coef[i, -1]
        np.testing.assert_allclose(coef[i], ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    jac0 = np.diag(body.inertia_diagonal) + body.coupling
    assert coef[0, -1] == pytest.approx(np.linalg.det(jac0), rel=1e-12)


def test_one_link_pendulum_analytic_roots():
    """Limit case N = 1: roots of J s² + v s + (k − g a) by the quadratic formula."""
    mass, length, com, inertia, g = 70.0, 1.0, 0.9, 5.0, 9.81
    pendulum = Body.from_arrays([mass], [length], [com], [inertia], gravity=g)
    ankle = MuscleSet((MusclePair("ankle", 0, 1, 0.0, 0.0),), 1)
    stiffness = np.array([[300.0], [700.0], [1000.0], [618.03]])  # unstable, real, complex, ~mgh
    res = batch_analyse(stiffness, 0.25, body=pendulum, muscles=ankle, keep_poles=True)
    jac = inertia + mass * com**2
    load = g * mass * com
    for i, stiff in enumerate(stiffness[:, 0]):
        disc = complex((0.25 * stiff) ** 2 - 4 * jac * (stiff - load))
        roots = np.array([(-0.25 * stiff + s * disc**0.5) / (2 * jac) for s in (1, -1)])
        assert pole_error(res.poles[i], sorted_poles(roots)) < 1e-12
        assert res.stable[i] == (stiff > load)
    assert batch_stable(stiffness, 0.25, body=pendulum, muscles=ankle).tolist() == [
        s > load for s in stiffness[:, 0]
    ]


def test_four_link_chain_general_path():
    """General N: a 4-link chain with 7 pairs and per-pair viscosity matches analyse."""
    rng = np.random.default_rng(7)
    chain = Body.from_arrays(rng.uniform(2, 30, 4), rng.uniform(0.3, 0.6, 4),
                             [0.1, 0.2, 0.15, 0.2], rng.uniform(0.1, 2, 4))
    spans = [(0, 1), (1, 2), (2, 3), (3, 4), (0, 2), (1, 3), (2, 4)]
    template = MuscleSet(tuple(MusclePair(f"p{i}", lo, hi, 0, 0)
                               for i, (lo, hi) in enumerate(spans)), 4)
    stiffness = rng.uniform(0, 2000, (40, 7))
    viscosity = rng.uniform(0, 300, (40, 7))
    res = batch_analyse(stiffness, pair_viscosity=viscosity, body=chain, muscles=template,
                        keep_poles=True)
    flags = batch_stable(stiffness, pair_viscosity=viscosity, body=chain, muscles=template)
    for i in range(40):
        muscles = MuscleSet(tuple(MusclePair(f"p{j}", lo, hi, stiffness[i, j], viscosity[i, j])
                                  for j, (lo, hi) in enumerate(spans)), 4)
        single = analyse(chain, muscles)
        assert pole_error(res.poles[i], single.poles) < POLE_RTOL
        assert res.stable[i] == single.stable == flags[i]


def test_per_set_body_arrays(body):
    """BodyArrays with one body per set equals analysing each body on its own."""
    rng = np.random.default_rng(3)
    scale = rng.uniform(0.8, 1.2, (9, 1))
    gravity = rng.uniform(9.0, 10.0, 9)
    arrays = BodyArrays(body.masses * scale, body.lengths, body.com_distances, body.inertias,
                        gravity)
    res = batch_analyse(TABLE_I, body=arrays, keep_poles=True)
    for i, case in enumerate(CASES):
        single_body = Body.from_arrays(arrays.masses[i], body.lengths, body.com_distances,
                                       body.inertias, gravity=gravity[i])
        single = analyse(single_body, paper_muscles(case))
        assert pole_error(res.poles[i], single.poles) < POLE_RTOL
        assert res.stable[i] == single.stable
    shared = batch_analyse(TABLE_I, body=BodyArrays.from_body(body), keep_poles=True)
    np.testing.assert_array_equal(shared.poles, batch_analyse(TABLE_I, keep_poles=True).poles)


def test_zero_viscosity_is_not_asymptotically_stable():
    """Viscosity 0: poles on the imaginary axis, so never 'stable' (margin δ, module notes)."""
    res = batch_analyse(TABLE_I, 0.0, keep_poles=True)
    assert not res.stable.any()
    assert not batch_stable(TABLE_I, 0.0).any()
    undamped = res.poles[0]  # case 1: K − g·diag(a) is positive definite
    np.testing.assert_allclose(undamped.real, 0.0, atol=1e-9)
    assert np.all(np.abs(undamped.imag) > 1.0)


def test_margin_boundary_shifted_pendulum():
    """Near-marginal: a pendulum with Re λ = −2δ is stable, one with Re λ = −δ/2 is not.

    (linear.analyse calls both stable: the documented band [−δ, 0).)
    """
    pendulum = Body.from_arrays([1.0], [1.0], [1.0], [1.0], gravity=1.0)  # J = 2, g·a = 1
    ankle = MuscleSet((MusclePair("ankle", 0, 1, 0.0, 0.0),), 1)
    stiffness = np.array([[3.0], [3.0]])  # 2 s² + v s + 2: Re λ = −v/4, ρ = 1, δ = margin
    viscosity = np.array([[8 * STABILITY_MARGIN], [2 * STABILITY_MARGIN]])
    res = batch_analyse(stiffness, pair_viscosity=viscosity, body=pendulum, muscles=ankle)
    flags = batch_stable(stiffness, pair_viscosity=viscosity, body=pendulum, muscles=ankle)
    np.testing.assert_allclose(res.max_real_part,
                               [-2 * STABILITY_MARGIN, -STABILITY_MARGIN / 2], rtol=1e-6)
    assert res.stable.tolist() == [True, False] == flags.tolist()


def test_fallback_to_eigvals_when_not_converged(body):
    """A set whose root iteration does not converge is recomputed with eigvals."""
    res = batch_analyse(TABLE_I, keep_poles=True, _max_iterations=1)
    for i, case in enumerate(CASES):
        single = analyse(body, paper_muscles(case))
        assert pole_error(res.poles[i], single.poles) < POLE_RTOL
        assert res.stable[i] == single.stable


def test_empty_and_single_row():
    """Zero sets give empty results; a 1-D stiffness is one set."""
    assert batch_analyse(np.empty((0, 5))).stable.shape == (0,)
    assert batch_stable(np.empty((0, 5))).shape == (0,)
    assert batch_analyse(STIFFNESS_CASES["1"], keep_poles=True).poles.shape == (1, 6)


@pytest.mark.parametrize("kwargs,match", [
    (dict(pair_stiffness=np.ones((3, 4))), r"shape \(M, 5\)"),
    (dict(pair_stiffness=-np.ones((3, 5))), ">= 0"),
    (dict(pair_stiffness=np.full((3, 5), np.nan)), "finite"),
    (dict(pair_stiffness=np.ones((3, 5)), viscosity_ratio=np.ones(2)), r"shape \(3,\)"),
    (dict(pair_stiffness=np.ones((3, 5)), viscosity_ratio=-0.1), ">= 0"),
    (dict(pair_stiffness=np.ones((3, 5)), viscosity_ratio=0.2,
          pair_viscosity=np.ones((3, 5))), "not both"),
    (dict(pair_stiffness=np.ones((3, 5)), pair_viscosity=np.ones((2, 5))), "3 rows"),
])
def test_bad_inputs_raise_parameter_error(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        batch_analyse(**kwargs)


def test_body_and_muscles_must_agree():
    pendulum = Body.from_arrays([1.0], [1.0], [0.5], [1.0])
    with pytest.raises(ParameterError, match="links"):
        batch_stable(np.ones((2, 5)), body=pendulum)
    with pytest.raises(ParameterError, match="sets"):
        batch_stable(np.ones((2, 5)), body=BodyArrays(np.ones((3, 3)), [1, 1, 1],
                                                       [0.5, 0.5, 0.5], [1, 1, 1]))


# ---- parameter grids -------------------------------------------------------


def test_parameter_grid_layout():
    """Row-major grid: set iy·nx + ix has x_values[ix], y_values[iy]; the rest from case 1."""
    grid = parameter_grid(("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000),
                          (5, 3), case="1")
    assert grid.shape == (3, 5) and grid.size == 15
    np.testing.assert_allclose(grid.x_values, [0, 500, 1000, 1500, 2000])
    np.testing.assert_allclose(grid.y_values, [0, 500, 1000])
    stiffness, ratio = grid.pair_stiffness, grid.viscosity_ratio
    assert stiffness.shape == (15, 5)
    np.testing.assert_array_equal(ratio, 0.25)
    assert stiffness[2 * 5 + 3].tolist() == [1500.0, 300.0, 300.0, 300.0, 1000.0]
    np.testing.assert_array_equal(stiffness[:, 1:4], 300.0)
    rows_s, rows_r = grid.rows(1, 2)
    np.testing.assert_array_equal(rows_s, stiffness[5:10])
    np.testing.assert_array_equal(rows_r, ratio[5:10])


def test_parameter_grid_viscosity_axis_and_table_i_points():
    """A viscosity-ratio axis; Table I cases in the plane are found, others are not."""
    grid = parameter_grid(ParameterRange("viscosity_ratio", 0.1, 0.5), ("stiffness:ankle", 0,
                                                                        1200), 3,
                          case="2")
    np.testing.assert_allclose(grid.viscosity_ratio[:3], [0.1, 0.3, 0.5])
    np.testing.assert_array_equal(grid.pair_stiffness[:, 4], 0.0)
    # case 2 (ankle 500) and case 3 (ankle 1000) share every other value with case 2
    assert grid.table_i_points() == [("2", 0.25, 500.0), ("3", 0.25, 1000.0)]
    plane = parameter_grid(("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000), 2,
                           case="1")
    assert plane.table_i_points() == [("1", 500.0, 300.0), ("2", 500.0, 0.0),
                                      ("3", 1000.0, 0.0)]
    off_ratio = parameter_grid(("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000),
                               2,
                               viscosity_ratio=0.3)
    assert off_ratio.table_i_points() == []


@pytest.mark.parametrize("args,error,match", [
    ((("ankel", 0, 1), ("stiffness:hip", 0, 1)), UnknownNameError, "known: stiffness:ankle"),
    ((("ankle", 0, 1), ("stiffness:hip", 0, 1)), ParameterError, "now called 'stiffness:ankle'"),
    ((("stiffness:ankle", 2, 1), ("stiffness:hip", 0, 1)), ParameterError, "low < high"),
    ((("stiffness:ankle", -1, 1), ("stiffness:hip", 0, 1)), ParameterError, ">= 0"),
    ((("stiffness:ankle", 0, 1), ("stiffness:ankle", 0, 1)), ParameterError, "different"),
    ((("stiffness:ankle", 0, 1), ("stiffness:hip", 0, 1), 1), ParameterError, r"\[2, 5000\]"),
    ((("stiffness:ankle", 0, 1), ("stiffness:hip", 0, 1), 5001), ParameterError, r"\[2, 5000\]"),
])
def test_parameter_grid_rejects_bad_input(args, error, match):
    with pytest.raises(error, match=match):
        parameter_grid(*args)


def test_parameter_grid_rejects_unknown_case_and_double_ratio():
    with pytest.raises(UnknownNameError, match="known cases"):
        parameter_grid(("stiffness:ankle", 0, 1), ("stiffness:hip", 0, 1), 2, case="8")
    with pytest.raises(ParameterError, match="swept"):
        parameter_grid(("viscosity_ratio", 0, 1), ("stiffness:hip", 0, 1), 2, viscosity_ratio=0.3)


def test_grid_parameter_names():
    assert GRID_PARAMETERS == (*(f"stiffness:{p}" for p in PAPER_PAIR_NAMES), "viscosity_ratio")


def test_stability_map_matches_single_case(body):
    """A small map: each point equals analyse of its own parameter set; progress reported."""
    calls = []
    smap = stability_map(("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000),
                         (4, 3), case="1",
                         progress=lambda done, total: calls.append((done, total)))
    assert smap.max_real_part.shape == smap.stable.shape == (3, 4)
    assert calls[0] == (0, 12) and calls[-1] == (12, 12)
    for iy, gastro in enumerate(smap.grid.y_values):
        for ix, ankle in enumerate(smap.grid.x_values):
            single = analyse(body, paper_muscles(stiffness=[ankle, 300, 300, 300, gastro]))
            assert smap.stable[iy, ix] == single.stable
            assert smap.max_real_part[iy, ix] == pytest.approx(single.max_real_part, abs=1e-9)


def test_three_link_fast_path_equals_general_expansion(rng):
    """The unrolled N = 3 determinant equals the general subset expansion (any matrices)."""
    import numba

    from posturelab.linear._batch_kernels import (
        _polynomial_determinant,
        _polynomial_determinant3,
    )
    from posturelab.linear.batch import _subset_tables

    @numba.njit
    def both(jac, damp, load, masks, mask_start, minors, fast, general):
        # the kernels have no Python wrapper: called from a compiled function
        _polynomial_determinant3(jac, damp, load, fast)
        _polynomial_determinant(jac, damp, load, masks, mask_start, minors, general)

    masks, mask_start = _subset_tables(3)
    minors = np.zeros((8, 7))
    for _ in range(20):
        jac, damp, load = rng.normal(size=(3, 3, 3))
        fast, general = np.empty(7), np.empty(7)
        both(jac, damp, load, masks, mask_start, minors, fast, general)
        np.testing.assert_allclose(fast, general, rtol=1e-12, atol=1e-12)
        # and both equal det at a sample point s = 0.7
        s = 0.7
        assert np.polyval(fast[::-1], s) == pytest.approx(
            np.linalg.det(s**2 * jac + s * damp + load), rel=1e-10, abs=1e-12)


def reference_csv(smap) -> str:
    """The CSV text as Python's %-formatting gives it (the writer's specification)."""
    g = smap.grid
    lines = [f"{g.x.name},{g.y.name},max_real_part,stable\n"]
    for iy, y in enumerate(g.y_values):
        for ix, x in enumerate(g.x_values):
            lines.append("%.12g,%.12g,%.12g,%d\n" % (x, y, smap.max_real_part[iy, ix],  # noqa: UP031
                                                     smap.stable[iy, ix]))
    return "".join(lines)


#: Values whose %.12g text is easy to get wrong, or that the compiled writer leaves to Python.
SPECIAL_VALUES = [0.0, -0.0, np.nan, np.inf, -np.inf, 1e-300, -5e-324, 1.7e308, 1e-4, 1e-5,
                  9.99999999999949e-5, 99999.9999999995, 999999999999.5, 0.1, 1 / 3, -2 / 3,
                  -1e-11, 1e12, -0.5, 2.5, 123456789012.5, 1e-15]


def awkward_values(rng, count):
    """SPECIAL_VALUES, exact ties at the 12th digit, powers of ten and their neighbours,
    and ``count`` values spread over 27 decades and around 0."""
    ties = (rng.integers(10**11, 10**12, count) + 0.5) * 10.0 ** rng.integers(-12, 1, count)
    edges = [10.0**k for k in range(-12, 14)]
    edges += [np.nextafter(v, s) for v in edges for s in (0.0, np.inf)]
    spread = rng.choice([-1.0, 1.0], count) * 10.0 ** rng.uniform(-13, 14, count)
    return np.concatenate([SPECIAL_VALUES, ties, edges, spread, rng.normal(size=count)])


def test_compiled_g12_equals_python_formatting(rng):
    from posturelab.linear import _format_kernels as fmt

    values = awkward_values(rng, 20_000)
    text = np.zeros((values.size, fmt.WIDTH), dtype=np.uint8)
    lengths = np.empty(values.size, dtype=np.int64)
    fmt.format_g12(values, text, lengths)
    left = set(fmt.special_values(values).tolist())
    for i, v in enumerate(values.tolist()):
        if lengths[i] < 0:
            assert i in left, v  # every value the kernel declines is preformatted
            continue
        assert i not in left or v == 0.0
        assert text[i, :lengths[i]].tobytes().decode() == "%.12g" % v, v  # noqa: UP031


@pytest.mark.parametrize("rows_per_block", [1, 7, 100_000])
def test_write_csv_is_the_percent_format_text(rng, tmp_path, rows_per_block):
    """The compiled writer gives the text of "%.12g,%.12g,%.12g,%d" row by row, to a
    text file (bytes written beneath it) or any text stream, block by block."""
    import io

    from posturelab.linear.batch import StabilityMap

    grid = parameter_grid(("stiffness:ankle", 0, 1999.9), ("viscosity_ratio", 1e-5, 0.6), (9, 6))
    values = awkward_values(rng, 2)[:54].reshape(6, 9)
    smap = StabilityMap(grid, values, rng.random((6, 9)) < 0.5)
    expected = reference_csv(smap)
    stream = io.StringIO()
    calls = []
    smap.write_csv(stream, rows_per_block=rows_per_block,
                   progress=lambda done, total: calls.append((done, total)))
    assert stream.getvalue() == expected
    assert calls[-1] == (54, 54) and len(calls) == -(-54 // rows_per_block)
    path = tmp_path / "map.csv"
    with open(path, "w", encoding="utf-8", newline="") as f:
        f.write("")  # the header goes through the text layer, the rows beneath it
        smap.write_csv(f, rows_per_block=rows_per_block)
    assert path.read_bytes() == expected.encode("ascii")


def test_write_csv_of_a_computed_map_is_the_percent_format_text():
    import io

    smap = stability_map(("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000), (23,
                                                                                              17))
    stream = io.StringIO()
    smap.write_csv(stream, rows_per_block=50)
    assert stream.getvalue() == reference_csv(smap)


def test_warm_started_map_roots_equal_cold_ones_and_do_not_depend_on_threads():
    """A map starts each set's root iteration from its x-neighbour's roots: the same
    largest real parts to rounding and the same flags as starting afresh, and the same bits
    whatever the number of threads (each thread's block starts a row)."""
    from posturelab.linear import _batch_kernels as kernels
    from posturelab.linear.batch import _analyse
    from posturelab.linear.system import linear_system

    grid = parameter_grid(("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000),
                          (150, 60))
    stiffness, ratio = grid.rows()
    system = linear_system(paper_body(), paper_muscles("1"), stiffness=stiffness,
                           viscosity_ratio=ratio, inputs=False)
    cold = _analyse(system, keep_poles=True)
    warm = _analyse(system, keep_poles=True, chain=150)
    np.testing.assert_array_equal(warm.stable, cold.stable)
    np.testing.assert_allclose(warm.max_real_part, cold.max_real_part, rtol=1e-9, atol=1e-12)
    assert pole_error(warm.poles, cold.poles) < POLE_RTOL
    one = kernels.run(kernels.MODE_POLES, system.without_delay(), system.n_sets, chain=150,
                      threads=1)
    two = kernels.run(kernels.MODE_POLES, system.without_delay(), system.n_sets, chain=150,
                      threads=2)
    np.testing.assert_array_equal(one["max_real"], two["max_real"])
