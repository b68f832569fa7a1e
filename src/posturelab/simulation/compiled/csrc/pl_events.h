/* Events inside a run (pl_events.c). */
#ifndef PL_EVENTS_H
#define PL_EVENTS_H

#include "pl.h"

/* What an event function needs besides (t, y). */
typedef struct {
    const pl_model *md;
    const double *E, *dp, *fpar, *before, *ev_offset;
    const pl_history *hist;
    double delay;
    const double *tp, *tilt_gain;          /* packed tilt, (4, n) joint gains on it */
    double tilt_depth;                     /* tilt axis below the ankle [m] */
    const double *mp;                      /* packed motor noise */
    const double *gains;                   /* (4, p) the run's pair gains */
    int64_t p;
    double *sc_out, *sc_inp, *sc_x, *ys;   /* scratch (2n), (2 + n), (2n), (2n) */
} pl_ctx;

void pl_inputs_at(const pl_ctx *cx, double t, double *out);
double pl_event_value(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t,
                      const double *y, int locked);
double pl_event_root(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t0,
                     double t1, double g0, double g1, const double *x, const double *Q,
                     double h, int locked);

#endif
