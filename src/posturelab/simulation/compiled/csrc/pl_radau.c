/* Radau IIA of order 5: scipy's Radau (Hairer & Wanner's RADAU5).
 *
 * Simplified Newton iterations with scipy's convergence-rate tests, the Jacobian
 * re-evaluated only when Newton converges slowly, the embedded error estimate with one extra
 * smoothing after a rejection, Gustafsson's predictive step control, and the cubic
 * collocation polynomial as dense output (also the next step's first Newton guess).
 *
 * The Jacobian of [Θ̇, Θ̈] is [[0, I], [P, Q]] (P = ∂Θ̈/∂Θ, Q = ∂Θ̈/∂Θ̇, forward differences),
 * so each Newton system (c·I − Jac) v = r of size 2N reduces to
 * S(c) a = r₂ + (c·I − Q) r₁, b = c·a − r₁, S(c) = c²I − c·Q − P of size N, for the real
 * eigenvalue c = μ_r/h and the complex one (solved as the real 2N×2N system
 * [[Re S, −Im S], [Im S, Re S]]). The inputs rows are (t, t + c1 h, t + c2 h, t + h).
 * Torque feedback filter states Y (m = 2N + P) add the columns R = ∂Θ̈/∂Y and Ẏ's diagonal D
 * (its only dependence on the state; jac's row n): Y's part v_y = r_y/(c − D) first, then
 * r₂ + R v_y in place of r₂. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "pl.h"
#include "pl_radau.h"  /* scipy's constants (generated): NODES, MU_*, E1–E3, P, T, TI */

#define NEWTON_MAXITER 6
#define SQRT_EPS 1.4901161193847656e-08
#define EPS 2.220446049250313e-16

typedef struct {
    int64_t n, m;
    double *Z, *Z0, *W, *F;       /* (3, m) */
    double *jac;                  /* (n + 1, m) acceleration rows, row n: D */
    double *lur; int64_t *pivr;   /* (n, n) real system: its factors, or inverse */
    double *luc; int64_t *pivc;   /* (2n, 2n) complex system, embedded: likewise */
    int closed;                   /* N = 3: closed-form inverses (matrix–vector solves) */
    double *scale, *fr, *fcr, *fci, *tmp, *err, *xt, *s1, *xold, *f0, *fnew;
    double h_lu, h_old, err_old, h_start, t_prev, h_prev, newton_tol;
    int have_sol, current_jac, err_rejected, last_rejected;
    int64_t piv[];                /* (3n): pivr, pivc */
} radau_ws;

static int64_t jacobian(radau_ws *w, const pl_model *md, const double *x, const double *f0,
                        const double *inp, int locked)
{
    const int64_t n = w->n, m = w->m;
    memcpy(w->xt, x, sizeof(double) * m);
    for (int64_t j = 0; j < m; j++) {
        double d = SQRT_EPS * fmax(fabs(x[j]), 1e-2);
        d = (x[j] + d) - x[j];
        w->xt[j] = x[j] + d;
        pl_rhs(md, w->xt, w->s1, inp, locked);
        w->xt[j] = x[j];
        for (int64_t i = 0; i < n; i++)
            w->jac[i * m + j] = (w->s1[n + i] - f0[n + i]) / d;
        w->jac[n * m + j] = j < 2 * n ? 0.0 : (w->s1[j] - f0[j]) / d;
    }
    return m;
}

/* S(c) = c²I − c·Q − P for c = μ_r/h (real) and μ_c/h (complex, as the real 2N × 2N
 * [[Re S, −Im S], [Im S, Re S]]), prepared for solves: inverted in closed form for N = 3
 * (the cyclic cofactor formula), LU-factored otherwise */
static void factor(radau_ws *w, double h)
{
    const int64_t n = w->n, m = w->m, n2 = 2 * n;
    const double cr = MU_REAL / h, ccr = MU_CRE / h, cci = MU_CIM / h;
    const double c2r = ccr * ccr - cci * cci, c2i = 2.0 * ccr * cci;
    double sr[9], si[9];
    for (int64_t i = 0; i < n; i++)
        for (int64_t j = 0; j < n; j++) {
            const double p = w->jac[i * m + j], q = w->jac[i * m + n + j];
            const double id = i == j ? 1.0 : 0.0;
            w->lur[i * n + j] = cr * cr * id - cr * q - p;
            const double re = c2r * id - ccr * q - p, im = c2i * id - cci * q;
            if (w->closed) {
                sr[i * 3 + j] = re;
                si[i * 3 + j] = im;
            }
            w->luc[i * n2 + j] = re;
            w->luc[i * n2 + n + j] = -im;
            w->luc[(n + i) * n2 + j] = im;
            w->luc[(n + i) * n2 + n + j] = re;
        }
    if (w->closed) {
        double a[9], ir[9], ii[9];
        memcpy(a, w->lur, sizeof(a));
        pl_inverse3(a, w->lur);
        pl_inverse3_complex(sr, si, ir, ii);
        for (int64_t i = 0; i < 3; i++)
            for (int64_t j = 0; j < 3; j++) {
                w->luc[i * 6 + j] = ir[i * 3 + j];
                w->luc[i * 6 + 3 + j] = -ii[i * 3 + j];
                w->luc[(3 + i) * 6 + j] = ii[i * 3 + j];
                w->luc[(3 + i) * 6 + 3 + j] = ir[i * 3 + j];
            }
    } else {
        pl_lu_factor(w->lur, w->pivr, n);
        pl_lu_factor(w->luc, w->pivc, n2);
    }
    w->h_lu = h;
}

/* b = A⁻¹ b with the prepared matrix: a product with the inverse (N = 3) or triangular
 * solves */
static void prepared_solve(const radau_ws *w, const double *A, const int64_t *piv, double *b,
                           int64_t k)
{
    if (!w->closed) {
        pl_lu_solve(A, piv, b, k);
        return;
    }
    double out[6];
    for (int64_t i = 0; i < k; i++) {
        double s = 0.0;
        for (int64_t j = 0; j < k; j++)
            s += A[i * k + j] * b[j];
        out[i] = s;
    }
    memcpy(b, out, sizeof(double) * k);
}

/* (c·I − Jac) v = r in place, c real: a = S⁻¹(r₂ + c r₁ − Q r₁), rates c·a − r₁ */
static void solve_real(radau_ws *w, double c, double *r)
{
    const int64_t n = w->n, m = w->m;
    for (int64_t j = 2 * n; j < m; j++)
        r[j] /= c - w->jac[n * m + j];
    for (int64_t i = 0; i < n; i++) {
        double s = r[n + i] + c * r[i];
        for (int64_t j = 0; j < n; j++)
            s -= w->jac[i * m + n + j] * r[j];
        for (int64_t j = 2 * n; j < m; j++)
            s += w->jac[i * m + j] * r[j];
        w->tmp[i] = s;
    }
    prepared_solve(w, w->lur, w->pivr, w->tmp, n);
    for (int64_t i = 0; i < n; i++) {
        r[n + i] = c * w->tmp[i] - r[i];
        r[i] = w->tmp[i];
    }
}

/* the same for complex c = (cre, cim) and r = (rr, ri) */
static void solve_complex(radau_ws *w, double cre, double cim, double *rr, double *ri)
{
    const int64_t n = w->n, m = w->m;
    for (int64_t j = 2 * n; j < m; j++) {  /* (rr + i ri)/(cre − D + i cim) */
        const double dr = cre - w->jac[n * m + j], q = dr * dr + cim * cim, a = rr[j];
        rr[j] = (a * dr + ri[j] * cim) / q;
        ri[j] = (ri[j] * dr - a * cim) / q;
    }
    for (int64_t i = 0; i < n; i++) {
        double ur = rr[n + i] + (cre * rr[i] - cim * ri[i]);
        double ui = ri[n + i] + (cre * ri[i] + cim * rr[i]);
        for (int64_t j = 2 * n; j < m; j++) {
            ur += w->jac[i * m + j] * rr[j];
            ui += w->jac[i * m + j] * ri[j];
        }
        for (int64_t j = 0; j < n; j++) {
            const double q = w->jac[i * m + n + j];
            ur -= q * rr[j];
            ui -= q * ri[j];
        }
        w->tmp[i] = ur;
        w->tmp[n + i] = ui;
    }
    prepared_solve(w, w->luc, w->pivc, w->tmp, 2 * n);
    for (int64_t i = 0; i < n; i++) {
        const double ar = w->tmp[i], ai = w->tmp[n + i];
        rr[n + i] = (cre * ar - cim * ai) - rr[i];
        ri[n + i] = (cre * ai + cim * ar) - ri[i];
        rr[i] = ar;
        ri[i] = ai;
    }
}

/* scipy's solve_collocation_system from the guess in Z; returns converged, sets iterations
 * and the rate of convergence (−1 when not measured) */
static int newton(radau_ws *w, const pl_model *md, double h, const double *x, const double *inp,
                  int locked, int64_t *iters, double *rate_out)
{
    const int64_t m = w->m, width = 2 + md->n + md->nf;
    const double cr = MU_REAL / h, ccr = MU_CRE / h, cci = MU_CIM / h;
    double *Z = w->Z, *W = w->W, *F = w->F;
    for (int64_t i = 0; i < m; i++)
        for (int64_t s = 0; s < 3; s++)
            W[s * m + i] = TI[s][0] * Z[i] + TI[s][1] * Z[m + i] + TI[s][2] * Z[2 * m + i];
    double norm_old = -1.0, rate = -1.0;
    int converged = 0;
    *iters = 0;
    for (int64_t k = 0; k < NEWTON_MAXITER; k++) {
        *iters = k + 1;
        for (int64_t s = 0; s < 3; s++) {
            for (int64_t i = 0; i < m; i++)
                w->xt[i] = x[i] + Z[s * m + i];
            pl_rhs(md, w->xt, F + s * m, inp + (s + 1) * width, locked);
        }
        double total = 0.0;
        for (int64_t i = 0; i < 3 * m; i++)
            total += F[i];
        if (!isfinite(total))
            break;
        for (int64_t i = 0; i < m; i++) {
            const double f0 = F[i], f1 = F[m + i], f2 = F[2 * m + i];
            const double w1 = W[m + i], w2 = W[2 * m + i];
            w->fr[i] = (TI[0][0] * f0 + TI[0][1] * f1 + TI[0][2] * f2) - cr * W[i];
            w->fcr[i] = (TI[1][0] * f0 + TI[1][1] * f1 + TI[1][2] * f2) - (ccr * w1 - cci * w2);
            w->fci[i] = (TI[2][0] * f0 + TI[2][1] * f1 + TI[2][2] * f2) - (ccr * w2 + cci * w1);
        }
        solve_real(w, cr, w->fr);
        solve_complex(w, ccr, cci, w->fcr, w->fci);
        double acc = 0.0;
        for (int64_t i = 0; i < m; i++) {
            const double a = w->fr[i] / w->scale[i], b = w->fcr[i] / w->scale[i],
                         c = w->fci[i] / w->scale[i];
            acc += a * a + b * b + c * c;
        }
        const double norm = sqrt(acc / (3.0 * m));
        if (norm_old >= 0.0)
            rate = norm / norm_old;
        if (rate >= 0.0) {
            double power = 1.0;  /* rate^(NEWTON_MAXITER − k) */
            for (int64_t e = k; e < NEWTON_MAXITER; e++)
                power *= rate;
            if (rate >= 1.0 || power / (1.0 - rate) * norm > w->newton_tol)
                break;
        }
        for (int64_t i = 0; i < m; i++) {
            W[i] += w->fr[i];
            W[m + i] += w->fcr[i];
            W[2 * m + i] += w->fci[i];
            const double w0 = W[i], w1 = W[m + i], w2 = W[2 * m + i];
            for (int64_t s = 0; s < 3; s++)
                Z[s * m + i] = T[s][0] * w0 + T[s][1] * w1 + T[s][2] * w2;
        }
        if (norm == 0.0 || (rate >= 0.0 && rate / (1.0 - rate) * norm < w->newton_tol)) {
            converged = 1;
            break;
        }
        norm_old = norm;
    }
    *rate_out = rate;
    return converged;
}

/* the embedded error estimate (μ_r/h·I − Jac)⁻¹ (f0 + Σ e_s Z_s / h) into w->err; its norm */
static double error_norm(radau_ws *w, double h, const double *x, const double *y,
                         const double *f0, double rtol, double atol)
{
    const int64_t m = w->m;
    for (int64_t i = 0; i < m; i++)
        w->err[i] = f0[i] + (E1 * w->Z[i] + E2 * w->Z[m + i] + E3 * w->Z[2 * m + i]) / h;
    solve_real(w, MU_REAL / h, w->err);
    double acc = 0.0;
    for (int64_t i = 0; i < m; i++) {
        const double v = w->err[i] / (atol + rtol * fmax(fabs(x[i]), fabs(y[i])));
        acc += v * v;
    }
    return sqrt(acc / m);
}

/* scipy's predict_factor, except that a previous error of exactly 0 counts as no history */
static double predict(double h, double h_old, double err, double err_old)
{
    double mult = 1.0;
    if (!(err_old <= 0.0 || h_old <= 0.0 || err == 0.0))
        mult = h / h_old * sqrt(sqrt(err_old / err));
    if (err == 0.0)
        return INFINITY;
    return fmin(1.0, mult) / sqrt(sqrt(err));
}

static void radau_start(pl_method *me, const pl_model *md, const double *x, const double *inp,
                        int locked, double rtol, int64_t *evals)
{
    radau_ws *w = me->ws;
    *evals += jacobian(w, md, x, w->f0, inp, locked);
    w->current_jac = 1;
    w->have_sol = 0;
    w->err_rejected = 0;
    w->last_rejected = 0;
    w->h_lu = w->h_old = w->err_old = -1.0;
    w->newton_tol = fmax(10.0 * EPS / rtol, fmin(0.03, sqrt(rtol)));
}

static void radau_capped(pl_method *me)
{
    radau_ws *w = me->ws;
    w->h_old = w->err_old = -1.0;  /* a capped step forgets the step-size history (scipy) */
}

static int radau_attempt(pl_method *me, const pl_model *md, double t, double h,
                         const double *x, double *y, double *Q, const double *inp, double rtol,
                         double atol, int locked, double *h_next, int64_t *evals)
{
    radau_ws *w = me->ws;
    const int64_t m = w->m, width = 2 + md->n + md->nf;
    if (!w->last_rejected)
        w->h_start = h;
    if (h != w->h_lu)
        factor(w, h);
    memset(w->Z0, 0, sizeof(double) * 3 * m);  /* first guess: zero, or after a kept step */
    for (int64_t s = 0; w->have_sol && s < 3; s++) {  /* the last collocation polynomial */
        const double sg = (t + NODES[s + 1] * h - w->t_prev) / w->h_prev;
        for (int64_t i = 0; i < m; i++) {
            const double *q = Q + 4 * i;
            w->Z0[s * m + i] = w->xold[i] + sg * (q[0] + sg * (q[1] + sg * q[2])) - x[i];
        }
    }
    for (int64_t i = 0; i < m; i++)
        w->scale[i] = atol + fabs(x[i]) * rtol;
    int converged;
    int64_t n_iter;
    double rate;
    for (;;) {
        memcpy(w->Z, w->Z0, sizeof(double) * 3 * m);
        converged = newton(w, md, h, x, inp, locked, &n_iter, &rate);
        *evals += 3 * n_iter;
        if (converged || w->current_jac)
            break;
        *evals += jacobian(w, md, x, w->f0, inp, locked);
        w->current_jac = 1;
        factor(w, h);
    }
    if (!converged) {
        w->last_rejected = 1;  /* a retry of the same step (keeps h_start) */
        *h_next = 0.5 * h;
        return 0;
    }
    for (int64_t i = 0; i < m; i++)
        y[i] = x[i] + w->Z[2 * m + i];
    double err = error_norm(w, h, x, y, w->f0, rtol, atol);
    const double safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter);
    if (w->err_rejected && err > 1.0) {  /* one more smoothing after a rejection */
        for (int64_t i = 0; i < m; i++)
            w->xt[i] = x[i] + w->err[i];
        pl_rhs(md, w->xt, w->s1, inp, locked);
        *evals += 1;
        err = error_norm(w, h, x, y, w->s1, rtol, atol);
    }
    if (!(err <= 1.0)) {
        *h_next = err == err ? h * fmax(0.2, safety * predict(h, w->h_old, err, w->err_old))
                             : 0.2 * h;
        w->last_rejected = 1;
        w->err_rejected = 1;
        return 0;
    }
    const int recompute_jac = n_iter > 2 && rate > 1e-3;
    double fac = fmin(10.0, safety * predict(h, w->h_old, err, w->err_old));
    if (!recompute_jac && fac < 1.2)
        fac = 1.0;
    pl_rhs(md, y, w->fnew, inp + 3 * width, locked);
    *evals += 1;
    if (recompute_jac) {
        *evals += jacobian(w, md, y, w->fnew, inp + 3 * width, locked);
        w->current_jac = 1;
        w->h_lu = -1.0;
    } else {
        w->current_jac = 0;
    }
    w->h_old = w->h_start;
    w->err_old = err;
    w->last_rejected = 0;
    w->err_rejected = 0;
    for (int64_t i = 0; i < m; i++) {
        const double z0 = w->Z[i], z1 = w->Z[m + i], z2 = w->Z[2 * m + i];
        for (int64_t k = 0; k < 3; k++)
            Q[4 * i + k] = (z0 * P[0][k] + z1 * P[1][k]) + z2 * P[2][k];
        Q[4 * i + 3] = 0.0;
        w->xold[i] = x[i];
    }
    w->have_sol = 1;
    w->t_prev = t;
    w->h_prev = h;
    *h_next = h * fac;
    return 1;
}

int pl_radau_init(pl_method *me, int64_t n, int64_t m)
{
    radau_ws *w = calloc(1, sizeof(radau_ws) + sizeof(int64_t) * 3 * n);
    *me = (pl_method){.n_nodes = 4, .order = 3, .nodes = NODES, .ws = w, .start = radau_start,
                      .capped = radau_capped, .attempt = radau_attempt};
    if (!w)
        return 0;
    w->n = n;
    w->m = m;
    w->closed = n == 3;
    double **slots[] = {&w->Z, &w->Z0, &w->W, &w->F, &w->jac, &w->lur, &w->luc, &w->scale,
                        &w->fr, &w->fcr, &w->fci, &w->tmp, &w->err, &w->xt, &w->s1, &w->xold,
                        &w->f0, &w->fnew};
    const int64_t sizes[] = {3 * m, 3 * m, 3 * m, 3 * m, (n + 1) * m, n * n, 4 * n * n, m, m, m,
                             m, m, m, m, m, m, m, m};
    const int ok = pl_alloc_block(slots, sizes, sizeof(sizes) / sizeof(sizes[0]));
    w->pivr = w->piv;
    w->pivc = w->piv + n;
    me->arrays = w->Z;
    me->f0 = w->f0;
    me->f_end = w->fnew;
    return ok;
}
