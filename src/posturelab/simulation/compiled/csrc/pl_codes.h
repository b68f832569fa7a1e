/* Codes and array layouts shared with Python: GENERATED, do not edit.
 *
 * python -m posturelab.simulation.compiled._codegen writes this file from
 * _codegen/codes.py and posturelab.model (events, gains); _layout.py states the same
 * numbers for Python. */
#ifndef PL_CODES_H
#define PL_CODES_H

/* Outcome of a run (result vector, R_STATUS) */
enum { PL_COMPLETED = 0, PL_FELL = 1, PL_STEP_TOO_SMALL = 2, PL_NONFINITE = 3, PL_CHATTERING = 4,
       PL_NO_MEMORY = 5, PL_STEP_BUDGET = 6, PL_TIME_BUDGET = 7 };

/* Integration methods */
enum { METHOD_RADAU = 0, METHOD_EXPLICIT = 1 };

/* Knee models */
enum { KNEE_FREE = 0, KNEE_LOCKED = 1, KNEE_STOP = 2 };

/* Packed disturbance ``dp``: dp[0] = number of terms Q, then Q rows of DIST_ROW numbers (kind,
 * axis, p0, p1, p2, p3), then the sampled profiles (times, x and y accelerations). The terms are
 * posturelab.model.platform.Primitive. */
enum { DIST_ROW = 6, DIST_WINDOWED_SINE = 1, DIST_SINE = 2, DIST_SAMPLES = 3 };

/* Packed tilt ``tp``: tp[0] = number of terms, then rows of TILT_ROW numbers (kind, p0 … p5), then
 * the piecewise-cubic data: K + 1 knots, then K rows of 4 coefficients in ascending powers of t −
 * knot (posturelab.model.tilt.TiltTerm). */
enum { TILT_ROW = 7, TILT_SINE = 1, TILT_RAISED_COSINE = 2, TILT_PPOLY = 3 };

/* Options, floats ``fpar`` */
enum { F_MAX_ANGLE = 0, F_HEEL = 1, F_TOE = 2, F_STOP_ANGLE = 3, F_RTOL = 4, F_ATOL = 5,
       F_MAX_STEP = 6, F_DURATION = 7, F_SETTLE_TOL = 8, F_TIME_LIMIT = 9, N_FPAR = 10 };

/* Options, integers ``ipar`` */
enum { I_USE_BOS = 0, I_USE_COP = 1, I_KNEE_MODE = 2, I_MAX_SWITCHES = 3, I_LOCKED0 = 4,
       I_MAX_STEPS = 5, N_IPAR = 6 };

/* Result vector of one run */
enum { R_STATUS = 0, R_N_SAMPLES = 1, R_FALL_KIND = 2, R_FALL_INDEX = 3, R_FALL_TIME = 4,
       R_N_SWITCHES = 5, R_T_REACHED = 6, R_N_STEPS = 7, R_N_REJECTED = 8, R_N_EVALS = 9,
       R_LAST_OUTSIDE = 10, R_ANY_OUTSIDE = 11, R_FINAL_OUTSIDE = 12, R_FALL_SAMPLE = 13,
       N_RESULT = 14 };

/* Event kinds (posturelab.model.events) */
enum { EV_LINK_ANGLE = 0, EV_COG_TOE = 1, EV_COG_HEEL = 2, EV_COP_TOE = 3, EV_COP_HEEL = 4,
       EV_SATURATES = 5, EV_LETS_GO = 6, EV_PAIR_SLACKENS = 7, EV_PAIR_ENGAGES = 8,
       EV_KNEE_HITS_STOP = 9, EV_KNEE_LEAVES_STOP = 10, EV_PAIR_PUSHES = 11, EV_PAIR_PULLS = 12 };

/* Conditions of a segment's event slots (posturelab.model.events) */
enum { COND_ALWAYS = 0, COND_JOINT_FREE = 1, COND_JOINT_SATURATED = 2, COND_PAIR_ACTIVE = 3,
       COND_PAIR_SLACK = 4, COND_KNEE_FREE = 5, COND_KNEE_LOCKED = 6 };

/* Rows of a (4, P) gains array (posturelab.model.gains) */
enum { GAIN_IMMEDIATE_STIFFNESS = 0, GAIN_IMMEDIATE_VISCOSITY = 1, GAIN_DELAYED_STIFFNESS = 2,
       GAIN_DELAYED_VISCOSITY = 3 };

#endif
