/* Events inside a run (pl_events.c). */
#ifndef PL_EVENTS_H
#define PL_EVENTS_H

#include "pl.h"

/* pl_ctx, pl_inputs_at and pl_event_value are generated (pl_model.h, pl_model.c). */
double pl_event_root(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t0,
                     double t1, double g0, double g1, const double *x, const double *Q,
                     double h, int locked);

#endif
