/* One step routine for every explicit Runge–Kutta pair: the tableau (A, c, e, P, error
 * order) comes from Python (posturelab/simulation/compiled/_tableaux.py), so a new pair is
 * data only.
 *
 * FSAL pairs: the last row of A is the solution weights, so the last stage is
 * f(t + h, y_new), the next step's first. Error: h Σ_j e_j K_j, RMS-scaled. Step-size
 * control: Hairer's PI controller of DOPRI5 (Hairer, Nørsett & Wanner, Solving ODEs I,
 * II.4 and IV.2; β = 0.04, safety 0.9, factor in [0.2, 10]). Dense output Q = h Kᵀ P. */
#include <math.h>
#include <stdlib.h>
#include "pl.h"

#define BETA 0.04
#define SAFE 0.9
#define FACC1 (1.0 / 0.2)
#define FACC2 (1.0 / 10.0)

typedef struct {
    int64_t S, m;
    const double *A, *e, *P;
    double exponent, log_err_old;
    int last_rejected;
    double *K;  /* (S, m) the stages */
} rk_ws;

static void rk_start(pl_method *me, const pl_model *md, const double *x, const double *inp,
                     int locked, double rtol, int64_t *evals)
{
    rk_ws *w = me->ws;
    (void)md, (void)x, (void)inp, (void)locked, (void)rtol, (void)evals;  /* (Radau's) */
    w->log_err_old = log(1e-4);
    w->last_rejected = 0;
}

static int rk_attempt(pl_method *me, const pl_model *md, double t, double h,
                      const double *restrict x, double *restrict y, double *restrict Q,
                      const double *inp, double rtol, double atol,
                      int locked, double *h_next, int64_t *evals)
{
    rk_ws *w = me->ws;
    const int64_t S = w->S, m = w->m, width = 2 + md->n + md->nf;
    double *restrict K = w->K;
    const double *restrict A = w->A, *restrict ew = w->e, *restrict P = w->P;
    (void)t;
    for (int64_t s = 1; s < S; s++) {
        const double *restrict a = A + s * S;
        for (int64_t i = 0; i < m; i++) {
            double acc = 0.0;
            for (int64_t j = 0; j < s; j++)
                acc += a[j] * K[j * m + i];
            y[i] = x[i] + h * acc;
        }
        pl_rhs(md, y, K + s * m, inp + s * width, locked);
    }
    *evals += S - 1;
    double err2 = 0.0;
    for (int64_t i = 0; i < m; i++) {
        double e = 0.0;
        for (int64_t j = 0; j < S; j++)
            e += ew[j] * K[j * m + i];
        e = h * e / (atol + rtol * fmax(fabs(x[i]), fabs(y[i])));
        err2 += e * e;
    }
    err2 /= m;
    if (!(err2 <= 1.0)) {  /* rejected; a NaN error counts as too large */
        if (err2 < 1e300)
            *h_next = h / fmin(FACC1, exp(0.5 * w->exponent * log(err2)) / SAFE);
        else if (err2 == err2)
            *h_next = h / FACC1;
        else
            *h_next = 0.1 * h;
        w->last_rejected = 1;
        return 0;
    }
    const double log_err = err2 > 1e-300 ? 0.5 * log(err2) : -345.0;
    const double fac = fmax(FACC2, fmin(FACC1, exp(w->exponent * log_err
                                                   - BETA * w->log_err_old) / SAFE));
    double hn = h / fac;
    if (w->last_rejected)
        hn = fmin(hn, h);
    *h_next = hn;
    w->last_rejected = 0;
    w->log_err_old = fmax(log_err, log(1e-4));
    for (int64_t i = 0; i < m; i++)
        for (int64_t k = 0; k < 4; k++) {
            double acc = 0.0;
            for (int64_t j = 0; j < S; j++)
                acc += K[j * m + i] * P[j * 4 + k];
            Q[4 * i + k] = h * acc;
        }
    return 1;
}

int pl_explicit_init(pl_method *me, const pl_run *run, int64_t n)
{
    rk_ws *w = calloc(1, sizeof(rk_ws));
    *me = (pl_method){.n_nodes = run->n_stages, .order = run->tab_error_order,
                      .nodes = run->tab_c, .ws = w, .start = rk_start, .attempt = rk_attempt};
    if (!w)
        return 0;
    w->S = run->n_stages;
    w->m = 2 * n + run->n_filters;
    w->A = run->tab_A;
    w->e = run->tab_e;
    w->P = run->tab_P;
    w->exponent = 1.0 / (run->tab_error_order + 1.0) - 0.75 * BETA;
    me->arrays = w->K = calloc(w->S * w->m, sizeof(double));
    /* FSAL: the first stage is f0, the last the end's */
    me->f0 = w->K;
    me->f_end = w->K ? w->K + (w->S - 1) * w->m : NULL;
    return w->K != NULL;
}
