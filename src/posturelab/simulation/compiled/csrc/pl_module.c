/* The extension module: what Python calls (through ctypes; _binding.py mirrors the structs).
 *
 * pl_run_one integrates one run with its samples; pl_run_batch runs rows [begin, end) of a
 * batch keeping outcomes only, without the GIL (ctypes releases it), so Python threads run
 * chunks in parallel; pl_state_derivative evaluates the right-hand side (for the tests);
 * pl_rotate_value exposes the rotated sines (for the tests); pl_source_hash names the C
 * sources this build came from and pl_source_files lists them (names, comma-separated). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdlib.h>
#include <string.h>
#include "pl.h"

#ifndef PL_SOURCE_HASH
#define PL_SOURCE_HASH "unknown"
#endif
#ifndef PL_SOURCE_FILES
#define PL_SOURCE_FILES ""
#endif

#ifdef _WIN32
#define PL_EXPORT __declspec(dllexport)
#else
#define PL_EXPORT __attribute__((visibility("default")))
#endif

PL_EXPORT const char *pl_source_hash(void) { return PL_SOURCE_HASH; }
PL_EXPORT const char *pl_source_files(void) { return PL_SOURCE_FILES; }

PL_EXPORT int64_t pl_run_one(const pl_run *run, pl_out *out) { return pl_integrate(run, out); }

/* Rows [begin, end) of a batch (pl_batch_row: run r uses level which[r] and its own row of
 * each per-run array). */
PL_EXPORT void pl_run_batch(const pl_batch *b, int64_t begin, int64_t end)
{
    for (int64_t r = begin; r < end; r++) {
        pl_run run;
        pl_out out;
        pl_batch_row(b, r, &run, &out);
        pl_integrate(&run, &out);
    }
}

PL_EXPORT void pl_state_derivative(int64_t n, int64_t p, const double *bp, const double *E,
                                   const double *C, const double *gains, const double *active,
                                   const double *lim, const double *sat, const double *x,
                                   const double *inp, int64_t locked, int64_t general,
                                   double *out, double *tau)
{
    double *tm, *base, *work, *s;
    double **slots[] = {&tm, &base, &work, &s};
    const int64_t sizes[] = {4 * n * n, 3 * n, n * (n + 4), n};
    if (!pl_alloc_block(slots, sizes, 4))
        return;
    memcpy(s, sat, sizeof(double) * n);
    pl_moment_gains(E, C, gains, NULL, active, p, n, tm);
    pl_set_base(x, base, n);
    pl_model md = {n, bp, tm, lim, s, base, work, tau};
    if (general)
        pl_rhs_general(&md, x, out, inp, (int)locked);
    else
        pl_rhs(&md, x, out, inp, (int)locked);
    free(tm);
}

PL_EXPORT void pl_rotate_value(double theta, double theta_b, double s_b, double c_b, double *s,
                               double *c)
{
    pl_rotate(theta, theta_b, s_b, c_b, s, c);
}

static struct PyModuleDef engine_module = {
    PyModuleDef_HEAD_INIT, "_engine",
    "posturelab's compiled simulation engine (C); called through ctypes, see _ctypes.py.",
    -1, NULL, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__engine(void)
{
    return PyModule_Create(&engine_module);
}
