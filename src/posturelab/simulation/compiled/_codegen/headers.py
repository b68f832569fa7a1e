"""Writes ``csrc/pl_model.h``: the interface of the generated model — the structs a run, its
outputs and a batch are packed into (their fields stated once in :data:`RUN_FIELDS`,
:data:`OUT_FIELDS` and :data:`BATCH_FIELDS`, which ``_layout.py`` also carries for the
ctypes mirror in ``_binding.py``), what the right-hand side and the event values need
(``pl_model``, ``pl_ctx``: :data:`MODEL_FIELDS`, :data:`CTX_FIELDS`), the angle-sum rotation
whose series sympy derives, and the generated functions' prototypes, taken from their
definitions.
"""

from __future__ import annotations

#: C type of each field code: i64/f64 scalars, *… read-only arrays, w… arrays written to.
C_TYPES = {"i64": "int64_t ", "f64": "double ", "*f64": "const double *",
           "*i64": "const int64_t *", "w*f64": "double *", "w*u8": "uint8_t *",
           "run": "pl_run ", "*model": "const pl_model *", "*hist": "const struct pl_history *"}

#: ``pl_run``: one run, everything the integration needs (read only): (field, type, comment).
RUN_FIELDS = [
    ("n", "i64", ""), ("p", "i64", ""), ("n_grid", "i64", ""), ("n_bps", "i64", ""),
    ("n_slots", "i64", ""), ("n_stages", "i64", ""), ("method", "i64", ""),
    ("x0", "*f64", "(2n)"), ("before", "*f64", "(2n)"), ("grid", "*f64", "(n_grid)"),
    ("bp", "*f64", "a (n), J_ii (n), c_ij (n*n), g, total mass"),
    ("E", "*f64", "(p, n) stretch rows"), ("C", "*f64", "(p, n) joint-crossing rows"),
    ("one_sided", "*i64", "(p)"),
    ("gains", "*f64", "(4, p) rows GAIN_*: immediate k, l, delayed k, l"),
    ("lim", "*f64", "(2n) torque limits >= 0: the negative side's (n), the positive "
            "side's (n), inf for none [N·m]"),
    ("delay", "f64", "feedback delay [s]"),
    ("dp", "*f64", "packed disturbance"), ("bps", "*f64", "breakpoints in (0, duration)"),
    ("fpar", "*f64", "F_*"), ("ipar", "*i64", "I_*"),
    ("active0", "*f64", "(p) at the start"), ("sat0", "*f64", "(n) at the start"),
    ("slot_kind", "*i64", "(n_slots) event slots, in order"), ("slot_index", "*i64", ""),
    ("slot_cond", "*i64", ""), ("slot_side", "*f64", ""),
    ("ev_offset", "*f64", "by kind: the event function's constant part"),
    ("ev_direction", "*i64", ""), ("ev_ends", "*i64", ""),
    ("tab_A", "*f64", "explicit tableau (n_stages ...)"), ("tab_c", "*f64", ""),
    ("tab_e", "*f64", ""), ("tab_P", "*f64", ""), ("tab_error_order", "i64", ""),
    ("delay_multiples", "i64", "land on k·delay for k = 1 … this"),
    ("tp", "*f64", "packed tilt (tp[0] = 0: none)"),
    ("tilt_gain", "*f64", "(4, n) joint moments per α(t), α̇(t), α(t−τ), α̇(t−τ)"),
    ("tilt_depth", "f64", "tilt axis below the ankle [m] (0: the ankle's)"),
    ("mp", "*f64", "packed motor noise (model.noise.TorqueSeries): mp[0] = K intervals "
            "(0: none), K + 1 knots, K·4·n coefficients (interval-major, ascending powers of "
            "t − knot, joint fastest)"),
    ("n_filters", "i64", "torque feedback filter states after [Θ, Θ̇]: p, or 0"),
    ("filter_gain", "f64", "K_t of the torque feedback [-]"),
    ("filter_time", "f64", "τ_t of its filter [s]"),
    ("tilt_pair_gain", "*f64", "(4, p) pair torques per α(t), α̇(t), α(t−τ), α̇(t−τ)"),
    ("joint_gain", "*f64", "(4, n, n) joint-space controller's moment gains, rows GAIN_*"),
    ("vp", "*f64", "packed visual-scene tilt (vp[0] = 0: none)"),
    ("visual_gain", "*f64", "(4, n) joint moments per v(t), v̇(t), v(t−τ), v̇(t−τ)"),
    ("visual_pair_gain", "*f64", "(4, p) pair torques per v(t), v̇(t), v(t−τ), v̇(t−τ)"),
]
#: ``pl_out``: where one run's outputs go (any pointer may be NULL where noted).
OUT_FIELDS = [
    ("samples", "w*f64", "(2n + n_filters, n_grid + 1) or NULL"),
    ("fb", "w*f64", "(2n, n_grid + 1) states the muscles responded to, or NULL"),
    ("locked", "w*u8", "(n_grid + 1) or NULL"),
    ("switches", "w*f64", "(switch_cap) or NULL"), ("switch_cap", "i64", ""),
    ("peak", "w*f64", "(n)"), ("final", "w*f64", "(2n)"), ("res", "w*f64", "(N_RESULT)"),
]
#: ``pl_batch``: the fields of ``pl_run`` that differ between a batch's runs, (field, "level"
#: or "run", numbers per row): an array of rows, one per level (a run's is ``which[r]``) or per
#: run, called ``{field}_all``; the rest of a run is ``base``.
BATCH_ROWS = [
    ("x0", "level", "2 * n"), ("before", "level", "2 * n"), ("dp", "level", "b->dp_stride"),
    ("ipar", "level", "N_IPAR"), ("active0", "level", "p"), ("gains", "run", "4 * p"),
    ("lim", "run", "2 * n"), ("delay", "run", "1"), ("sat0", "run", "n"), ("method", "run", "1"),
    ("tilt_gain", "run", "4 * n"), ("tilt_pair_gain", "run", "4 * p"),
    ("visual_gain", "run", "4 * n"), ("visual_pair_gain", "run", "4 * p"),
]
#: The outputs a batch keeps, per run: (field of ``pl_out``, array of ``pl_batch``, per row).
BATCH_OUTS = [("peak", "peaks", "n"), ("final", "finals", "2 * n"), ("res", "results", "N_RESULT")]


def _batch_fields() -> list[tuple[str, str, str]]:
    kinds = {field: kind for field, kind, _ in RUN_FIELDS}
    rows = [(f"{field}_all", "*" + kinds[field].lstrip("*"),
             f"({per}s)" if size == "1" else f"({per}s, {size.removeprefix('b->')})")
            for field, per, size in BATCH_ROWS]
    return ([("base", "run", "what the runs share"),
             ("which", "*i64", "(runs) the level of each run"),
             ("dp_stride", "i64", "numbers per level of dp_all")] + rows
            + [(name, "w*f64", f"(runs, {size})") for _, name, size in BATCH_OUTS])


#: ``pl_batch``: a batch's shared run, its per-level and per-run rows, its outputs.
BATCH_FIELDS = _batch_fields()
#: ``pl_model``: what the right-hand side needs besides the state.
MODEL_FIELDS = [
    ("n", "i64", ""), ("bp", "*f64", ""),
    ("tm", "w*f64", "(4, n, n): T_K, T_L, delayed T_K, delayed T_L"),
    ("lim", "*f64", "(2n): negative, positive limits"), ("sat", "w*f64", "(n) saturation signs"),
    ("base", "w*f64", "(3n) θ, sin θ, cos θ at the step's start"),
    ("work", "w*f64", "(n, n + 4)"), ("tau", "w*f64", "(n) receives the joint moments"),
    ("nf", "i64", "torque feedback filter states after [Θ, Θ̇] (0: none)"),
    ("tf_gain", "f64", "K_t [-]"), ("tf_time", "f64", "τ_t [s]"),
    ("C", "*f64", "(p, n) joint-crossing rows"), ("active", "*f64", "(p) which pairs act"),
    ("fscr", "w*f64", "(2 + n + nf) the inputs with the filters' moments, their rates"),
]
#: ``pl_ctx``: what the inputs and an event function need besides (t, y).
CTX_FIELDS = [
    ("md", "*model", ""), ("E", "*f64", ""), ("dp", "*f64", ""), ("fpar", "*f64", ""),
    ("before", "*f64", ""), ("ev_offset", "*f64", ""), ("hist", "*hist", ""),
    ("delay", "f64", ""), ("tp", "*f64", "packed tilt"),
    ("tilt_gain", "*f64", "(4, n) joint gains on the tilt"),
    ("tilt_depth", "f64", "tilt axis below the ankle [m]"),
    ("mp", "*f64", "packed motor noise"), ("gains", "*f64", "(4, p) the run's pair gains"),
    ("p", "i64", ""), ("sc_out", "w*f64", "scratch (m)"), ("sc_inp", "w*f64", "(2 + n + nf)"),
    ("sc_x", "w*f64", "(m)"), ("ys", "w*f64", "(m)"),
    ("tilt_pair_gain", "*f64", "(4, p) pair gains on the tilt"),
    ("vp", "*f64", "packed visual-scene tilt"),
    ("visual_gain", "*f64", "(4, n) joint gains on it"),
    ("visual_pair_gain", "*f64", "(4, p) pair gains on it"),
]


def batch_row() -> str:
    """``pl_batch_row``: run r of a batch, from :data:`BATCH_ROWS` and :data:`BATCH_OUTS`."""
    lines = ["", "/* Run r of a batch and where its outputs go (headers.BATCH_ROWS, BATCH_OUTS) */",
             "void pl_batch_row(const pl_batch *b, int64_t r, pl_run *run, pl_out *out)", "{",
             "    const int64_t n = b->base.n, p = b->base.p, level = b->which[r];",
             "    *run = b->base;"]
    for field, per, size in BATCH_ROWS:
        row = "level" if per == "level" else "r"
        lines.append(f"    run->{field} = b->{field}_all[{row}];" if size == "1" else
                     f"    run->{field} = b->{field}_all + {row} * ({size});")
    outs = [f".{field} = b->{name} + r * ({size})" for field, name, size in BATCH_OUTS]
    return "\n".join(lines + ["    *out = (pl_out){" + ",\n                     ".join(outs)
                               + "};", "}", ""])


def _struct(name: str, fields) -> list[str]:
    out = ["typedef struct {"]
    for field, kind, comment in fields:
        line = f"    {C_TYPES[kind]}{field};"
        out.append(f"{line:<40}/* {comment} */" if comment else line)
    return out + [f"}} {name};", ""]


def _rotation() -> str:
    """pl_rotate, with the series of sin δ and cos δ − 1 from sympy in Horner form in z = δ²."""
    import sympy as sp

    from .spec import c

    d, z = sp.symbols("d z")
    sin_poly = sp.Poly(sp.series(sp.sin(d), d, 0, 11).removeO(), d)
    cos_poly = sp.Poly(sp.series(sp.cos(d) - 1, d, 0, 10).removeO(), d)

    def horner(coefficients):  # Σ c_k z^k, k >= 1, as z·(c_1 + z·(c_2 + …))
        expr = sp.S.Zero
        for coefficient in reversed(coefficients):
            expr = sp.Mul(sp.Add(sp.Rational(coefficient), expr, evaluate=False), z,
                          evaluate=False) if expr != 0 else sp.Mul(sp.Rational(coefficient), z,
                                                                    evaluate=False)
        return expr

    sin_terms = [sin_poly.coeff_monomial(d ** (2 * k + 1)) for k in range(1, 5)]
    cos_terms = [cos_poly.coeff_monomial(d ** (2 * k)) for k in range(1, 5)]
    return f"""\
/* sin θ and cos θ from those of a nearby θ_b by the angle-sum formulas: within a step the
 * angles move by hundredths of a radian, and the series of sin δ (to δ⁹) and cos δ − 1 (to δ⁸)
 * are exact to rounding for |δ| <= 0.1 and much shorter than libm's sin and cos; farther
 * away, libm. pl_set_base stores (θ_b, sin θ_b, cos θ_b) at each step's start. */
static inline void pl_rotate(double theta, double theta_b, double s_b, double c_b, double *s,
                             double *c)
{{
    const double d = theta - theta_b;
    if (d > 0.1 || d < -0.1) {{
        *s = sin(theta);
        *c = cos(theta);
        return;
    }}
    const double z = d * d;
    const double sd = d + d * ({c(horner(sin_terms))});
    const double cdm1 = {c(horner(cos_terms))};
    *s = s_b + (s_b * cdm1 + c_b * sd);
    *c = c_b + (c_b * cdm1 - s_b * sd);
}}
"""


def header(*sources: str) -> str:
    """The text of ``csrc/pl_model.h``, declaring the functions the generated C ``sources``
    (the texts of pl_model.c and pl_rhs_small.c) define."""
    out = ["/* The interface of the generated model: GENERATED, do not edit.",
           " *",
           " * python -m posturelab.simulation.compiled._codegen writes this file from",
           " * _codegen/headers.py (the structs' fields, which _layout.py carries for",
           " * _binding.py), sympy (the rotation's series) and the definitions in pl_model.c",
           " * and pl_rhs_small.c (the prototypes); pl.h includes it. */",
           "#ifndef PL_MODEL_H", "#define PL_MODEL_H", "",
           "/* One run: everything the integration needs (read only). */"]
    out += _struct("pl_run", RUN_FIELDS)
    out.append("/* Outputs of one run (any pointer may be NULL where noted). */")
    out += _struct("pl_out", OUT_FIELDS)
    out.append("/* A batch: its runs share base but for the rows below (pl_batch_row). */")
    out += _struct("pl_batch", BATCH_FIELDS)
    out.append("/* What the right-hand side needs besides the state. */")
    out += _struct("pl_model", MODEL_FIELDS)
    out += ["struct pl_history;", "", "/* What the inputs and an event function need besides "
            "(t, y). */"]
    out += _struct("pl_ctx", CTX_FIELDS)
    out.append(_rotation())
    out += _prototypes(*sources) + [""]
    out.append("#endif")
    return "\n".join(out) + "\n"


def _prototypes(*sources: str) -> list[str]:
    """The declaration of each function that the C ``sources`` define for the rest of the
    engine: the signature of its definition there (from the column-0 line that starts it to
    the line before its ``{``)."""
    out = ["/* the functions of pl_model.c and pl_rhs_small.c (what each does: there) */"]
    for text in sources:
        signature: list[str] = []
        for line in text.splitlines():
            if line == "{" and signature:
                out += signature[:-1] + [signature[-1] + ";"]
                signature = []
            elif line[:1].isalpha() and "(" in line and not line.startswith("static"):
                signature = [line]
            elif signature:
                signature.append(line)
    return out

