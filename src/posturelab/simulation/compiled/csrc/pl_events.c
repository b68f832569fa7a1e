/* Event functions and their roots (the table of kinds, directions, offsets and the order of
 * a segment's events is posturelab.model.events: Python passes it as numbers).
 *
 * Events are located on the dense output of the step in which they occur: Illinois regula
 * falsi (bisection when a secant leaves the bracket) to the tolerance of scipy's brentq in
 * solve_ivp, 4 ε (1 + |t|). */
#include <math.h>
#include "pl.h"
#include "pl_events.h"

#define EPS 2.220446049250313e-16

void pl_inputs_at(const pl_ctx *cx, double t, double *out)
{
    const int64_t n = cx->md->n;
    const double *tm = cx->md->tm;
    double ax = 0.0, ay = 0.0;
    if (cx->dp[0] > 0.0)
        pl_platform_acceleration(t, cx->dp, &ax, &ay);
    double a = 0.0, ad = 0.0, add = 0.0;
    if (cx->tp[0] > 0.0)
        pl_tilt(t, cx->tp, &a, &ad, &add);
    if (cx->tilt_depth > 0.0) {  /* the ankle moves on a circle about the tilt axis */
        const double c = cos(a), s = sin(a), h = cx->tilt_depth;
        ax -= h * (add * c - ad * ad * s);
        ay -= h * (add * s + ad * ad * c);
    }
    out[0] = ax;
    out[1] = ay;
    if (cx->delay > 0.0) {
        pl_history_at(cx->hist, cx->before, t - cx->delay, cx->sc_x);
        for (int64_t j = 0; j < n; j++) {
            double s = 0.0;
            for (int64_t k = 0; k < n; k++)
                s += tm[2 * n * n + j * n + k] * cx->sc_x[k]
                     + tm[3 * n * n + j * n + k] * cx->sc_x[n + k];
            out[2 + j] = s;
        }
    } else {
        for (int64_t j = 0; j < n; j++)
            out[2 + j] = 0.0;
    }
    if (cx->tp[0] > 0.0) {  /* the tilt's moments: now, and as the delayed part felt it */
        const double *g = cx->tilt_gain;
        for (int64_t j = 0; j < n; j++)
            out[2 + j] += g[j] * a + g[n + j] * ad;
        if (cx->delay > 0.0) {
            pl_tilt(t - cx->delay, cx->tp, &a, &ad, &add);
            for (int64_t j = 0; j < n; j++)
                out[2 + j] += g[2 * n + j] * a + g[3 * n + j] * ad;
        }
    }
    if (cx->mp[0] > 0.0)  /* the motor noise, on the motor command */
        pl_motor_noise_add(t, cx->mp, n, out + 2);
}

double pl_event_value(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t,
                      const double *y, int locked)
{
    const pl_model *md = cx->md;
    const int64_t n = md->n;
    const double *bp = md->bp, *fpar = cx->fpar;
    double g;
    switch (kind) {
    case EV_LINK_ANGLE:
        g = fpar[F_MAX_ANGLE] - fabs(y[idx]);
        break;
    case EV_COG_TOE:
    case EV_COG_HEEL: {
        double xc = 0.0;
        for (int64_t i = 0; i < n; i++)
            xc += bp[i] * sin(y[i]);
        xc /= bp[2 * n + n * n + 1];
        g = kind == EV_COG_TOE ? fpar[F_TOE] - xc : xc - fpar[F_HEEL];
        break;
    }
    case EV_PAIR_SLACKENS:
    case EV_PAIR_ENGAGES:
    case EV_PAIR_PUSHES:
    case EV_PAIR_PULLS: {  /* the stretch, or the torque k s + l ṡ, of the fed-back state */
        const double *s = y;
        if (cx->delay > 0.0) {
            pl_history_at(cx->hist, cx->before, t - cx->delay, cx->sc_x);
            s = cx->sc_x;
        }
        double st = 0.0, sd = 0.0;
        for (int64_t j = 0; j < n; j++) {
            st += cx->E[idx * n + j] * s[j];
            sd += cx->E[idx * n + j] * s[n + j];
        }
        if (kind == EV_PAIR_PUSHES || kind == EV_PAIR_PULLS) {
            const double *gn = cx->gains;
            const int64_t p = cx->p;
            const double k = gn[idx] + gn[2 * p + idx];
            g = k * st + (gn[p + idx] + gn[3 * p + idx]) * sd;
            if (kind == EV_PAIR_PULLS)  /* stretched, and pulling */
                g = fmin(g, (k > 0.0 ? k : 1.0) * st);
        } else {
            g = st;
        }
        break;
    }
    case EV_KNEE_HITS_STOP:
        g = (y[1] - y[0]) - fpar[F_STOP_ANGLE];
        break;
    default:
        pl_inputs_at(cx, t, cx->sc_inp);
        if (kind == EV_SATURATES || kind == EV_LETS_GO) {
            const double *tk = md->tm, *tl = md->tm + n * n;
            double tau = cx->sc_inp[2 + idx];
            for (int64_t k = 0; k < n; k++)
                tau += tk[idx * n + k] * y[k] + tl[idx * n + k] * y[n + k];
            g = side * tau - md->lim[idx];
        } else if (kind == EV_KNEE_LEAVES_STOP) {
            pl_rhs(md, y, cx->sc_out, cx->sc_inp, 0);
            g = cx->sc_out[n + 1] - cx->sc_out[n];
        } else {  /* centre of pressure x_p = τ_ankle / F_y, in moment form: toe F_y − τ_ankle
                   * and τ_ankle − heel F_y, of the sign of toe − x_p and x_p − heel while the
                   * foot is pressed (F_y > 0) and continuous where F_y passes 0 */
            pl_rhs(md, y, cx->sc_out, cx->sc_inp, locked);
            double fy = bp[2 * n + n * n + 1] * (bp[2 * n + n * n] + cx->sc_inp[1]);
            for (int64_t i = 0; i < n; i++)
                fy -= bp[i] * (cx->sc_out[n + i] * sin(y[i]) + y[n + i] * y[n + i] * cos(y[i]));
            g = kind == EV_COP_TOE ? fpar[F_TOE] * fy - md->tau[0]
                                   : md->tau[0] - fpar[F_HEEL] * fy;
        }
    }
    return g + cx->ev_offset[kind];
}

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
        pl_dense_at(x, Q, 2 * cx->md->n, t0, h, tc, cx->ys);
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
