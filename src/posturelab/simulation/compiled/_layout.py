"""Codes and array layouts shared by the C engine (``csrc/pl.h`` states the same numbers; a
test compares them) and the Python layer that packs its arguments."""

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
#: SimulationResult.status of each code.
STATUS_NAMES = ("completed", "fell", "failed", "failed", "failed", "failed", "failed", "failed")
#: A failed run's reason in a few words ("" for a run that completed or fell).
STATUS_FAILURES = ("", "", "step size underflow", "non-finite state",
                   "chattering (too many switches)", "out of memory", "step budget spent",
                   "time limit reached")
#: The outcome of each code in the words of posturelab.simulation.setup.outcome_message.
STATUS_OUTCOMES = ("completed", "fell", "step-too-small", "non-finite", "chattering",
                   "no-memory", "step-budget", "time-budget")

METHOD_RADAU = 0
METHOD_EXPLICIT = 1

KNEE_FREE = 0
KNEE_LOCKED = 1
KNEE_STOP = 2

# Packed disturbance ``dp``: dp[0] = number of terms Q, then Q rows of DIST_ROW numbers
# (kind, axis, p0, p1, p2, p3), then the sampled profiles (times, x and y accelerations).
# The terms are posturelab.model.platform.Primitive.
DIST_ROW = 6
#: a = p0 sin(2π p3 s), s = (t − p2)/p1 in [0, 1]: (amplitude [m/s²], duration [s],
#: start [s], cycles [-])
DIST_WINDOWED_SINE = 1
#: a = p0 sin(2π p1 t + p2): (amplitude [m/s²], frequency [Hz], phase [rad], 0)
DIST_SINE = 2
#: linear interpolation of a sampled profile, zero outside: (index of its times in dp, S, 0, 0)
DIST_SAMPLES = 3
# Packed tilt ``tp``: tp[0] = number of terms, then rows of TILT_ROW numbers, then the
# piecewise-cubic data (csrc/pl.h states the layout).
TILT_ROW = 7
#: (kind, amplitude [rad], frequency [Hz], phase [rad])
TILT_SINE = 1
#: (kind, amplitude [rad], start [s], duration [s])
TILT_RAISED_COSINE = 2
#: (kind, offset of the knots in tp, K intervals, period [s] or 0)
TILT_PPOLY = 3

# Options, floats ``fpar``
F_MAX_ANGLE = 0  # [rad]
F_HEEL = 1  # [m]
F_TOE = 2  # [m]
F_STOP_ANGLE = 3  # [rad]
F_RTOL = 4  # [-]
F_ATOL = 5  # [rad, rad/s]
F_MAX_STEP = 6  # largest step resolving the profile, and at most the duration [s]
F_DURATION = 7  # [s]
F_SETTLE_TOL = 8  # [rad]
F_TIME_LIMIT = 9  # wall-clock budget of the run, inf for none [s]
N_FPAR = 10

# Options, integers ``ipar``
I_USE_BOS = 0
I_USE_COP = 1
I_KNEE_MODE = 2
I_MAX_SWITCHES = 3
I_LOCKED0 = 4
I_MAX_STEPS = 5  # the step budget: accepted steps [-]
N_IPAR = 6

# Result vector of one run
R_STATUS = 0
R_N_SAMPLES = 1  # samples on the grid
R_FALL_KIND = 2  # event code of the fall (posturelab.model.events), −1 if none
R_FALL_INDEX = 3  # its link index
R_FALL_TIME = 4  # [s], NaN if none
R_N_SWITCHES = 5
R_T_REACHED = 6  # [s]
R_N_STEPS = 7
R_N_REJECTED = 8
R_N_EVALS = 9
R_LAST_OUTSIDE = 10  # last sample time with some |θ_i| > settle tolerance [s], NaN if none
R_ANY_OUTSIDE = 11  # 0/1
R_FINAL_OUTSIDE = 12  # 0/1: the last sample is outside
R_FALL_SAMPLE = 13  # 0/1: the state at the fall closes the series, off the grid
N_RESULT = 14


def body_size(n: int) -> int:
    """Length of the packed body ``bp``: a (N), J_ii (N), c_ij (N², row-major), g, Σm."""
    return 2 * n + n * n + 2
