"""The codes and array layouts the C engine and its Python layer share, stated once: this table
writes both ``csrc/pl_codes.h`` (the C enums) and ``_layout.py`` (the same numbers for Python).
The event kinds and slot conditions come from :mod:`posturelab.model.events`, the gain rows
from :mod:`posturelab.model.gains`.
"""

from __future__ import annotations

Row = tuple[str, str | None, int, str]


def _counted(*rows: str | tuple[str, str], c_prefix: tuple[str, str] = ("", "")) -> list[Row]:
    """Codes numbered 0, 1, … in the order given; a row is a name or (name, comment). C spells
    a name the same, or with the prefix ``c_prefix[0]`` replaced by ``c_prefix[1]``."""
    out = []
    for value, row in enumerate(rows):
        name, comment = (row, "") if isinstance(row, str) else row
        out.append((name, name.replace(*c_prefix, 1) if c_prefix[0] else name, value, comment))
    return out


def _packed(prefix: str, row: int, *kinds: tuple[str, str]) -> list[Row]:
    """A packed list of terms: ``{prefix}_ROW``, the numbers per term, then the term kinds
    (name, its parameters) numbered from 1 as ``{prefix}_{name}``."""
    return [(f"{prefix}_ROW", f"{prefix}_ROW", row, "numbers per term")] + [
        (f"{prefix}_{name}", f"{prefix}_{name}", code, comment)
        for code, (name, comment) in enumerate(kinds, start=1)]


#: (heading, [(Python name, C name, value, comment)]) — the C name None when C has none.
GROUPS: list[tuple[str, list[Row]]] = [
    ("Outcome of a run (result vector, R_STATUS)", _counted(
        "STATUS_COMPLETED", "STATUS_FELL", "STATUS_STEP_TOO_SMALL", "STATUS_NONFINITE",
        "STATUS_CHATTERING", "STATUS_NO_MEMORY", "STATUS_STEP_BUDGET", "STATUS_TIME_BUDGET",
        c_prefix=("STATUS_", "PL_"))),
    ("Integration methods", _counted("METHOD_RADAU", "METHOD_EXPLICIT")),
    ("Knee models", _counted("KNEE_FREE", "KNEE_LOCKED", "KNEE_STOP")),
    ("Packed disturbance ``dp``: dp[0] = number of terms Q, then Q rows of DIST_ROW numbers "
     "(kind, axis, p0, p1, p2, p3), then the sampled profiles (times, x and y "
     "accelerations). The terms are posturelab.model.platform.Primitive.", _packed(
        "DIST", 6, ("WINDOWED_SINE", "(amplitude [m/s²], duration [s], start [s], cycles [-])"),
        ("SINE", "(amplitude [m/s²], frequency [Hz], phase [rad], 0)"),
        ("SAMPLES", "linear interpolation, zero outside: (index of its times in dp, S, 0, 0)"))),
    ("Packed tilt ``tp``: tp[0] = number of terms, then rows of TILT_ROW numbers (kind, p0 … "
     "p5), then the piecewise-cubic data: K + 1 knots, then K rows of 4 coefficients in "
     "ascending powers of t − knot (posturelab.model.tilt.TiltTerm).", _packed(
        "TILT", 7, ("SINE", "(amplitude [rad], frequency [Hz], phase [rad])"),
        ("RAISED_COSINE", "(amplitude [rad], start [s], duration [s])"),
        ("PPOLY", "(offset of the knots in tp, K intervals, period [s] or 0)"))),
    ("Options, floats ``fpar``", _counted(
        ("F_MAX_ANGLE", "[rad]"), ("F_HEEL", "[m]"), ("F_TOE", "[m]"),
        ("F_STOP_ANGLE", "[rad]"), ("F_RTOL", "[-]"), ("F_ATOL", "[rad, rad/s]"),
        ("F_MAX_STEP", "largest step resolving the profile, and at most the duration [s]"),
        ("F_DURATION", "[s]"), ("F_SETTLE_TOL", "[rad]"),
        ("F_TIME_LIMIT", "wall-clock budget of the run, inf for none [s]"), "N_FPAR")),
    ("Options, integers ``ipar``", _counted(
        "I_USE_BOS", "I_USE_COP", "I_KNEE_MODE", "I_MAX_SWITCHES", "I_LOCKED0",
        ("I_MAX_STEPS", "the step budget: accepted steps [-]"), "N_IPAR")),
    ("Result vector of one run", _counted(
        "R_STATUS", ("R_N_SAMPLES", "samples on the grid"),
        ("R_FALL_KIND", "event code of the fall (posturelab.model.events), −1 if none"),
        ("R_FALL_INDEX", "its link index"), ("R_FALL_TIME", "[s], NaN if none"),
        "R_N_SWITCHES", ("R_T_REACHED", "[s]"), "R_N_STEPS", "R_N_REJECTED", "R_N_EVALS",
        ("R_LAST_OUTSIDE", "last sample time with some |θ_i| > settle tolerance [s], NaN if none"),
        ("R_ANY_OUTSIDE", "0/1"), ("R_FINAL_OUTSIDE", "0/1: the last sample is outside"),
        ("R_FALL_SAMPLE", "0/1: the state at the fall closes the series, off the grid"),
        "N_RESULT")),
]

#: The parameters of each analytic disturbance term (model.platform.Primitive), packed in
#: this order after (kind, axis); the names are those of its formula's arguments.
DIST_TERM_FIELDS = {"windowed-sine": ("amplitude", "duration", "start", "cycles"),
                    "sine": ("amplitude", "frequency", "phase")}
#: The parameters of each analytic tilt term (model.tilt.TiltTerm), packed after its kind.
TILT_TERM_FIELDS = {"sine": ("amplitude", "frequency", "phase"),
                    "raised-cosine": ("amplitude", "start", "duration")}

#: SimulationResult.status, a failure's words and outcome_message's word, by status code.
STATUS_TEXT = [
    ("completed", "", "completed"),
    ("fell", "", "fell"),
    ("failed", "step size underflow", "step-too-small"),
    ("failed", "non-finite state", "non-finite"),
    ("failed", "chattering (too many switches)", "chattering"),
    ("failed", "out of memory", "no-memory"),
    ("failed", "step budget spent", "step-budget"),
    ("failed", "time limit reached", "time-budget"),
]


def _model_groups():
    """The groups stated in posturelab.model: event kinds, slot conditions, gain rows."""
    from ....model import events as ev
    from ....model import gains

    kinds = [(None, "EV_" + k.name.upper().replace("-", "_"), k.code, k.name)
             for k in ev.EVENT_KINDS]
    conditions = [(None, "COND_" + name, getattr(ev, name), "")
                  for name in ev.CONDITION_NAMES]
    rows = [(None, "GAIN_" + name.upper(), getattr(gains, name.upper()), "")
            for name in gains.GAIN_ROWS]
    return [("Event kinds (posturelab.model.events)", kinds),
            ("Conditions of a segment's event slots (posturelab.model.events)", conditions),
            ("Rows of a (4, P) gains array (posturelab.model.gains)", rows)]


def _wrap(text: str, prefix: str, width: int = 96) -> list[str]:
    import textwrap

    return textwrap.wrap(text, width=width, initial_indent=prefix, subsequent_indent=prefix)


def _tuple(name: str, values: list[str]) -> list[str]:
    """``name = (…)`` wrapped at 96 characters."""
    import json

    items = [json.dumps(v, ensure_ascii=False) for v in values]
    lines = [f"{name} = ({items[0]}"]
    for item in items[1:]:
        if len(lines[-1]) + len(item) + 3 > 96:
            lines[-1] += ","
            lines.append(" " * (len(name) + 4) + item)
        else:
            lines[-1] += ", " + item
    lines[-1] += ")"
    return lines


def header() -> str:
    """The text of ``csrc/pl_codes.h``."""
    out = ["/* Codes and array layouts shared with Python: GENERATED, do not edit.",
           " *",
           " * python -m posturelab.simulation.compiled._codegen writes this file from",
           " * _codegen/codes.py and posturelab.model (events, gains); _layout.py states the "
           "same", " * numbers for Python. */",
           "#ifndef PL_CODES_H", "#define PL_CODES_H", ""]
    for heading, rows in GROUPS + _model_groups():
        out.append("/* " + "\n * ".join(line.strip() for line in _wrap(heading, "")) + " */")
        items = [f"{cname} = {value}" for _, cname, value, _ in rows if cname]
        lines = ["enum { " + items[0]]
        for item in items[1:]:
            if len(lines[-1]) + len(item) + 2 > 96:
                lines[-1] += ","
                lines.append("       " + item)
            else:
                lines[-1] += ", " + item
        out += lines[:-1] + [lines[-1] + " };", ""]
    out.append("#endif")
    return "\n".join(out) + "\n"


def layout() -> str:
    """The text of ``_layout.py``."""
    out = ['"""Codes and array layouts shared with the C engine (``csrc/pl_codes.h`` states the',
           "same numbers): GENERATED, do not edit.", "",
           "``python -m posturelab.simulation.compiled._codegen`` writes this file from",
           '``_codegen/codes.py``; a test regenerates it and compares."""', "",
           "from __future__ import annotations"]
    for heading, rows in GROUPS:
        out.append("")
        out += _wrap(heading, "# ")
        for name, _, value, comment in rows:
            out += _wrap(comment, "#: ") if comment else []
            out.append(f"{name} = {value}")
    out += ["", "#: SimulationResult.status of each code."]
    out += _tuple("STATUS_NAMES", [s for s, _, _ in STATUS_TEXT])
    out.append('#: A failed run\'s reason in a few words ("" for a run that completed or fell).')
    out += _tuple("STATUS_FAILURES", [f for _, f, _ in STATUS_TEXT])
    out.append("#: The outcome of each code in the words of "
               "posturelab.simulation.setup.outcome_message.")
    out += _tuple("STATUS_OUTCOMES", [o for _, _, o in STATUS_TEXT])
    from .headers import BATCH_FIELDS, OUT_FIELDS, RUN_FIELDS

    for name, table, where in (("DIST_TERM_FIELDS", DIST_TERM_FIELDS, "after (kind, axis)"),
                               ("TILT_TERM_FIELDS", TILT_TERM_FIELDS, "after its kind")):
        out.append(f"#: The parameters of each analytic term, packed in this order {where}.")
        out.append(f"{name} = {{")
        out += [f"    {kind!r}: {fields!r},".replace("'", '"') for kind, fields in table.items()]
        out.append("}")

    for name, fields, struct in (("RUN_FIELDS", RUN_FIELDS, "pl_run"),
                                 ("OUT_FIELDS", OUT_FIELDS, "pl_out"),
                                 ("BATCH_FIELDS", BATCH_FIELDS, "pl_batch")):
        out.append(f"#: The fields of ``{struct}`` (csrc/pl_model.h) and their types: i64, f64, "
                   "*… arrays" + (", run: a pl_run." if struct == "pl_batch" else "."))
        out += _tuple(name, [f"{field}:{kind.lstrip('w')}" for field, kind, _ in fields])
    out += ["", "",
            "def body_size(n: int) -> int:",
            '    """Length of the packed body ``bp``: a (N), J_ii (N), c_ij (N², row-major), g, '
            'Σm."""',
            "    return 2 * n + n * n + 2"]
    return "\n".join(out) + "\n"
