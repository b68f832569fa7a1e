/* posturelab's compiled engine: shared declarations.
 *
 * The physics is that of posturelab.model (the equation of motion of an N-link chain on a
 * moving platform under muscle-pair feedback), the events those of posturelab.model.events,
 * the run set-up that of posturelab.simulation.setup; Python packs them into the structs
 * below (posturelab/simulation/compiled/_binding.py mirrors them field by field).
 *
 * Units: SI throughout (m, kg, s, rad, N·m). Arrays are C-ordered doubles unless stated.
 */
#ifndef PL_H
#define PL_H

#include <math.h>
#include <stdint.h>

/* Outcome codes (R_STATUS of the result vector); _layout.py holds the same numbers. */
enum { PL_COMPLETED = 0, PL_FELL = 1, PL_STEP_TOO_SMALL = 2, PL_NONFINITE = 3,
       PL_CHATTERING = 4, PL_NO_MEMORY = 5, PL_STEP_BUDGET = 6, PL_TIME_BUDGET = 7 };

/* Result vector indices */
enum { R_STATUS = 0, R_N_SAMPLES, R_FALL_KIND, R_FALL_INDEX, R_FALL_TIME, R_N_SWITCHES,
       R_T_REACHED, R_N_STEPS, R_N_REJECTED, R_N_EVALS, R_LAST_OUTSIDE, R_ANY_OUTSIDE,
       R_FINAL_OUTSIDE, R_FALL_SAMPLE, N_RESULT };

/* fpar / ipar indices */
enum { F_MAX_ANGLE = 0, F_HEEL, F_TOE, F_STOP_ANGLE, F_RTOL, F_ATOL, F_MAX_STEP, F_DURATION,
       F_SETTLE_TOL, F_TIME_LIMIT, N_FPAR };
enum { I_USE_BOS = 0, I_USE_COP, I_KNEE_MODE, I_MAX_SWITCHES, I_LOCKED0, I_MAX_STEPS, N_IPAR };
enum { KNEE_FREE = 0, KNEE_LOCKED = 1, KNEE_STOP = 2 };

/* Packed disturbance: dp[0] = number of terms, then rows of DIST_ROW numbers
 * (kind, axis, p0, p1, p2, p3), then sampled profiles (posturelab.model.platform.Primitive). */
enum { DIST_ROW = 6, DIST_WINDOWED_SINE = 1, DIST_SINE = 2, DIST_SAMPLES = 3 };

/* Packed tilt: tp[0] = number of terms, then rows of TILT_ROW numbers
 * (kind, p0 … p5), then piecewise-cubic data (posturelab.model.tilt.TiltTerm):
 * sine (A, f, φ), raised cosine (A, start, duration), ppoly (offset, K, period): at
 * tp[offset] K + 1 knots, then K rows of 4 coefficients in ascending powers of t − knot. */
enum { TILT_ROW = 7, TILT_SINE = 1, TILT_RAISED_COSINE = 2, TILT_PPOLY = 3 };

/* Packed motor noise (posturelab.model.noise.TorqueSeries): mp[0] = K intervals (0: none),
 * then K + 1 knots, then K·4·n coefficients, interval-major, ascending powers of t − knot,
 * joint fastest. */

/* Event kinds (posturelab.model.events) and the conditions of the segment's event slots */
enum { EV_LINK_ANGLE = 0, EV_COG_TOE, EV_COG_HEEL, EV_COP_TOE, EV_COP_HEEL, EV_SATURATES,
       EV_LETS_GO, EV_PAIR_SLACKENS, EV_PAIR_ENGAGES, EV_KNEE_HITS_STOP, EV_KNEE_LEAVES_STOP,
       EV_PAIR_PUSHES, EV_PAIR_PULLS };
enum { COND_ALWAYS = 0, COND_JOINT_FREE, COND_JOINT_SATURATED, COND_PAIR_ACTIVE,
       COND_PAIR_SLACK, COND_KNEE_FREE, COND_KNEE_LOCKED };

/* Methods */
enum { METHOD_RADAU = 0, METHOD_EXPLICIT = 1 };

/* One run: everything the integration needs (read only). */
typedef struct {
    int64_t n, p, n_grid, n_bps, n_slots, n_stages, method;
    const double *x0, *before, *grid;   /* (2n), (2n), (n_grid) */
    const double *bp;                   /* a (n), J_ii (n), c_ij (n*n), g, total mass */
    const double *E, *C;                /* (p, n) stretch rows, joint-crossing rows */
    const int64_t *one_sided;           /* (p) */
    const double *gains;                /* (4, p): k_d, l_d, delayed k_d, delayed l_d */
    const double *lim;                  /* (n) torque limits, inf for none [N·m] */
    double delay;                       /* feedback delay [s] */
    const double *dp, *bps;             /* packed disturbance, breakpoints in (0, duration) */
    const double *fpar;
    const int64_t *ipar;
    const double *active0, *sat0;       /* (p), (n) at the start */
    const int64_t *slot_kind, *slot_index, *slot_cond;  /* (n_slots) event slots, in order */
    const double *slot_side;
    const double *ev_offset;            /* by kind: the event function's constant part */
    const int64_t *ev_direction, *ev_ends;
    const double *tab_A, *tab_c, *tab_e, *tab_P;  /* explicit tableau (n_stages ...) */
    int64_t tab_error_order;
    int64_t delay_multiples;            /* land on k·delay for k = 1 … this */
    const double *tp;                   /* packed tilt (tp[0] = 0: none) */
    const double *tilt_gain;            /* (4, n) joint moments per α(t), α̇(t), α(t−τ), α̇(t−τ) */
    double tilt_depth;                  /* tilt axis below the ankle [m] (0: the ankle's) */
    const double *mp;                   /* packed motor noise (mp[0] = 0: none) */
} pl_run;

/* Outputs of one run (any pointer may be NULL where noted). */
typedef struct {
    double *samples;     /* (2n, n_grid + 1) or NULL */
    double *fb;          /* (2n, n_grid + 1) states the muscles responded to, or NULL */
    uint8_t *locked;     /* (n_grid + 1) or NULL */
    double *switches;    /* (switch_cap) or NULL */
    int64_t switch_cap;
    double *peak;        /* (n) */
    double *final;       /* (2n) */
    double *res;         /* (N_RESULT) */
} pl_out;

/* What the right-hand side needs besides the state. */
typedef struct {
    int64_t n;
    const double *bp;
    double *tm;          /* (4, n, n): T_K, T_L, delayed T_K, delayed T_L */
    const double *lim;   /* (n) */
    double *sat;         /* (n) saturation signs */
    double *base;        /* (3n) θ, sin θ, cos θ at the step's start */
    double *work;        /* (n, n + 4) */
    double *tau;         /* (n) receives the joint moments */
} pl_model;

/* sin θ and cos θ from those of a nearby θ_b by the angle-sum formulas: within a step the
 * angles move by hundredths of a radian, and the series of sin δ (to δ⁹) and cos δ − 1 (to δ⁸)
 * are exact to rounding for |δ| <= 0.1 and much shorter than libm's sin and cos; farther
 * away, libm. pl_set_base stores (θ_b, sin θ_b, cos θ_b) at each step's start. */
static inline void pl_rotate(double theta, double theta_b, double s_b, double c_b, double *s,
                             double *c)
{
    const double d = theta - theta_b;
    if (d > 0.1 || d < -0.1) {
        *s = sin(theta);
        *c = cos(theta);
        return;
    }
    const double z = d * d;
    const double sd = d + d * z * (-1.0 / 6.0 + z * (1.0 / 120.0 + z * (-1.0 / 5040.0
                                                                        + z * (1.0 / 362880.0))));
    const double cdm1 = z * (-0.5 + z * (1.0 / 24.0 + z * (-1.0 / 720.0 + z * (1.0 / 40320.0))));
    *s = s_b + (s_b * cdm1 + c_b * sd);
    *c = c_b + (c_b * cdm1 - s_b * sd);
}

/* right-hand side (pl_rhs.c, pl_rhs_small.c) */
void pl_rhs(const pl_model *md, const double *x, double *out, const double *inp, int locked);
void pl_rhs_general(const pl_model *md, const double *x, double *out, const double *inp,
                    int locked);
void pl_rhs1(const pl_model *md, const double *x, double *out, const double *inp, int locked);
void pl_rhs2(const pl_model *md, const double *x, double *out, const double *inp, int locked);
void pl_rhs3(const pl_model *md, const double *x, double *out, const double *inp, int locked);
void pl_set_base(const double *x, double *base, int64_t n);
void pl_moment_gains(const double *E, const double *C, const double *kd, const double *ld,
                     const double *active, int64_t p, int64_t n, double *tk, double *tl);
void pl_project_velocity(double *x, const double *bp, double *work, int64_t n);

/* linear algebra (pl_linalg.c) */
void pl_solve_into(double *M, int64_t n, int64_t ncol, int64_t stride);
void pl_lu_factor(double *A, int64_t *piv, int64_t n);
void pl_lu_solve(const double *A, const int64_t *piv, double *b, int64_t n);
void pl_inverse3(const double *a, double *out);
void pl_inverse3_complex(const double *ar, const double *ai, double *outr, double *outi);

/* platform (pl_platform.c) */
void pl_platform_acceleration(double t, const double *dp, double *ax, double *ay);
void pl_tilt(double t, const double *tp, double *angle, double *rate, double *accel);
void pl_motor_noise_add(double t, const double *mp, int64_t n, double *tau);

/* history of a delayed run (pl_history.c) */
typedef struct {
    int64_t m, count, cap;
    double *t, *h, *x, *q;   /* (cap), (cap), (cap, m), (cap, m, 4) */
} pl_history;
int pl_history_init(pl_history *hist, int64_t m, int64_t cap);
int pl_history_add(pl_history *hist, double t, double h, const double *x, const double *Q);
void pl_history_at(const pl_history *hist, const double *before, double s, double *out);
void pl_history_drop(pl_history *hist);  /* the last step out again (overlapping steps) */
void pl_history_extrapolate(const pl_history *hist, double t, double h, const double *x,
                            double *Q);
void pl_history_free(pl_history *hist);

/* dense output of a step: x + Q·(σ, σ², σ³, σ⁴) */
void pl_dense_at(const double *restrict x, const double *restrict Q, int64_t m, double t0,
                 double h, double t, double *restrict out);

/* the integration loop (pl_driver.c) and the methods (pl_explicit.c, pl_radau.c) */
int64_t pl_integrate(const pl_run *run, pl_out *out);

typedef struct pl_method pl_method;
struct pl_method {
    int64_t n_nodes;
    const double *nodes;
    void *ws;
    double (*start)(pl_method *me, const pl_model *md, double t, const double *x,
                    double t_stop, double max_step, double rtol, double atol, int locked,
                    const double *inp, int64_t *evals);
    double (*limit)(pl_method *me, double h, double max_step);
    int (*attempt)(pl_method *me, const pl_model *md, double t, double h, const double *x,
                   double *y, double *Q, const double *inp, double rtol, double atol,
                   int locked, double *h_next, int64_t *evals);
    void (*commit)(pl_method *me);
    void (*release)(pl_method *me);
    /* after a step onto a breakpoint: the first stage again, from the inputs just after it */
    void (*refresh)(pl_method *me, const pl_model *md, const double *x, const double *inp,
                    int locked, int64_t *evals);
};
int pl_explicit_init(pl_method *me, const pl_run *run, int64_t n);
int pl_radau_init(pl_method *me, int64_t n);
void pl_radau_constants(void);  /* once, at import */
double pl_initial_step(const pl_model *md, double t0, const double *y0, const double *f0,
                       double t_bound, double max_step, double rtol, double atol, int locked,
                       const double *inp, double *y1, double *f1, int64_t m, int order);

#endif
