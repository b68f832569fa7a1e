/* Small dense linear algebra: Gaussian elimination and LU with partial pivoting, in place,
 * row-major, for any N. */
#include <math.h>
#include "pl.h"

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
