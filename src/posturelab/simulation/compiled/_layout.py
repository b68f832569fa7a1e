"""Codes and array layouts shared with the C engine (``csrc/pl_codes.h`` states the
same numbers): GENERATED, do not edit.

``python -m posturelab.simulation.compiled._codegen`` writes this file from
``_codegen/codes.py``; a test regenerates it and compares."""

from __future__ import annotations

# Outcome of a run (result vector, R_STATUS)
STATUS_COMPLETED = 0
STATUS_FELL = 1
STATUS_STEP_TOO_SMALL = 2
STATUS_NONFINITE = 3
STATUS_CHATTERING = 4
STATUS_NO_MEMORY = 5
STATUS_STEP_BUDGET = 6
STATUS_TIME_BUDGET = 7

# Integration methods
METHOD_RADAU = 0
METHOD_EXPLICIT = 1

# Knee models
KNEE_FREE = 0
KNEE_LOCKED = 1
KNEE_STOP = 2

# Packed disturbance ``dp``: dp[0] = number of terms Q, then Q rows of DIST_ROW numbers (kind,
# axis, p0, p1, p2, p3), then the sampled profiles (times, x and y accelerations). The terms are
# posturelab.model.platform.Primitive.
#: numbers per term
DIST_ROW = 6
#: (amplitude [m/s²], duration [s], start [s], cycles [-])
DIST_WINDOWED_SINE = 1
#: (amplitude [m/s²], frequency [Hz], phase [rad], 0)
DIST_SINE = 2
#: linear interpolation, zero outside: (index of its times in dp, S, 0, 0)
DIST_SAMPLES = 3

# Packed tilt ``tp``: tp[0] = number of terms, then rows of TILT_ROW numbers (kind, p0 … p5),
# then the piecewise-cubic data: K + 1 knots, then K rows of 4 coefficients in ascending powers
# of t − knot (posturelab.model.tilt.TiltTerm).
#: numbers per term
TILT_ROW = 7
#: (amplitude [rad], frequency [Hz], phase [rad])
TILT_SINE = 1
#: (amplitude [rad], start [s], duration [s])
TILT_RAISED_COSINE = 2
#: (offset of the knots in tp, K intervals, period [s] or 0)
TILT_PPOLY = 3

# Options, floats ``fpar``
#: [rad]
F_MAX_ANGLE = 0
#: [m]
F_HEEL = 1
#: [m]
F_TOE = 2
#: [rad]
F_STOP_ANGLE = 3
#: [-]
F_RTOL = 4
#: [rad, rad/s]
F_ATOL = 5
#: largest step resolving the profile, and at most the duration [s]
F_MAX_STEP = 6
#: [s]
F_DURATION = 7
#: [rad]
F_SETTLE_TOL = 8
#: wall-clock budget of the run, inf for none [s]
F_TIME_LIMIT = 9
N_FPAR = 10

# Options, integers ``ipar``
I_USE_BOS = 0
I_USE_COP = 1
I_KNEE_MODE = 2
I_MAX_SWITCHES = 3
I_LOCKED0 = 4
#: the step budget: accepted steps [-]
I_MAX_STEPS = 5
N_IPAR = 6

# Result vector of one run
R_STATUS = 0
#: samples on the grid
R_N_SAMPLES = 1
#: event code of the fall (posturelab.model.events), −1 if none
R_FALL_KIND = 2
#: its link index
R_FALL_INDEX = 3
#: [s], NaN if none
R_FALL_TIME = 4
R_N_SWITCHES = 5
#: [s]
R_T_REACHED = 6
R_N_STEPS = 7
R_N_REJECTED = 8
R_N_EVALS = 9
#: last sample time with some |θ_i| > settle tolerance [s], NaN if none
R_LAST_OUTSIDE = 10
#: 0/1
R_ANY_OUTSIDE = 11
#: 0/1: the last sample is outside
R_FINAL_OUTSIDE = 12
#: 0/1: the state at the fall closes the series, off the grid
R_FALL_SAMPLE = 13
N_RESULT = 14

#: SimulationResult.status of each code.
STATUS_NAMES = ("completed", "fell", "failed", "failed", "failed", "failed", "failed", "failed")
#: A failed run's reason in a few words ("" for a run that completed or fell).
STATUS_FAILURES = ("", "", "step size underflow", "non-finite state",
                   "chattering (too many switches)", "out of memory", "step budget spent",
                   "time limit reached")
#: The outcome of each code in the words of posturelab.simulation.setup.outcome_message.
STATUS_OUTCOMES = ("completed", "fell", "step-too-small", "non-finite", "chattering",
                   "no-memory", "step-budget", "time-budget")
#: The parameters of each analytic term, packed in this order after (kind, axis).
DIST_TERM_FIELDS = {
    "windowed-sine": ("amplitude", "duration", "start", "cycles"),
    "sine": ("amplitude", "frequency", "phase"),
}
#: The parameters of each analytic term, packed in this order after its kind.
TILT_TERM_FIELDS = {
    "sine": ("amplitude", "frequency", "phase"),
    "raised-cosine": ("amplitude", "start", "duration"),
}
#: The fields of ``pl_run`` (csrc/pl_model.h) and their types: i64, f64, *… arrays.
RUN_FIELDS = ("n:i64", "p:i64", "n_grid:i64", "n_bps:i64", "n_slots:i64", "n_stages:i64",
              "method:i64", "x0:*f64", "before:*f64", "grid:*f64", "bp:*f64", "E:*f64",
              "C:*f64", "one_sided:*i64", "gains:*f64", "lim:*f64", "delay:f64", "dp:*f64",
              "bps:*f64", "fpar:*f64", "ipar:*i64", "active0:*f64", "sat0:*f64",
              "slot_kind:*i64", "slot_index:*i64", "slot_cond:*i64", "slot_side:*f64",
              "ev_offset:*f64", "ev_direction:*i64", "ev_ends:*i64", "tab_A:*f64", "tab_c:*f64",
              "tab_e:*f64", "tab_P:*f64", "tab_error_order:i64", "delay_multiples:i64",
              "tp:*f64", "tilt_gain:*f64", "tilt_depth:f64", "mp:*f64", "n_filters:i64",
              "filter_gain:f64", "filter_time:f64", "tilt_pair_gain:*f64", "joint_gain:*f64",
              "vp:*f64", "visual_gain:*f64", "visual_pair_gain:*f64")
#: The fields of ``pl_out`` (csrc/pl_model.h) and their types: i64, f64, *… arrays.
OUT_FIELDS = ("samples:*f64", "fb:*f64", "locked:*u8", "switches:*f64", "switch_cap:i64",
              "peak:*f64", "final:*f64", "res:*f64")
#: The fields of ``pl_batch`` (csrc/pl_model.h) and their types: i64, f64, *… arrays, run: a pl_run.
BATCH_FIELDS = ("base:run", "which:*i64", "dp_stride:i64", "x0_all:*f64", "before_all:*f64",
                "dp_all:*f64", "ipar_all:*i64", "active0_all:*f64", "gains_all:*f64",
                "lim_all:*f64", "delay_all:*f64", "sat0_all:*f64", "method_all:*i64",
                "tilt_gain_all:*f64", "tilt_pair_gain_all:*f64", "visual_gain_all:*f64",
                "visual_pair_gain_all:*f64", "peaks:*f64", "finals:*f64", "results:*f64")


def body_size(n: int) -> int:
    """Length of the packed body ``bp``: a (N), J_ii (N), c_ij (N², row-major), g, Σm."""
    return 2 * n + n * n + 2
