/* The equation of motion, written once for N links (posturelab.model.dynamics states it in
 * numpy; the tests compare the two at random states).
 *
 *   J(Θ)Θ̈ + B(Θ,Θ̇)Θ̇ − (g + ÿ_d)G(Θ) + ẍ_d H(Θ) = U,   U_i = τ_{i+1} − τ_i,
 *
 * τ the net muscle moments at the joints: τ = T_K Θ + T_L Θ̇ + τ_delayed (T_K = Cᵀ diag(k_d·active) E,
 * pl_moment_gains), or ±limit_j while joint j saturates. inp = (ẍ_d, ÿ_d, τ_delayed[0..N-1]).
 * pl_rhs dispatches to the straight-line code generated for N = 1, 2, 3 (pl_rhs_small.c,
 * written by _codegen.py from the same formulas) or to pl_rhs_general. */
#include <math.h>
#include "pl.h"

void pl_set_base(const double *x, double *base, int64_t n)
{
    for (int64_t i = 0; i < n; i++) {
        base[i] = x[i];
        base[n + i] = sin(x[i]);
        base[2 * n + i] = cos(x[i]);
    }
}

void pl_rhs_general(const pl_model *md, const double *x, double *out, const double *inp,
                    int locked)
{
    const int64_t n = md->n, oc = 2 * n, w = n + 4;
    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + n * n;
    double *work = md->work, *tau = md->tau;
    const double ax = inp[0], ga = bp[oc + n * n] + inp[1];
    for (int64_t i = 0; i < n; i++)
        pl_rotate(x[i], md->base[i], md->base[n + i], md->base[2 * n + i],
                  &work[i * w + n + 2], &work[i * w + n + 3]);
    for (int64_t j = 0; j < n; j++) {
        double t = inp[2 + j];
        for (int64_t k = 0; k < n; k++)
            t += tk[j * n + k] * x[k] + tl[j * n + k] * x[n + k];
        if (md->sat[j] != 0.0)
            t = md->sat[j] * md->lim[j];
        tau[j] = t;
    }
    for (int64_t i = 0; i < n; i++) {
        const double si = work[i * w + n + 2], ci = work[i * w + n + 3];
        double r = (i + 1 < n ? tau[i + 1] : 0.0) - tau[i] + bp[i] * (ga * si - ax * ci);
        for (int64_t j = 0; j < n; j++) {
            if (j == i) {
                work[i * w + j] = bp[n + i];
                continue;
            }
            const double sj = work[j * w + n + 2], cj = work[j * w + n + 3];
            const double cij = bp[oc + i * n + j];
            r -= cij * (si * cj - ci * sj) * x[n + j] * x[n + j];
            work[i * w + j] = cij * (ci * cj + si * sj);
        }
        work[i * w + n] = r;
        work[i * w + n + 1] = 0.0;
    }
    int64_t ncol = 1;
    if (locked) {
        work[n + 1] = -1.0;
        work[w + n + 1] = 1.0;
        ncol = 2;
    }
    pl_solve_into(work, n, ncol, w);
    if (locked) {
        const double lam = (work[w + n] - work[n]) / (work[w + n + 1] - work[n + 1]);
        for (int64_t i = 0; i < n; i++)
            work[i * w + n] -= work[i * w + n + 1] * lam;
    }
    for (int64_t i = 0; i < n; i++) {
        out[i] = x[n + i];
        out[n + i] = work[i * w + n];
    }
}

void pl_rhs(const pl_model *md, const double *x, double *out, const double *inp, int locked)
{
    switch (md->n) {
    case 3: pl_rhs3(md, x, out, inp, locked); break;
    case 2: pl_rhs2(md, x, out, inp, locked); break;
    case 1: pl_rhs1(md, x, out, inp, locked); break;
    default: pl_rhs_general(md, x, out, inp, locked);
    }
}

void pl_moment_gains(const double *E, const double *C, const double *kd, const double *ld,
                     const double *active, int64_t p, int64_t n, double *tk, double *tl)
{
    for (int64_t j = 0; j < n; j++)
        for (int64_t k = 0; k < n; k++) {
            double sk = 0.0, sl = 0.0;
            for (int64_t q = 0; q < p; q++) {
                const double wgt = C[q * n + j] * E[q * n + k] * active[q];
                sk += wgt * kd[q];
                sl += wgt * ld[q];
            }
            tk[j * n + k] = sk;
            tl[j * n + k] = sl;
        }
}

/* Plastic impact onto the knee constraint, in place on x's rates:
 * Θ̇ − J⁻¹C (C·Θ̇)/(C·J⁻¹C), C = (−1, 1, 0, …). work holds at least n·(n + 1). */
void pl_project_velocity(double *x, const double *bp, double *work, int64_t n)
{
    const int64_t s = n + 1;
    for (int64_t i = 0; i < n; i++) {
        for (int64_t j = 0; j < n; j++)
            work[i * s + j] = i == j ? bp[n + i] : bp[2 * n + i * n + j] * cos(x[j] - x[i]);
        work[i * s + n] = 0.0;
    }
    work[n] = -1.0;
    work[s + n] = 1.0;
    pl_solve_into(work, n, 1, s);
    const double lam = (x[n + 1] - x[n]) / (work[s + n] - work[n]);
    for (int64_t i = 0; i < n; i++)
        x[n + i] -= work[i * s + n] * lam;
}
