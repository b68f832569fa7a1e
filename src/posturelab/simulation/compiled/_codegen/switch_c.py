"""The switch part of ``csrc/pl_model.c`` (written by :mod:`.model_c`): what each switch
does and which events a smooth segment lists, from ``model.switched.SWITCH_EFFECTS`` and its
functions and ``model.events.SLOT_CONDITIONS``, each rule printed from its one statement."""

from __future__ import annotations

import operator

import sympy as sp

from ....model import events as ev
from ....model import switched
from .spec import SYMPY, c, symbols

__all__ = ["switch_effects"]


_COMPARISONS = {operator.eq: "==", operator.ne: "!=", operator.gt: ">"}
#: the segment's switches in C (model.events.SLOT_CONDITIONS)
_SWITCHES = {"saturation": "sat[i]", "active": "active[i]", "locked": "locked"}


def _kind_case(code: int) -> str:
    return f"    case EV_{ev.EVENT_KINDS[code].name.upper().replace('-', '_')}:"


def switch_effects() -> str:
    """pl_slot_side, pl_switch_needs_feedback, pl_apply_switch and pl_slot_on, from
    model.switched.SWITCH_EFFECTS and its functions, and model.events.SIDE_IS_SATURATION and
    SLOT_CONDITIONS."""
    stretch_rate, side = symbols("sd", "side")
    x0, stop_angle = symbols("x[0]", "stop_angle")
    groups: dict = {}
    for kind, effect in switched.SWITCH_EFFECTS.items():
        if effect == "active":
            value = sp.sympify(switched.pair_activity_after(kind, stretch_rate, SYMPY.where))
            body = [f"active[j] = {c(value)};"]
            if stretch_rate in value.free_symbols:
                body = ["double sd = 0.0;", "for (int64_t k = 0; k < n; k++)",
                        "    sd += run->E[j * n + k] * feedback[n + k];"] + body
        elif effect == "saturation":
            body = [f"sat[j] = {c(switched.saturation_after(kind, side))};"]
        elif effect == "knee impact":
            body = [f"x[1] = {c(switched.knee_angle_at_stop(x0, stop_angle))};",
                    "pl_project_velocity(x, run->bp, work, n);", "*locked = 1;"]
        else:
            body = ["*locked = 0;"]
        groups.setdefault(tuple(body), []).append(kind)
    cases = []
    for body, kinds in groups.items():
        lines = [_kind_case(k) for k in kinds]
        lines[-1] += " {"
        lines += [f"        {line}" for line in body] + ["        break;", "    }"]
        cases.append("\n".join(lines))
    needs = [_kind_case(k) for k, effect in switched.SWITCH_EFFECTS.items()
             if effect == "active"]
    conds = []
    for code, (switch, compare, value, negated) in ev.SLOT_CONDITIONS.items():
        if switch is None:
            continue
        test = _SWITCHES[switch]
        if compare is not None:
            test = f"{test} {_COMPARISONS[compare]} {c(value)}"
        if negated:
            test = f"!({test})" if compare is not None else f"!{test}"
        conds.append(f"    case COND_{ev.CONDITION_NAMES[code]}: return {test};")
    from_saturation = [_kind_case(k) for k in sorted(ev.SIDE_IS_SATURATION)]
    return f"""
/* The side of an event slot of kind `kind` at joint or pair i in a segment that starts with
 * joint saturation `sat` (model.events.SIDE_IS_SATURATION: a joint lets go from the side it
 * is saturated at), else the slot's `side`. */
double pl_slot_side(int64_t kind, int64_t i, double side, const double *sat)
{{
    switch (kind) {{
{chr(10).join(from_saturation)}
        return sat[i];
    default:
        return side;
    }}
}}

/* Whether switch `kind` reads the state the muscles respond to (model.switched.SWITCH_EFFECTS:
 * a pair's activity follows its fed-back stretch rate). */
int pl_switch_needs_feedback(int64_t kind)
{{
    switch (kind) {{
{chr(10).join(needs)}
        return 1;
    default:
        return 0;
    }}
}}

/* What switch `kind` (index j, side `side`) does (model.switched.apply_switch): x, active,
 * sat and *locked updated in place, `feedback` the state the muscles respond to (x, or the
 * delayed state), `work` pl_project_velocity's scratch. */
void pl_apply_switch(const pl_run *run, int64_t kind, int64_t j, double side,
                     const double *feedback, double *x, double *active, double *sat,
                     int *locked, double *work)
{{
    const int64_t n = run->n;
    const double stop_angle = run->fpar[F_STOP_ANGLE];
    (void)side;
    (void)feedback;
    (void)stop_angle;
    switch (kind) {{
{chr(10).join(cases)}
    default:
        break;
    }}
}}

/* Whether an event slot with condition `cond` (at joint or pair i) is part of a segment that
 * starts with these switches (model.events.SLOT_CONDITIONS). */
int pl_slot_on(int64_t cond, int64_t i, const double *sat, const double *active, int locked)
{{
    switch (cond) {{
{chr(10).join(conds)}
    default: return 1;
    }}
}}
"""
