"""Writes ``csrc/pl_model.c``: the switched model in C for any N — the inputs (platform
acceleration, tilt, axis translation, delayed moments, motor noise), the right-hand side
(``pl_rhs_general``, the knee impact ``pl_project_velocity``, the dispatch to the small-N code),
each event's value (``pl_event_value``), what a switch does (``pl_apply_switch``,
``pl_switch_needs_feedback``) and which slots a segment lists, with which side
(``pl_slot_on``, ``pl_slot_side``).

The loops and the packing are written here; every formula is evaluated from its one statement
in :mod:`posturelab.model` on sympy symbols named as C expressions (:mod:`.spec`) and printed.
"""

from __future__ import annotations

import inspect

from ....model import dynamics, joint_feedback, kinematics, platform, switched, tilt
from ....model import events as ev
from ....model.gains import GAIN_ROWS
from . import filters_c
from .codes import DIST_TERM_FIELDS, TILT_TERM_FIELDS
from .headers import batch_row
from .spec import SYMPY, c, symbols, trig_symbols
from .switch_c import switch_effects

HEADER = """/* The switched model for any N links: GENERATED, do not edit.
 *
 * python -m posturelab.simulation.compiled._codegen writes this file from the formulas of
 * posturelab.model (dynamics, platform, tilt, switched), printed by sympy into the loops of
 * _codegen/model_c.py; a test regenerates it and compares. Layouts: pl.h, pl_codes.h.
 *
 *   J(Θ)Θ̈ + B(Θ,Θ̇)Θ̇ − (g + ÿ_d)G(Θ) + ẍ_d H(Θ) = U,   U_i = τ_{i+1} − τ_i,
 *
 * τ the net muscle moments at the joints: τ = T_K Θ + T_L Θ̇ + inp[2 + j] (T_K = Cᵀ
 * diag(k·active) E, pl_moment_gains), or its positive or negative limit (pl_model.lim)
 * while joint j saturates;
 * inp = (ẍ_d, ÿ_d, delayed, tilt and noise moments, then each torque feedback filter's
 * input), from pl_inputs_at; with torque feedback the state is [Θ, Θ̇, Y] (filters_c.py). */
#include <math.h>
#include "pl.h"
"""


# ---------------------------------------------------------------------------
# Inputs: platform, tilt, motor noise
# ---------------------------------------------------------------------------


def _row(kind: str, table: dict, first: int) -> dict:
    """A packed term's parameters as symbols r[first], r[first + 1], … by name."""
    return {name: symbols(f"r[{first + k}]") for k, name in enumerate(table[kind])}


def _platform() -> str:
    t = symbols("t")
    windowed = platform.windowed_sine_formula(t, **_row("windowed-sine", DIST_TERM_FIELDS, 2),
                                              xp=SYMPY)
    sine = platform.sine_formula(t, **_row("sine", DIST_TERM_FIELDS, 2), xp=SYMPY)
    return f"""
/* numpy.interp(t, xp, fp, left=0, right=0), xp = dp[first .. first+count), fp its col-th
 * block of count values after it */
static double interp0(double t, const double *dp, int64_t first, int64_t count, int64_t col)
{{
    const int64_t hi = first + count - 1;
    if (!(t >= dp[first] && t <= dp[hi]))
        return 0.0;
    const int64_t off = col * count;
    if (t == dp[hi])
        return dp[hi + off];
    const int64_t lo = pl_interval_of(dp, first, hi, t);
    const double slope = (dp[lo + 1 + off] - dp[lo + off]) / (dp[lo + 1] - dp[lo]);
    return slope * (t - dp[lo]) + dp[lo + off];
}}

/* the platform acceleration: the sum of the disturbance's terms (model.platform.Primitive) */
void pl_platform_acceleration(double t, const double *dp, double *ax, double *ay)
{{
    double sx = 0.0, sy = 0.0;
    const int64_t nq = (int64_t)dp[0];
    for (int64_t q = 0; q < nq; q++) {{
        const double *r = dp + 1 + DIST_ROW * q;
        const int kind = (int)r[0];
        double v = 0.0;
        if (kind == DIST_WINDOWED_SINE) {{
            v = {c(windowed)};
        }} else if (kind == DIST_SINE) {{
            v = {c(sine)};
        }} else if (kind == DIST_SAMPLES) {{
            const int64_t first = (int64_t)r[2], count = (int64_t)r[3];
            sx += interp0(t, dp, first, count, 1);
            sy += interp0(t, dp, first, count, 2);
            continue;
        }}
        if (r[1] == 0.0)
            sx += v;
        else
            sy += v;
    }}
    *ax = sx;
    *ay = sy;
}}
"""


def _tilt() -> str:
    t = symbols("t")
    sine = tilt.sine_tilt_formula(t, **_row("sine", TILT_TERM_FIELDS, 1), xp=SYMPY)
    ramp = tilt.raised_cosine_tilt_formula(t, **_row("raised-cosine", TILT_TERM_FIELDS, 1),
                                           xp=SYMPY)
    q0, q1, q2, q3, u = symbols("q[0]", "q[1]", "q[2]", "q[3]", "u")
    cubic = tilt.cubic_formula(q0, q1, q2, q3, u)
    qj = symbols("q[j]", "q[n + j]", "q[2 * n + j]", "q[3 * n + j]")
    noise = tilt.cubic_formula(*qj, u)[0]

    def add(parts):
        return "\n".join(f"            {v} += {c(e)};" for v, e in zip(("a", "ad", "add"), parts,
                                                                         strict=True))

    return f"""
/* α, α̇, α̈ of one piecewise cubic: knots x[0..K], coefficients c[4k .. 4k+3] */
static void ppoly(double t, const double *x, const double *c, int64_t K, double period,
                  double *angle, double *rate, double *accel)
{{
    if (period > 0.0 && t >= x[0])
        t = x[0] + fmod(t - x[0], period);
    const int inside = t >= x[0] && t <= x[K];
    if (t < x[0])
        t = x[0];
    if (t > x[K])
        t = x[K];
    const int64_t lo = pl_interval_of(x, 0, K, t);
    const double u = t - x[lo], *q = c + 4 * lo;
    *angle = {c(cubic[0])};
    *rate = inside ? {c(cubic[1])} : 0.0;
    *accel = inside ? {c(cubic[2])} : 0.0;
}}

/* the tilt: the sum of its terms (model.tilt.TiltTerm) */
void pl_tilt(double t, const double *tp, double *angle, double *rate, double *accel)
{{
    double a = 0.0, ad = 0.0, add = 0.0;
    const int64_t nq = (int64_t)tp[0];
    for (int64_t q = 0; q < nq; q++) {{
        const double *r = tp + 1 + TILT_ROW * q;
        const int kind = (int)r[0];
        if (kind == TILT_SINE) {{
{add(sine)}
        }} else if (kind == TILT_RAISED_COSINE) {{
{add(ramp)}
        }} else if (kind == TILT_PPOLY) {{
            const int64_t off = (int64_t)r[1], K = (int64_t)r[2];
            double pa, pr, pq;
            ppoly(t, tp + off, tp + off + K + 1, K, r[3], &pa, &pr, &pq);
            a += pa;
            ad += pr;
            add += pq;
        }}
    }}
    *angle = a;
    *rate = ad;
    *accel = add;
}}

/* tau[j] += the motor noise at joint j (model.noise.torque_at: the interval whose knot is the
 * last at or before t, the end intervals carried on outside the knots) */
void pl_motor_noise_add(double t, const double *mp, int64_t n, double *tau)
{{
    const int64_t K = (int64_t)mp[0];
    const double *x = mp + 1, *c = mp + 2 + K;
    const int64_t lo = pl_interval_of(x, 0, K, t);  /* in [0, K - 1] */
    const double u = t - x[lo], *q = c + lo * 4 * n;
    for (int64_t j = 0; j < n; j++)
        tau[j] += {c(noise)};
}}
"""


def _inputs() -> str:
    h, a, ad, add = symbols("cx->tilt_depth", "a", "ad", "add")
    axis_x, axis_y = tilt.axis_acceleration_formula(h, a, ad, add, SYMPY)
    g = symbols(*(f"g[GAIN_{row.upper()} * n + j]" for row in GAIN_ROWS))
    tilt_moment = switched.tilt_pair_torque_formula(*g, a, ad, *symbols("a_d", "ad_d"))
    visual_moment = switched.tilt_pair_torque_formula(*g, *symbols("v", "vd", "v_d", "vd_d"))
    return f"""
/* The inputs at t: inp = (ẍ_d, ÿ_d, the moments that do not depend on the state now: the
 * delayed part of the feedback on x(t − τ), the tilt's part, the visual scene's part, the
 * motor noise). */
void pl_inputs_at(const pl_ctx *cx, double t, double *out)
{{
    const int64_t n = cx->md->n;
    const double *tm = cx->md->tm;
    double ax = 0.0, ay = 0.0;
    if (cx->dp[0] > 0.0)
        pl_platform_acceleration(t, cx->dp, &ax, &ay);
    double a = 0.0, ad = 0.0, add = 0.0;
    if (cx->tp[0] > 0.0)
        pl_tilt(t, cx->tp, &a, &ad, &add);
    if (cx->tilt_depth > 0.0) {{  /* the ankle moves on a circle about the tilt axis */
        ax += {c(axis_x)};
        ay += {c(axis_y)};
    }}
    out[0] = ax;
    out[1] = ay;
    if (cx->delay > 0.0) {{
        pl_history_at(cx->hist, cx->before, t - cx->delay, cx->sc_x);
        for (int64_t j = 0; j < n; j++) {{
            double s = 0.0;
            for (int64_t k = 0; k < n; k++)
                s += tm[2 * n * n + j * n + k] * cx->sc_x[k]
                     + tm[3 * n * n + j * n + k] * cx->sc_x[n + k];
            out[2 + j] = s;
        }}
{filters_c.inputs_pairs()}    }} else {{
        for (int64_t j = 0; j < n; j++)
            out[2 + j] = 0.0;
    }}
    if (cx->tp[0] > 0.0) {{  /* the tilt's moments: now, and as the delayed part felt it */
        const double *g = cx->tilt_gain;
        double a_d = 0.0, ad_d = 0.0, add_d = 0.0;
        if (cx->delay > 0.0)
            pl_tilt(t - cx->delay, cx->tp, &a_d, &ad_d, &add_d);
        for (int64_t j = 0; j < n; j++)
            out[2 + j] += {c(tilt_moment)};
{filters_c.inputs_tilt()}    }}
    if (cx->vp[0] > 0.0) {{  /* the visual scene's moments: through the active part only */
        const double *g = cx->visual_gain;
        double v = 0.0, vd = 0.0, vdd = 0.0, v_d = 0.0, vd_d = 0.0, vdd_d = 0.0;
        pl_tilt(t, cx->vp, &v, &vd, &vdd);
        if (cx->delay > 0.0)
            pl_tilt(t - cx->delay, cx->vp, &v_d, &vd_d, &vdd_d);
        for (int64_t j = 0; j < n; j++)
            out[2 + j] += {c(visual_moment)};
{filters_c.inputs_tilt("visual_pair_gain", "v_d", "vd_d")}    }}
    if (cx->mp[0] > 0.0)  /* the motor noise, on the motor command */
        pl_motor_noise_add(t, cx->mp, n, out + 2);
}}
"""


# ---------------------------------------------------------------------------
# The right-hand side for any N
# ---------------------------------------------------------------------------


def _rhs() -> str:
    thi, thj, wj = symbols("thi", "thj", "x[n + j]")
    trig = {thi: ("si", "ci"), thj: ("sj", "cj")}
    cij, a_i = symbols("cij", "bp[i]")
    coupling = trig_symbols(dynamics.coupling_formula(cij, thi, thj, SYMPY), trig)
    centripetal = trig_symbols(dynamics.centripetal_formula(cij, thi, thj, wj, SYMPY), trig)
    load = trig_symbols(dynamics.load_formula(a_i, thi, *symbols("ga", "ax"), SYMPY), trig)
    saturated = switched.saturated_moment_formula(
        *symbols("t", "md->sat[j]", "md->lim[j]", "md->lim[n + j]"), SYMPY)
    xi, xj = symbols("x[i]", "x[j]")
    impact = dynamics.coupling_formula(symbols("bp[2 * n + i * n + j]"), xi, xj, SYMPY)
    joint = joint_feedback.joint_moment_gain_formula(*symbols("tm[k]", "jg[k]"))
    return f"""
void pl_set_base(const double *x, double *base, int64_t n)
{{
    for (int64_t i = 0; i < n; i++) {{
        base[i] = x[i];
        base[n + i] = sin(x[i]);
        base[2 * n + i] = cos(x[i]);
    }}
}}

void pl_rhs_general(const pl_model *md, const double *x, double *out, const double *inp,
                    int locked)
{{
    const int64_t n = md->n, oc = 2 * n, w = n + 4;
    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + n * n;
    double *work = md->work, *tau = md->tau;
    const double ax = inp[0], ga = bp[oc + n * n] + inp[1];
    for (int64_t i = 0; i < n; i++)
        pl_rotate(x[i], md->base[i], md->base[n + i], md->base[2 * n + i],
                  &work[i * w + n + 2], &work[i * w + n + 3]);
    for (int64_t j = 0; j < n; j++) {{
        double t = inp[2 + j];
        for (int64_t k = 0; k < n; k++)
            t += tk[j * n + k] * x[k] + tl[j * n + k] * x[n + k];
        tau[j] = {c(saturated)};
    }}
    for (int64_t i = 0; i < n; i++) {{
        const double si = work[i * w + n + 2], ci = work[i * w + n + 3];
        double r = (i + 1 < n ? tau[i + 1] : 0.0) - tau[i] + {c(load)};
        for (int64_t j = 0; j < n; j++) {{
            if (j == i) {{
                work[i * w + j] = bp[n + i];
                continue;
            }}
            const double sj = work[j * w + n + 2], cj = work[j * w + n + 3];
            const double cij = bp[oc + i * n + j];
            r -= {c(centripetal)};
            work[i * w + j] = {c(coupling)};
        }}
        work[i * w + n] = r;
        work[i * w + n + 1] = 0.0;
    }}
    int64_t ncol = 1;
    if (locked) {{
        work[n + 1] = -1.0;
        work[w + n + 1] = 1.0;
        ncol = 2;
    }}
    pl_solve_into(work, n, ncol, w);
    if (locked) {{
        const double lam = (work[w + n] - work[n]) / (work[w + n + 1] - work[n + 1]);
        for (int64_t i = 0; i < n; i++)
            work[i * w + n] -= work[i * w + n + 1] * lam;
    }}
    for (int64_t i = 0; i < n; i++) {{
        out[i] = x[n + i];
        out[n + i] = work[i * w + n];
    }}
}}
{filters_c.rhs()}
/* A segment's moment gains tm (GAIN_ROWS, n, n): T_K, T_L and their delayed parts,
 * T = Cᵀ diag(g·active) E for each row g of the pair gains (GAIN_ROWS, p), plus the
 * joint-space controller's rows jg (model.joint_feedback; NULL: none). */
void pl_moment_gains(const double *E, const double *C, const double *gains, const double *jg,
                     const double *active, int64_t p, int64_t n, double *tm)
{{
    for (int64_t r = 0; r < {len(GAIN_ROWS)}; r++)
        for (int64_t j = 0; j < n; j++)
            for (int64_t k = 0; k < n; k++) {{
                double sum = 0.0;
                for (int64_t q = 0; q < p; q++)
                    sum += C[q * n + j] * E[q * n + k] * active[q] * gains[r * p + q];
                tm[(r * n + j) * n + k] = sum;
            }}
    for (int64_t k = 0; jg && k < {len(GAIN_ROWS)} * n * n; k++)
        tm[k] = {c(joint)};
}}

/* Plastic impact onto the knee constraint, in place on x's rates:
 * Θ̇ − J⁻¹C (C·Θ̇)/(C·J⁻¹C), C = (−1, 1, 0, …). work holds at least n·(n + 1). */
void pl_project_velocity(double *x, const double *bp, double *work, int64_t n)
{{
    const int64_t s = n + 1;
    for (int64_t i = 0; i < n; i++) {{
        for (int64_t j = 0; j < n; j++)
            work[i * s + j] = i == j ? bp[n + i] : {c(impact)};
        work[i * s + n] = 0.0;
    }}
    work[n] = -1.0;
    work[s + n] = 1.0;
    pl_solve_into(work, n, 1, s);
    const double lam = (x[n + 1] - x[n]) / (work[s + n] - work[n]);
    for (int64_t i = 0; i < n; i++)
        x[n + i] -= work[i * s + n] * lam;
}}
"""


# ---------------------------------------------------------------------------
# Event values
# ---------------------------------------------------------------------------

#: The C statements that compute what a quantity needs (in this order when several do); the
#: ones several kinds share are helpers (:func:`_helpers`), written once.
_STEPS = {
    "feedback": "pair_stretch(cx, idx, t, y, &st, &sd);",
    "pair_gains": "pair_gains(cx, idx, &pk, &pv);",
    "cog": "xc = cog_x(md, y);",
    "inputs": "pl_inputs_at(cx, t, cx->sc_inp);",
    "moment": """const double *tk = md->tm, *tl = md->tm + n * n;
        double tau = cx->sc_inp[2 + idx];
        for (int64_t k = 0; k < n; k++)
            tau += tk[idx * n + k] * y[k] + tl[idx * n + k] * y[n + k];"""
    + filters_c.moment_step(),
    "free": "pl_rhs(md, y, cx->sc_out, cx->sc_inp, 0);",
    "response": "pl_rhs(md, y, cx->sc_out, cx->sc_inp, locked);",
    "reaction": "fy = vertical_reaction(cx, y);",
}


def _helpers() -> str:
    """The steps several event kinds share, as static C functions."""
    cog = dynamics.load_formula(symbols("bp[i]"), symbols("y[i]"), 1, 0, SYMPY)
    reaction = kinematics.cog_acceleration_terms_formula(
        *symbols("bp[i]", "y[i]", "y[n + i]", "cx->sc_out[n + i]"), SYMPY)[1]
    return f"""
/* The stretch of pair idx (its row of E times the angles) and its rate, on the state the
 * feedback sees: x(t − τ) when it is delayed, y otherwise. */
static void pair_stretch(const pl_ctx *cx, int64_t idx, double t, const double *y,
                         double *stretch, double *stretch_rate)
{{
    const int64_t n = cx->md->n;
    const double *fb = y;
    if (cx->delay > 0.0) {{
        pl_history_at(cx->hist, cx->before, t - cx->delay, cx->sc_x);
        fb = cx->sc_x;
    }}
    double st = 0.0, sd = 0.0;
    for (int64_t j = 0; j < n; j++) {{
        st += cx->E[idx * n + j] * fb[j];
        sd += cx->E[idx * n + j] * fb[n + j];
    }}
    *stretch = st;
    *stretch_rate = sd;
}}

/* pair idx's stiffness and viscosity: its immediate and delayed gains together */
static void pair_gains(const pl_ctx *cx, int64_t idx, double *stiffness, double *viscosity)
{{
    const double *gn = cx->gains;
    const int64_t p = cx->p;
    *stiffness = gn[GAIN_IMMEDIATE_STIFFNESS * p + idx] + gn[GAIN_DELAYED_STIFFNESS * p + idx];
    *viscosity = gn[GAIN_IMMEDIATE_VISCOSITY * p + idx] + gn[GAIN_DELAYED_VISCOSITY * p + idx];
}}

/* the centre of gravity's x at the angles y [m] */
static double cog_x(const pl_model *md, const double *y)
{{
    const int64_t n = md->n;
    const double *bp = md->bp;
    double xc = 0.0;
    for (int64_t i = 0; i < n; i++)
        xc += {c(cog)};
    return xc / bp[2 * n + n * n + 1];
}}

/* the vertical ground reaction [N], once pl_rhs has left Θ̈ in cx->sc_out and the
 * platform's vertical acceleration is in cx->sc_inp */
static double vertical_reaction(const pl_ctx *cx, const double *y)
{{
    const int64_t n = cx->md->n;
    const double *bp = cx->md->bp;
    double fy = bp[2 * n + n * n + 1] * (bp[2 * n + n * n] + cx->sc_inp[1]);
    for (int64_t i = 0; i < n; i++)
        fy += {c(reaction)};
    return fy;
}}
"""


#: quantity -> (the steps it needs, its C expression)
_QUANTITIES = {
    "link_angle": ((), "y[idx]"),
    "max_link_angle": ((), "fpar[F_MAX_ANGLE]"),
    "toe": ((), "fpar[F_TOE]"),
    "heel": ((), "fpar[F_HEEL]"),
    "stop_angle": ((), "fpar[F_STOP_ANGLE]"),
    "side": ((), "side"),
    "negative_limit": ((), "md->lim[idx]"),
    "positive_limit": ((), "md->lim[n + idx]"),
    "cog_x": (("cog",), "xc"),
    "stretch": (("feedback",), "st"),
    "stretch_rate": (("feedback",), "sd"),
    "pair_stiffness": (("pair_gains",), "pk"),
    "pair_viscosity": (("pair_gains",), "pv"),
    "moment": (("inputs", "moment"), "tau"),
    "knee_angle": ((), "(y[1] - y[0])"),
    "free_knee_acceleration": (("inputs", "free"), "(cx->sc_out[n + 1] - cx->sc_out[n])"),
    "ankle_moment": (("inputs", "response", "reaction"), "md->tau[0]"),
    "vertical_reaction": (("inputs", "response", "reaction"), "fy"),
}
_ORDER = ("feedback", "pair_gains", "cog", "inputs", "moment", "free", "response", "reaction")


def _events() -> str:
    groups: dict = {}
    for kind in ev.EVENT_KINDS:
        groups.setdefault(switched.EVENT_VALUES[kind.code], []).append(kind)
    cases = []
    for formula, kinds in groups.items():
        names = [p for p in inspect.signature(formula).parameters if p != "xp"]
        needed = {s for name in names for s in _QUANTITIES[name][0]}
        args = [symbols(_QUANTITIES[name][1]) for name in names]
        lines = [f"    case EV_{k.name.upper().replace('-', '_')}:" for k in kinds]
        lines[-1] += " {"
        lines += [f"        {_STEPS[s]}" for s in _ORDER if s in needed]
        lines += [f"        g = {c(formula(*args, xp=SYMPY))};", "        break;", "    }"]
        cases.append("\n".join(lines))
    body = "\n".join(cases)
    return _helpers() + f"""
/* The value of an event function (model.switched.EVENT_VALUES, plus the kind's offset of
 * model.events) at (t, y) with the segment's switches. */
double pl_event_value(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t,
                      const double *y, int locked)
{{
    const pl_model *md = cx->md;
    const int64_t n = md->n;
    const double *fpar = cx->fpar;
    (void)locked;
    (void)side;
    double st = 0.0, sd = 0.0, pk = 0.0, pv = 0.0, xc = 0.0, fy = 0.0, g = 0.0;
    switch (kind) {{
{body}
    default:
        break;
    }}
    return g + cx->ev_offset[kind];
}}
"""


#: a comparison of model.events.SLOT_CONDITIONS in C
def generate() -> str:
    """The text of ``csrc/pl_model.c``."""
    return (HEADER + _platform() + _tilt() + _inputs() + _rhs() + _events()
            + switch_effects() + batch_row())
