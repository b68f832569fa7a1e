/* One step routine for every explicit Runge–Kutta pair: the tableau (A, c, e, P, error
 * order) comes from Python (posturelab/simulation/compiled/_tableaux.py), so a new pair is
 * data only.
 *
 * FSAL pairs: the last row of A is the solution weights, so the last stage is
 * f(t + h, y_new), the next step's first. Error: h Σ_j e_j K_j, RMS-scaled. Step-size
 * control: Hairer's PI controller of DOPRI5 (Hairer, Nørsett & Wanner, Solving ODEs I,
 * II.4 and IV.2; β = 0.04, safety 0.9, factor in [0.2, 10]); the first step is scipy's
 * select_initial_step. Dense output Q = h Kᵀ P. */
#include <math.h>
#include <stdlib.h>
#include "pl.h"

#define BETA 0.04
#define SAFE 0.9
#define FACC1 (1.0 / 0.2)
#define FACC2 (1.0 / 10.0)

typedef struct {
    int64_t S, m, order;
    const double *A, *e, *P;
    double exponent, log_err_old;
    int last_rejected;
    double *K, *y1, *f1;
} rk_ws;

double pl_initial_step(const pl_model *md, double t0, const double *y0, const double *f0,
                       double t_bound, double max_step, double rtol, double atol, int locked,
                       const double *inp, double *y1, double *f1, int64_t m, int order)
{
    const double interval = t_bound - t0;
    if (interval <= 0.0)
        return 0.0;
    double d0 = 0.0, d1 = 0.0;
    for (int64_t i = 0; i < m; i++) {
        const double sc = atol + fabs(y0[i]) * rtol;
        d0 += (y0[i] / sc) * (y0[i] / sc);
        d1 += (f0[i] / sc) * (f0[i] / sc);
    }
    d0 = sqrt(d0 / m);
    d1 = sqrt(d1 / m);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    h0 = fmin(h0, interval);
    for (int64_t i = 0; i < m; i++)
        y1[i] = y0[i] + h0 * f0[i];
    pl_rhs(md, y1, f1, inp, locked);
    double d2 = 0.0;
    for (int64_t i = 0; i < m; i++) {
        const double sc = atol + fabs(y0[i]) * rtol, v = (f1[i] - f0[i]) / sc;
        d2 += v * v;
    }
    d2 = sqrt(d2 / m) / h0;
    double h1 = (d1 <= 1e-15 && d2 <= 1e-15) ? fmax(1e-6, h0 * 1e-3)
                                             : pow(0.01 / fmax(d1, d2), 1.0 / (order + 1.0));
    return fmin(fmin(100.0 * h0, h1), fmin(interval, max_step));
}

static double rk_start(pl_method *me, const pl_model *md, double t, const double *x,
                       double t_stop, double max_step, double rtol, double atol, int locked,
                       const double *inp, int64_t *evals)
{
    rk_ws *w = me->ws;
    pl_rhs(md, x, w->K, inp, locked);
    w->log_err_old = log(1e-4);
    w->last_rejected = 0;
    *evals += 2;
    return pl_initial_step(md, t, x, w->K, t_stop, max_step, rtol, atol, locked, inp, w->y1,
                           w->f1, w->m, (int)w->order);
}

static double rk_limit(pl_method *me, double h, double max_step)
{
    (void)me;
    return fmin(h, max_step);
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

static void rk_commit(pl_method *me)
{
    rk_ws *w = me->ws;
    for (int64_t i = 0; i < w->m; i++)
        w->K[i] = w->K[(w->S - 1) * w->m + i];
}

/* after a step onto a breakpoint the last stage (the left limit there) is not the next
 * step's first: evaluate it with the inputs just after the breakpoint */
static void rk_refresh(pl_method *me, const pl_model *md, const double *x, const double *inp,
                       int locked, int64_t *evals)
{
    rk_ws *w = me->ws;
    pl_rhs(md, x, w->K, inp, locked);
    *evals += 1;
}

static void rk_release(pl_method *me)
{
    rk_ws *w = me->ws;
    if (w) {
        free(w->K);
        free(w->y1);
        free(w->f1);
        free(w);
    }
    me->ws = NULL;
}

int pl_explicit_init(pl_method *me, const pl_run *run, int64_t n)
{
    rk_ws *w = calloc(1, sizeof(rk_ws));
    *me = (pl_method){.n_nodes = run->n_stages, .nodes = run->tab_c, .ws = w,
                      .start = rk_start, .limit = rk_limit, .attempt = rk_attempt,
                      .commit = rk_commit, .release = rk_release, .refresh = rk_refresh};
    if (!w)
        return 0;
    w->S = run->n_stages;
    w->m = 2 * n + run->n_filters;
    w->order = run->tab_error_order;
    w->A = run->tab_A;
    w->e = run->tab_e;
    w->P = run->tab_P;
    w->exponent = 1.0 / (w->order + 1.0) - 0.75 * BETA;
    w->K = calloc(w->S * w->m, sizeof(double));
    w->y1 = calloc(w->m, sizeof(double));
    w->f1 = calloc(w->m, sizeof(double));
    return w->K && w->y1 && w->f1;
}
