/* The past of a run with delayed feedback: every kept step's dense output.
 *
 * Before t = 0 the past is the state before the run; after it, the interpolant of the step
 * that covered that time. Steps are at most τ long, so the past a step needs is complete
 * when the step starts, except with a very short delay (pl_driver.c: overlapping steps):
 * there the step being tried is stored too, first as the last step's interpolant carried
 * on (pl_history_extrapolate), then as its own, and taken out again if it is rejected.
 * The arrays (the times, the steps' records) double when full. */
#include <stdlib.h>
#include <string.h>
#include "pl.h"

void pl_dense_at(const double *restrict x, const double *restrict Q, int64_t m, double s,
                 double *restrict out)
{
    for (int64_t i = 0; i < m; i++) {
        const double *q = Q + 4 * i;
        out[i] = x[i] + s * (q[0] + s * (q[1] + s * (q[2] + s * q[3])));
    }
}

int pl_history_init(pl_history *hist, int64_t m, int64_t cap)
{
    *hist = (pl_history){.m = m, .cap = cap, .t = malloc(sizeof(double) * cap),
                         .rec = malloc(sizeof(double) * cap * (1 + 5 * m))};
    return hist->t && hist->rec;
}

int pl_history_add(pl_history *hist, double t, double h, const double *x, const double *Q)
{
    const int64_t m = hist->m, width = 1 + 5 * m;
    if (hist->count == hist->cap) {
        const int64_t cap = 2 * hist->cap;
        double *tq = realloc(hist->t, sizeof(double) * cap);
        if (tq)
            hist->t = tq;  /* (longer than needed if the records cannot follow) */
        double *rq = tq ? realloc(hist->rec, sizeof(double) * cap * width) : NULL;
        if (!rq)
            return 0;
        hist->rec = rq;
        hist->cap = cap;
    }
    const int64_t k = hist->count++;
    double *rec = hist->rec + k * width;
    hist->t[k] = t;
    rec[0] = h;
    memcpy(rec + 1, x, sizeof(double) * m);
    memcpy(rec + 1 + m, Q, sizeof(double) * m * 4);
    return 1;
}

void pl_history_at(const pl_history *hist, const double *before, double s, double *out)
{
    const int64_t m = hist->m;
    if (s < 0.0 || hist->count == 0) {
        memcpy(out, before, sizeof(double) * m);
        return;
    }
    const int64_t k = pl_interval_of(hist->t, 0, hist->count, s);
    const double *rec = hist->rec + k * (1 + 5 * m);
    double sg = (s - hist->t[k]) / rec[0];
    if (sg > 1.0)
        sg = 1.0;
    pl_dense_at(rec + 1, rec + 1 + m, m, sg, out);
}

void pl_history_free(pl_history *hist)
{
    free(hist->t);
    free(hist->rec);
    hist->t = hist->rec = NULL;
}

void pl_history_drop(pl_history *hist)
{
    if (hist->count > 0)
        hist->count--;
}

/* Q of a step [t, t + h] from x that carries on the last stored step's interpolant: its
 * derivatives re-expanded about t (σ' = a + b σ, a = (t − t_p)/h_p, b = h/h_p), the step's
 * own start taking the place of its value; zero (the start held) when nothing is stored. */
void pl_history_extrapolate(const pl_history *hist, double t, double h, double *Q)
{
    const int64_t m = hist->m, last = hist->count - 1;
    if (last < 0) {
        for (int64_t i = 0; i < 4 * m; i++)
            Q[i] = 0.0;
        return;
    }
    const double *rec = hist->rec + last * (1 + 5 * m), hp = rec[0];
    const double a = (t - hist->t[last]) / hp, b = h / hp;
    static const double binom[5][5] = {{1, 0, 0, 0, 0}, {1, 1, 0, 0, 0}, {1, 2, 1, 0, 0},
                                       {1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};
    double apow[5] = {1.0, a, a * a, a * a * a, a * a * a * a};
    for (int64_t i = 0; i < m; i++) {
        const double *q = rec + 1 + m + 4 * i;
        double bj = 1.0;
        for (int64_t j = 1; j <= 4; j++) {
            bj *= b;
            double acc = 0.0;
            for (int64_t k = j; k <= 4; k++)
                acc += q[k - 1] * binom[k][j] * apow[k - j];
            Q[4 * i + j - 1] = acc * bj;
        }
    }
}
