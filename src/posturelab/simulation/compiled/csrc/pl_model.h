/* The interface of the generated model: GENERATED, do not edit.
 *
 * python -m posturelab.simulation.compiled._codegen writes this file from
 * _codegen/headers.py (the structs' fields, which _layout.py carries for
 * _binding.py), sympy (the rotation's series) and the definitions in pl_model.c
 * and pl_rhs_small.c (the prototypes); pl.h includes it. */
#ifndef PL_MODEL_H
#define PL_MODEL_H

/* One run: everything the integration needs (read only). */
typedef struct {
    int64_t n;
    int64_t p;
    int64_t n_grid;
    int64_t n_bps;
    int64_t n_slots;
    int64_t n_stages;
    int64_t method;
    const double *x0;                   /* (2n) */
    const double *before;               /* (2n) */
    const double *grid;                 /* (n_grid) */
    const double *bp;                   /* a (n), J_ii (n), c_ij (n*n), g, total mass */
    const double *E;                    /* (p, n) stretch rows */
    const double *C;                    /* (p, n) joint-crossing rows */
    const int64_t *one_sided;           /* (p) */
    const double *gains;                /* (4, p) rows GAIN_*: immediate k, l, delayed k, l */
    const double *lim;                  /* (2n) torque limits >= 0: the negative side's (n), the positive side's (n), inf for none [N·m] */
    double delay;                       /* feedback delay [s] */
    const double *dp;                   /* packed disturbance */
    const double *bps;                  /* breakpoints in (0, duration) */
    const double *fpar;                 /* F_* */
    const int64_t *ipar;                /* I_* */
    const double *active0;              /* (p) at the start */
    const double *sat0;                 /* (n) at the start */
    const int64_t *slot_kind;           /* (n_slots) event slots, in order */
    const int64_t *slot_index;
    const int64_t *slot_cond;
    const double *slot_side;
    const double *ev_offset;            /* by kind: the event function's constant part */
    const int64_t *ev_direction;
    const int64_t *ev_ends;
    const double *tab_A;                /* explicit tableau (n_stages ...) */
    const double *tab_c;
    const double *tab_e;
    const double *tab_P;
    int64_t tab_error_order;
    int64_t delay_multiples;            /* land on k·delay for k = 1 … this */
    const double *tp;                   /* packed tilt (tp[0] = 0: none) */
    const double *tilt_gain;            /* (4, n) joint moments per α(t), α̇(t), α(t−τ), α̇(t−τ) */
    double tilt_depth;                  /* tilt axis below the ankle [m] (0: the ankle's) */
    const double *mp;                   /* packed motor noise (model.noise.TorqueSeries): mp[0] = K intervals (0: none), K + 1 knots, K·4·n coefficients (interval-major, ascending powers of t − knot, joint fastest) */
    int64_t n_filters;                  /* torque feedback filter states after [Θ, Θ̇]: p, or 0 */
    double filter_gain;                 /* K_t of the torque feedback [-] */
    double filter_time;                 /* τ_t of its filter [s] */
    const double *tilt_pair_gain;       /* (4, p) pair torques per α(t), α̇(t), α(t−τ), α̇(t−τ) */
    const double *joint_gain;           /* (4, n, n) joint-space controller's moment gains, rows GAIN_* */
    const double *vp;                   /* packed visual-scene tilt (vp[0] = 0: none) */
    const double *visual_gain;          /* (4, n) joint moments per v(t), v̇(t), v(t−τ), v̇(t−τ) */
    const double *visual_pair_gain;     /* (4, p) pair torques per v(t), v̇(t), v(t−τ), v̇(t−τ) */
} pl_run;

/* Outputs of one run (any pointer may be NULL where noted). */
typedef struct {
    double *samples;                    /* (2n + n_filters, n_grid + 1) or NULL */
    double *fb;                         /* (2n, n_grid + 1) states the muscles responded to, or NULL */
    uint8_t *locked;                    /* (n_grid + 1) or NULL */
    double *switches;                   /* (switch_cap) or NULL */
    int64_t switch_cap;
    double *peak;                       /* (n) */
    double *final;                      /* (2n) */
    double *res;                        /* (N_RESULT) */
} pl_out;

/* A batch: its runs share base but for the rows below (pl_batch_row). */
typedef struct {
    pl_run base;                        /* what the runs share */
    const int64_t *which;               /* (runs) the level of each run */
    int64_t dp_stride;                  /* numbers per level of dp_all */
    const double *x0_all;               /* (levels, 2 * n) */
    const double *before_all;           /* (levels, 2 * n) */
    const double *dp_all;               /* (levels, dp_stride) */
    const int64_t *ipar_all;            /* (levels, N_IPAR) */
    const double *active0_all;          /* (levels, p) */
    const double *gains_all;            /* (runs, 4 * p) */
    const double *lim_all;              /* (runs, 2 * n) */
    const double *delay_all;            /* (runs) */
    const double *sat0_all;             /* (runs, n) */
    const int64_t *method_all;          /* (runs) */
    const double *tilt_gain_all;        /* (runs, 4 * n) */
    const double *tilt_pair_gain_all;   /* (runs, 4 * p) */
    const double *visual_gain_all;      /* (runs, 4 * n) */
    const double *visual_pair_gain_all; /* (runs, 4 * p) */
    double *peaks;                      /* (runs, n) */
    double *finals;                     /* (runs, 2 * n) */
    double *results;                    /* (runs, N_RESULT) */
} pl_batch;

/* What the right-hand side needs besides the state. */
typedef struct {
    int64_t n;
    const double *bp;
    double *tm;                         /* (4, n, n): T_K, T_L, delayed T_K, delayed T_L */
    const double *lim;                  /* (2n): negative, positive limits */
    double *sat;                        /* (n) saturation signs */
    double *base;                       /* (3n) θ, sin θ, cos θ at the step's start */
    double *work;                       /* (n, n + 4) */
    double *tau;                        /* (n) receives the joint moments */
    int64_t nf;                         /* torque feedback filter states after [Θ, Θ̇] (0: none) */
    double tf_gain;                     /* K_t [-] */
    double tf_time;                     /* τ_t [s] */
    const double *C;                    /* (p, n) joint-crossing rows */
    const double *active;               /* (p) which pairs act */
    double *fscr;                       /* (2 + n + nf) the inputs with the filters' moments, their rates */
} pl_model;

struct pl_history;

/* What the inputs and an event function need besides (t, y). */
typedef struct {
    const pl_model *md;
    const double *E;
    const double *dp;
    const double *fpar;
    const double *before;
    const double *ev_offset;
    const struct pl_history *hist;
    double delay;
    const double *tp;                   /* packed tilt */
    const double *tilt_gain;            /* (4, n) joint gains on the tilt */
    double tilt_depth;                  /* tilt axis below the ankle [m] */
    const double *mp;                   /* packed motor noise */
    const double *gains;                /* (4, p) the run's pair gains */
    int64_t p;
    double *sc_out;                     /* scratch (m) */
    double *sc_inp;                     /* (2 + n + nf) */
    double *sc_x;                       /* (m) */
    double *ys;                         /* (m) */
    const double *tilt_pair_gain;       /* (4, p) pair gains on the tilt */
    const double *vp;                   /* packed visual-scene tilt */
    const double *visual_gain;          /* (4, n) joint gains on it */
    const double *visual_pair_gain;     /* (4, p) pair gains on it */
} pl_ctx;

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
    const double sd = d + d * (z*(z*(z*((1.0/362880.0)*z - 1.0/5040.0) + 1.0/120.0) - 1.0/6.0));
    const double cdm1 = z*(z*(z*((1.0/40320.0)*z - 1.0/720.0) + 1.0/24.0) - 1.0/2.0);
    *s = s_b + (s_b * cdm1 + c_b * sd);
    *c = c_b + (c_b * cdm1 - s_b * sd);
}

/* the functions of pl_model.c and pl_rhs_small.c (what each does: there) */
void pl_platform_acceleration(double t, const double *dp, double *ax, double *ay);
void pl_tilt(double t, const double *tp, double *angle, double *rate, double *accel);
void pl_motor_noise_add(double t, const double *mp, int64_t n, double *tau);
void pl_inputs_at(const pl_ctx *cx, double t, double *out);
void pl_set_base(const double *x, double *base, int64_t n);
void pl_rhs_general(const pl_model *md, const double *x, double *out, const double *inp,
                    int locked);
void pl_rhs(const pl_model *md, const double *x, double *out, const double *inp, int locked);
void pl_moment_gains(const double *E, const double *C, const double *gains, const double *jg,
                     const double *active, int64_t p, int64_t n, double *tm);
void pl_project_velocity(double *x, const double *bp, double *work, int64_t n);
double pl_event_value(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t,
                      const double *y, int locked);
double pl_slot_side(int64_t kind, int64_t i, double side, const double *sat);
int pl_switch_needs_feedback(int64_t kind);
void pl_apply_switch(const pl_run *run, int64_t kind, int64_t j, double side,
                     const double *feedback, double *x, double *active, double *sat,
                     int *locked, double *work);
int pl_slot_on(int64_t cond, int64_t i, const double *sat, const double *active, int locked);
void pl_batch_row(const pl_batch *b, int64_t r, pl_run *run, pl_out *out);
void pl_rhs1(const pl_model *md, const double *x, double *out, const double *inp, int locked);
void pl_rhs2(const pl_model *md, const double *x, double *out, const double *inp, int locked);
void pl_rhs3(const pl_model *md, const double *x, double *out, const double *inp, int locked);

#endif
