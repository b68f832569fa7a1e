/* The roots of event functions (the table of kinds, directions, offsets and the order of a
 * segment's events is posturelab.model.events: Python passes it as numbers; the values,
 * pl_event_value, are generated into pl_model.c from posturelab.model.switched).
 *
 * Events are located on the dense output of the step in which they occur: Illinois regula
 * falsi (bisection when a secant leaves the bracket) to the tolerance of scipy's brentq in
 * solve_ivp, 4 ε (1 + |t|). */
#include <math.h>
#include "pl.h"

#define EPS 2.220446049250313e-16

double pl_event_root(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t0,
                     double t1, double g0, double g1, const double *x, const double *Q,
                     double h, int locked)
{
    if (g0 == 0.0)
        return t0;
    if (g1 == 0.0)
        return t1;
    double ta = t0, tb = t1, ga = g0, gb = g1;
    int last = 0;
    for (int it = 0; it < 200; it++) {
        if (fabs(tb - ta) <= 4.0 * EPS + 4.0 * EPS * fabs(tb))
            break;
        double tc = (ta * gb - tb * ga) / (gb - ga);
        if (!(tc > fmin(ta, tb) && tc < fmax(ta, tb)))
            tc = 0.5 * (ta + tb);
        pl_dense_at(x, Q, 2 * cx->md->n + cx->md->nf, (tc - t0) / h, cx->ys);
        const double gc = pl_event_value(cx, kind, idx, side, tc, cx->ys, locked);
        if (gc == 0.0)
            return tc;
        if ((gc > 0.0) == (gb > 0.0)) {
            tb = tc;
            gb = gc;
            if (last == -1)
                ga *= 0.5;
            last = -1;
        } else {
            ta = tc;
            ga = gc;
            if (last == 1)
                gb *= 0.5;
            last = 1;
        }
    }
    return 0.5 * (ta + tb);
}
