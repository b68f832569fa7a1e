/* Small dense linear algebra: Gaussian elimination and LU with partial pivoting, in place,
 * row-major, for any N; the search of a sorted array; the work arrays of a run in one block. */
#include <math.h>
#include <stdlib.h>
#include "pl.h"

/* One zeroed block for a set of work arrays: *slots[k] gets sizes[k] doubles of it. The first
 * owns the block (free it to free them all); all are NULL when there is no memory (returns 0). */
int pl_alloc_block(double **const *slots, const int64_t *sizes, int64_t count)
{
    int64_t total = 0;
    for (int64_t k = 0; k < count; k++)
        total += sizes[k];
    double *next = calloc(total > 0 ? total : 1, sizeof(double));
    for (int64_t k = 0; k < count; k++) {
        *slots[k] = next;
        next = next ? next + sizes[k] : NULL;
    }
    return *slots[0] != NULL;
}

/* the largest k in [lo, hi) with x[k] <= t, by bisection (x increasing; lo if none) */
int64_t pl_interval_of(const double *x, int64_t lo, int64_t hi, double t)
{
    while (hi - lo > 1) {
        const int64_t mid = (lo + hi) >> 1;
        if (x[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* Gaussian elimination on the augmented (n, n + ncol) matrix M (rows ``stride`` apart); the
 * solutions replace the last ncol columns. */
void pl_solve_into(double *M, int64_t n, int64_t ncol, int64_t stride)
{
    const int64_t w = n + ncol;
    for (int64_t k = 0; k < n; k++) {
        int64_t piv = k;
        double big = fabs(M[k * stride + k]);
        for (int64_t i = k + 1; i < n; i++)
            if (fabs(M[i * stride + k]) > big) {
                big = fabs(M[i * stride + k]);
                piv = i;
            }
        if (piv != k)
            for (int64_t j = k; j < w; j++) {
                double tmp = M[k * stride + j];
                M[k * stride + j] = M[piv * stride + j];
                M[piv * stride + j] = tmp;
            }
        const double inv = 1.0 / M[k * stride + k];
        for (int64_t i = k + 1; i < n; i++) {
            const double f = M[i * stride + k] * inv;
            if (f != 0.0)
                for (int64_t j = k + 1; j < w; j++)
                    M[i * stride + j] -= f * M[k * stride + j];
        }
    }
    for (int64_t c = n; c < w; c++)
        for (int64_t i = n - 1; i >= 0; i--) {
            double s = M[i * stride + c];
            for (int64_t j = i + 1; j < n; j++)
                s -= M[i * stride + j] * M[j * stride + c];
            M[i * stride + c] = s / M[i * stride + i];
        }
}

/* LU factorisation with partial pivoting of the (n, n) A in place; whole rows are swapped,
 * as LAPACK's getrf does. */
void pl_lu_factor(double *A, int64_t *piv, int64_t n)
{
    for (int64_t k = 0; k < n; k++) {
        int64_t p = k;
        double big = fabs(A[k * n + k]);
        for (int64_t i = k + 1; i < n; i++) {
            double v = fabs(A[i * n + k]);
            if (v > big) {
                big = v;
                p = i;
            }
        }
        piv[k] = p;
        if (p != k)
            for (int64_t j = 0; j < n; j++) {
                double tmp = A[k * n + j];
                A[k * n + j] = A[p * n + j];
                A[p * n + j] = tmp;
            }
        const double inv = 1.0 / A[k * n + k];
        for (int64_t i = k + 1; i < n; i++) {
            A[i * n + k] *= inv;
            const double f = A[i * n + k];
            for (int64_t j = k + 1; j < n; j++)
                A[i * n + j] -= f * A[k * n + j];
        }
    }
}

/* Solve with the factors of pl_lu_factor, b in place. */
void pl_lu_solve(const double *A, const int64_t *piv, double *b, int64_t n)
{
    for (int64_t k = 0; k < n; k++) {
        int64_t p = piv[k];
        if (p != k) {
            double tmp = b[k];
            b[k] = b[p];
            b[p] = tmp;
        }
    }
    for (int64_t i = 0; i < n; i++) {
        double s = b[i];
        for (int64_t j = 0; j < i; j++)
            s -= A[i * n + j] * b[j];
        b[i] = s;
    }
    for (int64_t i = n - 1; i >= 0; i--) {
        double s = b[i];
        for (int64_t j = i + 1; j < n; j++)
            s -= A[i * n + j] * b[j];
        b[i] = s / A[i * n + i];
    }
}

/* The inverse of a 3×3 matrix (row-major) by its cofactors, in their cyclic form:
 * inv[i][j] = (a[j+1][i+1] a[j+2][i+2] − a[j+1][i+2] a[j+2][i+1]) / det, indices mod 3. */
void pl_inverse3(const double *a, double *out)
{
    double cof[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            const int j1 = (j + 1) % 3, j2 = (j + 2) % 3, i1 = (i + 1) % 3, i2 = (i + 2) % 3;
            cof[i * 3 + j] = a[j1 * 3 + i1] * a[j2 * 3 + i2] - a[j1 * 3 + i2] * a[j2 * 3 + i1];
        }
    const double inv = 1.0 / (a[0] * cof[0] + a[1] * cof[3] + a[2] * cof[6]);
    for (int k = 0; k < 9; k++)
        out[k] = cof[k] * inv;
}

/* The same for a complex matrix ar + i·ai, into outr + i·outi. */
void pl_inverse3_complex(const double *ar, const double *ai, double *outr, double *outi)
{
    double cr[9], ci[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            const int p = ((j + 1) % 3) * 3 + (i + 1) % 3, q = ((j + 2) % 3) * 3 + (i + 2) % 3;
            const int u = ((j + 1) % 3) * 3 + (i + 2) % 3, v = ((j + 2) % 3) * 3 + (i + 1) % 3;
            cr[i * 3 + j] = (ar[p] * ar[q] - ai[p] * ai[q]) - (ar[u] * ar[v] - ai[u] * ai[v]);
            ci[i * 3 + j] = (ar[p] * ai[q] + ai[p] * ar[q]) - (ar[u] * ai[v] + ai[u] * ar[v]);
        }
    double dr = 0.0, di = 0.0;
    for (int k = 0; k < 3; k++) {
        dr += ar[k] * cr[k * 3] - ai[k] * ci[k * 3];
        di += ar[k] * ci[k * 3] + ai[k] * cr[k * 3];
    }
    const double d2 = dr * dr + di * di, invr = dr / d2, invi = -di / d2;
    for (int k = 0; k < 9; k++) {
        outr[k] = cr[k] * invr - ci[k] * invi;
        outi[k] = cr[k] * invi + ci[k] * invr;
    }
}
