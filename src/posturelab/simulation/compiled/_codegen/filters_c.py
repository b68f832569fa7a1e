"""The torque feedback of the compiled engine (Peterka 2002; docs/design.md, "Torque
feedback"), generated into ``csrc/pl_model.c`` by :mod:`.model_c`.

With torque feedback the state is [Θ, Θ̇, Y] of size m = 2N + P: one filter state Y_p [N·m]
per pair, Ẏ_p = (K_t A_p − Y_p)/τ_t with A_p = P_p + a_p Y_p
(:func:`posturelab.model.switched.torque_feedback_rate`), P_p the pair's delayed torque
(:func:`~posturelab.model.switched.delayed_pair_torques`: its delayed gains on x(t − τ), times
its activity a_p, plus the tilt's delayed part) and a_p Y_p added to the pair's torque before
the joint moments and their saturation (:func:`~posturelab.model.switched.raw_moments`).

* ``pl_inputs_at`` appends P_p to the inputs (``inp[2 + n + q]``): it depends on the past only.
* ``pl_rhs`` adds the filters' joint moments to the inputs' moments, calls the N-link
  right-hand side and appends the filters' rates.
* The event value of a joint's moment adds them too.

A switch leaves Y as it is and the filters start at rest (Y = 0) as in the reference engine;
the hand-written C carries the m components (pl_driver.c, pl_radau.c, pl_explicit.c).
"""

from __future__ import annotations

from ....model import switched
from ....model.gains import DELAYED_STIFFNESS, DELAYED_VISCOSITY, GAIN_ROWS
from .rhs_small import SIZES
from .spec import c, symbols

_DK, _DV = (f"GAIN_{GAIN_ROWS[k].upper()}" for k in (DELAYED_STIFFNESS, DELAYED_VISCOSITY))


def inputs_pairs() -> str:
    """C inside ``pl_inputs_at``'s delayed branch (``cx->sc_x`` = x(t − τ)): each filter's
    input, its pair's delayed torque a_q (k_q E_q Θ(t − τ) + l_q E_q Θ̇(t − τ))."""
    k, v, st, sd, act = symbols(f"cx->gains[{_DK} * cx->p + q]", f"cx->gains[{_DV} * cx->p + q]",
                                "st", "sd", "cx->md->active[q]")
    torque = act * switched.pair_torque_formula(k, v, st, sd)
    return f"""        for (int64_t q = 0; q < cx->md->nf; q++) {{  /* the filters' inputs */
            double st = 0.0, sd = 0.0;
            for (int64_t k = 0; k < n; k++) {{
                st += cx->E[q * n + k] * cx->sc_x[k];
                sd += cx->E[q * n + k] * cx->sc_x[n + k];
            }}
            out[2 + n + q] = {c(torque)};
        }}
"""


def inputs_tilt(gains: str = "tilt_pair_gain", angle: str = "a_d", rate: str = "ad_d") -> str:
    """C inside ``pl_inputs_at``'s branch of one tilt stimulus (the surface's, or the visual
    scene's with ``gains="visual_pair_gain"``): its delayed part of each filter's input
    (:func:`~posturelab.model.switched.tilt_pair_torque_formula` without the parts that act
    at once), ``angle`` and ``rate`` the C names of the stimulus at t − τ."""
    g = symbols(f"cx->{gains}[{_DK} * cx->p + q]", f"cx->{gains}[{_DV} * cx->p + q]")
    part = switched.tilt_pair_torque_formula(0, 0, *g, 0, 0, *symbols(angle, rate))
    return f"""        for (int64_t q = 0; q < cx->md->nf; q++)
            out[2 + n + q] += {c(part)};
"""


def _filter_moment(state: str) -> str:
    """a_q Y_q, pair q's filter's part of its torque (``state`` the C array of the state)."""
    return c(symbols("md->active[q]") * symbols(f"{state}[2 * n + q]"))


def rhs() -> str:
    """``pl_rhs``: the filters around the N-link right-hand side."""
    y, inp, act, gain, lag = symbols("x[2 * n + q]", "inp[2 + n + q]", "md->active[q]",
                                     "md->tf_gain", "md->tf_time")
    rate = switched.torque_feedback_rate_formula(y, inp + act * y, gain, lag)
    small = "\n".join(f"    case {n}: pl_rhs{n}(md, x, out, inp, locked); break;"
                      for n in reversed(SIZES))  # the straight-line code of rhs_small
    return f"""
/* [Θ̇, Θ̈, Ẏ] at x = [Θ, Θ̇, Y]: the N-link right-hand side, with the torque feedback filters'
 * moments added to the inputs' and their rates after it (model.switched.raw_moments,
 * torque_feedback_rate) */
void pl_rhs(const pl_model *md, const double *x, double *out, const double *inp, int locked)
{{
    const int64_t n = md->n, nf = md->nf;
    double *fs = md->fscr;
    if (nf > 0) {{
        for (int64_t k = 0; k < 2 + n; k++)
            fs[k] = inp[k];
        for (int64_t q = 0; q < nf; q++) {{
            for (int64_t j = 0; j < n; j++)
                fs[2 + j] += md->C[q * n + j] * ({_filter_moment("x")});
            fs[2 + n + q] = {c(rate)};
        }}
        inp = fs;
    }}
    switch (n) {{
{small}
    default: pl_rhs_general(md, x, out, inp, locked);
    }}
    for (int64_t q = 0; q < nf; q++)
        out[2 * n + q] = fs[2 + n + q];
}}
"""


def moment_step() -> str:
    """C of the event value of joint ``idx``'s moment: the filters' part."""
    return f"""
        for (int64_t q = 0; q < md->nf; q++)
            tau += md->C[q * n + idx] * ({_filter_moment("y")});"""
