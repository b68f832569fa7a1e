/* The past of a run with delayed feedback: every kept step's dense output.
 *
 * Before t = 0 the past is the state before the run; after it, the interpolant of the step
 * that covered that time. Steps are at most τ long, so the past a step needs is complete
 * when the step starts, except with a very short delay (pl_driver.c: overlapping steps):
 * there the step being tried is stored too, first as the last step's interpolant carried
 * on (pl_history_extrapolate), then as its own, and taken out again if it is rejected.
 * Arrays double when full. */
#include <stdlib.h>
#include <string.h>
#include "pl.h"

void pl_dense_at(const double *restrict x, const double *restrict Q, int64_t m, double t0,
                 double h, double t, double *restrict out)
{
    const double s = (t - t0) / h;
    for (int64_t i = 0; i < m; i++) {
        const double *q = Q + 4 * i;
        out[i] = x[i] + s * (q[0] + s * (q[1] + s * (q[2] + s * q[3])));
    }
}

int pl_history_init(pl_history *hist, int64_t m, int64_t cap)
{
    hist->m = m;
    hist->count = 0;
    hist->cap = cap;
    hist->t = malloc(sizeof(double) * cap);
    hist->h = malloc(sizeof(double) * cap);
    hist->x = malloc(sizeof(double) * cap * m);
    hist->q = malloc(sizeof(double) * cap * m * 4);
    return hist->t && hist->h && hist->x && hist->q;
}

static int grow(double **p, size_t size)
{
    double *q = realloc(*p, size);
    if (!q)
        return 0;
    *p = q;
    return 1;
}

int pl_history_add(pl_history *hist, double t, double h, const double *x, const double *Q)
{
    const int64_t m = hist->m;
    if (hist->count == hist->cap) {
        const int64_t cap = 2 * hist->cap;
        if (!grow(&hist->t, sizeof(double) * cap) || !grow(&hist->h, sizeof(double) * cap)
            || !grow(&hist->x, sizeof(double) * cap * m)
            || !grow(&hist->q, sizeof(double) * cap * m * 4))
            return 0;
        hist->cap = cap;
    }
    const int64_t k = hist->count++;
    hist->t[k] = t;
    hist->h[k] = h;
    memcpy(hist->x + k * m, x, sizeof(double) * m);
    memcpy(hist->q + k * m * 4, Q, sizeof(double) * m * 4);
    return 1;
}

void pl_history_at(const pl_history *hist, const double *before, double s, double *out)
{
    const int64_t m = hist->m, n = hist->count;
    if (s < 0.0 || n == 0) {
        memcpy(out, before, sizeof(double) * m);
        return;
    }
    int64_t lo = 0, hi = n - 1;
    if (s >= hist->t[hi])
        lo = hi;
    else
        while (hi - lo > 1) {
            int64_t mid = (lo + hi) >> 1;
            if (hist->t[mid] <= s)
                lo = mid;
            else
                hi = mid;
        }
    double sg = (s - hist->t[lo]) / hist->h[lo];
    if (sg > 1.0)
        sg = 1.0;
    const double *x = hist->x + lo * m, *q = hist->q + lo * m * 4;
    for (int64_t i = 0; i < m; i++)
        out[i] = x[i] + sg * (q[4 * i] + sg * (q[4 * i + 1] + sg * (q[4 * i + 2]
                                                                  + sg * q[4 * i + 3])));
}

void pl_history_free(pl_history *hist)
{
    free(hist->t);
    free(hist->h);
    free(hist->x);
    free(hist->q);
    hist->t = hist->h = hist->x = hist->q = NULL;
}

void pl_history_drop(pl_history *hist)
{
    if (hist->count > 0)
        hist->count--;
}

/* Q of a step [t, t + h] from x that carries on the last stored step's interpolant: its
 * derivatives re-expanded about t (σ' = a + b σ, a = (t − t_p)/h_p, b = h/h_p), its value
 * replaced by x; zero (x held) when nothing is stored. */
void pl_history_extrapolate(const pl_history *hist, double t, double h, const double *x,
                            double *Q)
{
    const int64_t m = hist->m, last = hist->count - 1;
    (void)x;
    if (last < 0) {
        for (int64_t i = 0; i < 4 * m; i++)
            Q[i] = 0.0;
        return;
    }
    const double a = (t - hist->t[last]) / hist->h[last], b = h / hist->h[last];
    static const double binom[5][5] = {{1, 0, 0, 0, 0}, {1, 1, 0, 0, 0}, {1, 2, 1, 0, 0},
                                       {1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};
    double apow[5] = {1.0, a, a * a, a * a * a, a * a * a * a};
    for (int64_t i = 0; i < m; i++) {
        const double *q = hist->q + (last * m + i) * 4;
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
