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

/* A batch: run r uses level which[r] (its start state, the state before, its disturbance,
 * options and pairs acting at the start) and its own gains, limits, delay and saturation. */
typedef struct {
    pl_run base;
    const int64_t *which;
    const double *x0_all, *before_all, *dp_all;
    int64_t dp_stride;
    const int64_t *ipar_all;
    const double *active0_all, *gains_all, *lim_all, *delay_all, *sat0_all;
    const int64_t *method_all;   /* per run: METHOD_RADAU or METHOD_EXPLICIT (the tableau) */
    double *results, *peaks, *finals;
    const double *tilt_gain_all, *tilt_pair_gain_all; /* per run (4, n), (4, p) */
    const double *visual_gain_all, *visual_pair_gain_all; /* the same on the visual scene */
} pl_batch;

PL_EXPORT void pl_run_batch(const pl_batch *b, int64_t begin, int64_t end)
{
    const int64_t n = b->base.n, m = 2 * n, p = b->base.p;
    for (int64_t r = begin; r < end; r++) {
        pl_run run = b->base;
        const int64_t lv = b->which[r];
        run.x0 = b->x0_all + lv * m;
        run.before = b->before_all + lv * m;
        run.dp = b->dp_all + lv * b->dp_stride;
        run.ipar = b->ipar_all + lv * N_IPAR;
        run.active0 = b->active0_all + lv * p;
        run.gains = b->gains_all + r * 4 * p;
        run.lim = b->lim_all + r * n;
        run.delay = b->delay_all[r];
        run.sat0 = b->sat0_all + r * n;
        run.method = b->method_all[r];
        run.tilt_gain = b->tilt_gain_all + r * 4 * n;
        run.tilt_pair_gain = b->tilt_pair_gain_all + r * 4 * p;
        run.visual_gain = b->visual_gain_all + r * 4 * n;
        run.visual_pair_gain = b->visual_pair_gain_all + r * 4 * p;
        pl_out out = {NULL, NULL, NULL, NULL, 0, b->peaks + r * n, b->finals + r * m,
                      b->results + r * N_RESULT};
        pl_integrate(&run, &out);
    }
}

PL_EXPORT void pl_state_derivative(int64_t n, int64_t p, const double *bp, const double *E,
                                   const double *C, const double *gains, const double *active,
                                   const double *lim, const double *sat, const double *x,
                                   const double *inp, int64_t locked, int64_t general,
                                   double *out, double *tau)
{
    double *tm = malloc(sizeof(double) * 4 * n * n), *base = malloc(sizeof(double) * 3 * n);
    double *work = malloc(sizeof(double) * n * (n + 4)), *s = malloc(sizeof(double) * n);
    if (!tm || !base || !work || !s) {
        free(tm);
        free(base);
        free(work);
        free(s);
        return;
    }
    memcpy(s, sat, sizeof(double) * n);
    pl_moment_gains(E, C, gains, gains + p, active, p, n, tm, tm + n * n);
    pl_moment_gains(E, C, gains + 2 * p, gains + 3 * p, active, p, n, tm + 2 * n * n,
                    tm + 3 * n * n);
    pl_set_base(x, base, n);
    pl_model md = {n, bp, tm, lim, s, base, work, tau};
    if (general)
        pl_rhs_general(&md, x, out, inp, (int)locked);
    else
        pl_rhs(&md, x, out, inp, (int)locked);
    free(tm);
    free(base);
    free(work);
    free(s);
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
    pl_radau_constants();
    return PyModule_Create(&engine_module);
}
