/* The integration loop of one run, written once for every integrator (pl_method: the
 * explicit pairs of pl_explicit.c or Radau, pl_radau.c).
 *
 * Events sit outside every method: after each kept step the loop evaluates the segment's
 * event functions at the step's end, finds the earliest root on its dense output, and either
 * ends the run (a fall) or applies the switch and restarts the integrator, as the reference
 * engine does. With a feedback delay τ each kept step's dense output goes to the history,
 * the inputs of every stage include the delayed joint moments, steps are at most τ long (or,
 * for a delay below OVERLAP_BELOW, overlap their own past) and land on kτ (k = 1 …
 * delay_multiples). Steps also land on every breakpoint and on its echoes kτ later, and on
 * the echoes of every switch: the inputs are taken just before a stop at a step's end and
 * just after it at the next step's start. The state is [Θ, Θ̇] or, with torque feedback,
 * [Θ, Θ̇, Y] (m = 2N + P): the filters start at rest and a switch leaves them as they are, the
 * history keeps [Θ, Θ̇] and the samples all m components. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "pl.h"

#define EPS 2.220446049250313e-16
#define SAMPLE_BLOCK 64  /* samples evaluated together */
#define CLOCK_EVERY 256  /* attempted steps between looks at the clock (a time limit) */
/* Overlapping steps: below this delay [s] a step may be longer than τ (otherwise it is at
 * most τ, and the past it needs is computed before it starts). Its delayed states inside
 * itself then come from its own dense output, first the last step's carried on, then its
 * own, iterated until the end state moves by less than OVERLAP_TOL of the tolerance; a step
 * that does not settle within OVERLAP_ITERATIONS tries is halved. */
#define OVERLAP_BELOW 1e-4
#define OVERLAP_TOL 1e-2
#define OVERLAP_ITERATIONS 8

/* Seconds on a clock that only moves forward (wall-clock seconds without one). [s] */
static double wall_seconds(void)
{
#if defined(CLOCK_MONOTONIC)
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) == 0)
        return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#endif
    return (double)time(NULL);
}

/* the run's work arrays: the doubles in one block (pl_alloc_block, owned by tm) */
typedef struct {
    double *tm, *sat, *base, *work, *tau, *active, *x, *y, *Q, *inp, *g_old, *g_new, *sc_out,
        *sc_inp, *sc_x, *ys, *ev_side, *block, *Qg, *yp, *fscr;
    int64_t *ev_kind, *ev_index;
} buffers;

static int alloc_buffers(buffers *b, int64_t n, int64_t nf, int64_t p, int64_t n_nodes,
                         int64_t n_slots)
{
    const int64_t m = 2 * n + nf, cap = n_slots > 0 ? n_slots : 1, width = 2 + n + nf;
    double **slots[] = {&b->tm, &b->sat, &b->base, &b->work, &b->tau, &b->active, &b->x, &b->y,
                        &b->Q, &b->inp, &b->g_old, &b->g_new, &b->ev_side, &b->sc_out,
                        &b->sc_inp, &b->sc_x, &b->ys, &b->block, &b->Qg, &b->yp, &b->fscr};
    const int64_t sizes[] = {4 * n * n, n, 3 * n, n * (n + 4), n, p > 0 ? p : 1, m, m, 4 * m,
                             n_nodes * width, cap, cap, cap, m, width, m, m,
                             m * SAMPLE_BLOCK, 4 * m, m, width};
    const int ok = pl_alloc_block(slots, sizes, sizeof(sizes) / sizeof(sizes[0]));
    b->ev_kind = calloc(2 * cap, sizeof(int64_t));
    b->ev_index = b->ev_kind ? b->ev_kind + cap : NULL;
    return ok && b->ev_kind;
}

static void free_buffers(buffers *b)
{
    free(b->tm);
    free(b->ev_kind);
}

/* The events of a smooth segment: the slots (posturelab.model.events.event_slots) whose
 * condition holds now (pl_slot_on, with pl_slot_side: generated), in slot order. */
static int64_t segment_events(const pl_run *run, const double *sat, const double *active,
                              int locked, int64_t *kind, int64_t *index, double *side)
{
    int64_t k = 0;
    for (int64_t s = 0; s < run->n_slots; s++) {
        const int64_t i = run->slot_index[s];
        if (!pl_slot_on(run->slot_cond[s], i, sat, active, locked))
            continue;
        kind[k] = run->slot_kind[s];
        index[k] = i;
        side[k] = pl_slot_side(run->slot_kind[s], i, run->slot_side[s], sat);
        k++;
    }
    return k;
}

/* Times at which the delayed feedback is not smooth after the start: kτ after each
 * breakpoint and each knee impact, k = 1 … delay_multiples (a corner of the stimulus or an
 * impact changes the rates or accelerations at once, the muscles feel it τ later, its
 * derivatives 2τ, … later), sorted. Steps land on them as on the breakpoints: an integrator
 * of order 5 that steps across a jump in a low derivative keeps an error its estimate does
 * not see. */
typedef struct {
    double *t;
    int64_t n, cap, next;
} jump_list;

static int jump_add(jump_list *j, double t)
{
    if (j->n == j->cap) {
        const int64_t cap = j->cap ? 2 * j->cap : 16;
        double *q = realloc(j->t, sizeof(double) * cap);
        if (!q)
            return 0;
        j->t = q;
        j->cap = cap;
    }
    int64_t k = j->n++;
    for (; k > j->next && j->t[k - 1] > t; k--)
        j->t[k] = j->t[k - 1];
    j->t[k] = t;
    return 1;
}

/* past the stops at or before t: breakpoints (bi), multiples of the delay (di), jumps */
static void pass_stops(const pl_run *run, double t, int64_t *bi, int64_t *di, jump_list *j)
{
    while (*bi < run->n_bps && run->bps[*bi] <= t + 1e-12)
        ++*bi;
    while (run->delay > 0.0 && *di <= run->delay_multiples && *di * run->delay <= t + 1e-12)
        ++*di;
    while (j->next < j->n && j->t[j->next] <= t + 1e-12)
        j->next++;
}

static double next_stop(const pl_run *run, int64_t bi, int64_t di, const jump_list *jumps,
                        double duration)
{
    double t_stop = bi < run->n_bps ? run->bps[bi] : duration;
    if (run->delay > 0.0 && di <= run->delay_multiples)
        t_stop = fmin(t_stop, di * run->delay);
    if (jumps->next < jumps->n)
        t_stop = fmin(t_stop, jumps->t[jumps->next]);
    return t_stop;
}

/* Whether breakpoint i is another's first echo (the set-up lists a tilt's corners t_k and
 * t_k + τ): its own echoes are the other's. */
static int is_echo(const pl_run *run, int64_t i)
{
    const double want = run->bps[i] - run->delay, tol = 1e-12 * fmax(1.0, run->bps[i]);
    const int64_t k = pl_interval_of(run->bps, 0, i, want + tol);  /* the last at or before */
    return i > 0 && run->bps[k] >= want - tol && run->bps[k] <= want + tol;
}

/* The first step of a segment from y0 (f0 = f(t0, y0)): scipy's select_initial_step, for an
 * error estimate of this order; y1 and f1 are scratch. [s] */
static double initial_step(const pl_model *md, double t0, const double *y0, const double *f0,
                           double t_bound, double max_step, double rtol, double atol, int locked,
                           const double *inp, double *y1, double *f1, int64_t m, int64_t order)
{
    const double interval = t_bound - t0;
    if (interval <= 0.0)
        return 0.0;
    double d0 = 0.0, d1 = 0.0;
    for (int64_t i = 0; i < m; i++) {
        const double sc = atol + fabs(y0[i]) * rtol;
        d0 += (y0[i] / sc) * (y0[i] / sc);
        d1 += (f0[i] / sc) * (f0[i] / sc);
    }
    d0 = sqrt(d0 / m);
    d1 = sqrt(d1 / m);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    h0 = fmin(h0, interval);
    for (int64_t i = 0; i < m; i++)
        y1[i] = y0[i] + h0 * f0[i];
    pl_rhs(md, y1, f1, inp, locked);
    double d2 = 0.0;
    for (int64_t i = 0; i < m; i++) {
        const double sc = atol + fabs(y0[i]) * rtol, v = (f1[i] - f0[i]) / sc;
        d2 += v * v;
    }
    d2 = sqrt(d2 / m) / h0;
    double h1 = (d1 <= 1e-15 && d2 <= 1e-15) ? fmax(1e-6, h0 * 1e-3)
                                             : pow(0.01 / fmax(d1, d2), 1.0 / (order + 1.0));
    return fmin(fmin(100.0 * h0, h1), fmin(interval, max_step));
}

/* The peaks of len samples of the angles (angle i's at rows + i·stride) into out->peak; the
 * last of the samples outside the settling band, −1 if none. */
static int64_t scan(pl_out *out, const double *rows, int64_t stride, int64_t n, int64_t len,
                    double settle_tol)
{
    int64_t last_out = -1;
    for (int64_t i = 0; i < n; i++) {
        const double *restrict row = rows + i * stride;
        double pk = out->peak[i];
        for (int64_t g = 0; g < len; g++) {
            const double v = fabs(row[g]);
            pk = v > pk ? v : pk;
        }
        out->peak[i] = pk;
        for (int64_t g = len - 1; g > last_out; g--)
            if (fabs(row[g]) > settle_tol) {
                last_out = g;
                break;
            }
    }
    return last_out;
}

/* How far inside a step its inputs are taken at a breakpoint it starts or ends on: far
 * beyond the rounding of t ± τ, and a negligible part of the step. [s] */
static double side_of(double t, double h)
{
    return fmin(1e-3 * h, 64.0 * EPS * (1.0 + fabs(t)));
}

int64_t pl_integrate(const pl_run *run, pl_out *out)
{
    const int64_t n = run->n, nf = run->n_filters, m = 2 * n + nf, T = run->n_grid;
    const int64_t width = 2 + n + nf;
    const double *fpar = run->fpar, *grid = run->grid;
    const double rtol = fpar[F_RTOL], atol = fpar[F_ATOL], duration = fpar[F_DURATION];
    const double settle_tol = fpar[F_SETTLE_TOL];
    const double delay = run->delay;
    double max_step = fpar[F_MAX_STEP];
    const int overlapping = delay > 0.0 && delay < OVERLAP_BELOW;
    if (delay > 0.0 && !overlapping)
        max_step = fmin(max_step, delay);  /* the method of steps: the past is computed */
    const int64_t max_switches = run->ipar[I_MAX_SWITCHES];
    const int64_t max_steps = run->ipar[I_MAX_STEPS];
    const double time_limit = fpar[F_TIME_LIMIT];
    const int timed = isfinite(time_limit);
    const double started = timed ? wall_seconds() : 0.0;
    int locked = run->ipar[I_LOCKED0] != 0;
    const int has_inputs = run->dp[0] > 0.0 || delay > 0.0 || run->tp[0] > 0.0
                           || run->mp[0] > 0.0 || run->vp[0] > 0.0;
    double *res = out->res;
    for (int64_t k = 0; k < N_RESULT; k++)
        res[k] = 0.0;

    pl_method me = {0};
    buffers b;
    pl_history hist = {0};
    jump_list jumps = {0};
    memset(&b, 0, sizeof(b));
    int ok = run->method == METHOD_RADAU ? pl_radau_init(&me, n, m)
                                         : pl_explicit_init(&me, run, n);
    ok = ok && alloc_buffers(&b, n, nf, run->p, me.n_nodes, run->n_slots);
    ok = ok && pl_history_init(&hist, 2 * n, delay > 0.0 ? 256 : 1);
    for (int64_t i = 0; delay > 0.0 && i < run->n_bps; i++)  /* the breakpoints' echoes */
        for (int64_t k = 1; ok && k <= run->delay_multiples && !is_echo(run, i); k++) {
            const double echo = run->bps[i] + k * delay;
            if (echo >= duration)
                break;
            ok = jump_add(&jumps, echo);
        }
    if (!ok) {
        free(me.arrays);
        free(me.ws);
        free_buffers(&b);
        pl_history_free(&hist);
        free(jumps.t);
        res[R_STATUS] = PL_NO_MEMORY;
        return PL_NO_MEMORY;
    }
    memcpy(b.sat, run->sat0, sizeof(double) * n);
    memcpy(b.active, run->active0, sizeof(double) * run->p);
    memcpy(b.x, run->x0, sizeof(double) * 2 * n);
    pl_model md = {n, run->bp, b.tm, run->lim, b.sat, b.base, b.work, b.tau, nf,
                   run->filter_gain, run->filter_time, run->C, b.active, b.fscr};
    pl_ctx cx = {&md, run->E, run->dp, fpar, run->before, run->ev_offset, &hist, delay,
                 run->tp, run->tilt_gain, run->tilt_depth, run->mp, run->gains, run->p,
                 b.sc_out, b.sc_inp, b.sc_x, b.ys, run->tilt_pair_gain, run->vp, run->visual_gain,
                 run->visual_pair_gain};
    double *x = b.x, *y = b.y, *Q = b.Q, *inp = b.inp;
    for (int64_t i = 0; i < n; i++)
        out->peak[i] = 0.0;
    for (int64_t i = 0; i < 2 * n; i++)
        out->final[i] = NAN;

    double t = 0.0, h = 0.0, fall_time = NAN, last_outside = NAN;
    int64_t status = PL_COMPLETED, fall_kind = -1, fall_index = -1, n_switches = 0;
    int64_t n_steps = 0, n_rejected = 0, n_evals = 0, gi = 0, bi = 0, di = 1, n_ev = 0;
    int any_outside = 0, final_outside = 0, fall_sample = 0, restart = 1, at_stop = 0;

    while (t < duration) {
        if (restart) {  /* a smooth segment starts (t = 0, or after a switch) */
            pass_stops(run, t, &bi, &di, &jumps);
            pl_moment_gains(run->E, run->C, run->gains, run->joint_gain, b.active, run->p, n,
                            b.tm);
            pl_set_base(x, b.base, n);
            if (t == 0.0 && locked && run->ipar[I_KNEE_MODE] == KNEE_STOP
                && pl_event_value(&cx, EV_KNEE_LEAVES_STOP, 1, 0.0, t, x, locked) < 0.0)
                locked = 0;  /* at its stop, but the muscles pull the knee off it at once */
            n_ev = segment_events(run, b.sat, b.active, locked, b.ev_kind, b.ev_index,
                                  b.ev_side);
            /* at a stop the inputs may jump: the events start from their values just
             * before it (an event that the jump fires is found at the next step's start), the
             * integrator from the inputs just after it */
            const double side = at_stop ? side_of(t, INFINITY) : 0.0;
            for (int64_t e = 0; e < n_ev; e++)
                b.g_old[e] = pl_event_value(&cx, b.ev_kind[e], b.ev_index[e], b.ev_side[e],
                                            t - side, x, locked);
            pl_inputs_at(&cx, t + side, inp);
            pl_rhs(&md, x, me.f0, inp, locked);
            h = initial_step(&md, t, x, me.f0, next_stop(run, bi, di, &jumps, duration),
                             max_step, rtol, atol, locked, inp, b.yp, b.Qg, m, me.order);
            n_evals += 2;
            me.start(&me, &md, x, inp, locked, rtol, &n_evals);
            restart = 0;
        }
        const double t_stop = next_stop(run, bi, di, &jumps, duration);
        if (h > max_step) {
            h = max_step;
            if (me.capped)
                me.capped(&me);
        }
        int landing = 0;
        if (t + 1.01 * h >= t_stop) {
            h = t_stop - t;  /* land exactly on the breakpoint (or the end) */
            landing = 1;
        }
        if (!(h > 10.0 * EPS * fabs(t))) {
            status = PL_STEP_TOO_SMALL;
            break;
        }
        if (n_steps >= max_steps) {  /* the budgets: a runaway integration ends as failed */
            status = PL_STEP_BUDGET;
            break;
        }
        if (timed && (n_steps + n_rejected) % CLOCK_EVERY == 0
            && wall_seconds() - started > time_limit) {
            status = PL_TIME_BUDGET;
            break;
        }
        const double t_new = landing ? t_stop : t + h;
        const int overlap = overlapping && h > delay;  /* its past reaches into itself */
        if (overlap) {
            pl_history_extrapolate(&hist, t, h, b.Qg);
            if (!pl_history_add(&hist, t, h, x, b.Qg)) {
                status = PL_NO_MEMORY;
                break;
            }
            for (int64_t i = 0; i < m; i++)
                b.yp[i] = x[i] + b.Qg[4 * i] + b.Qg[4 * i + 1] + b.Qg[4 * i + 2]
                          + b.Qg[4 * i + 3];
        }
        double h_next;
        int accepted = 0, settled = !overlap;
        for (int64_t it = 0;; it++) {
            if (has_inputs)
                for (int64_t k = 0; k < me.n_nodes; k++) {
                    /* the inputs may jump at a breakpoint: a step onto one takes them just
                     * before it at its end, a step from one just after it at its start */
                    double tk = me.nodes[k] == 1.0 ? t_new : t + me.nodes[k] * h;
                    if (landing && me.nodes[k] == 1.0)
                        tk = t_new - side_of(t_new, h);
                    else if (at_stop && me.nodes[k] == 0.0)
                        tk = t + side_of(t, h);
                    pl_inputs_at(&cx, tk, inp + k * width);
                }
            accepted = me.attempt(&me, &md, t, h, x, y, Q, inp, rtol, atol, locked, &h_next,
                                  &n_evals);
            if (!accepted || !overlap)
                break;
            pl_history_drop(&hist);  /* the step's past inside itself: its own output */
            pl_history_add(&hist, t, h, x, Q);  /* (the slot exists: cannot fail) */
            double change = 0.0;
            for (int64_t i = 0; i < m; i++) {
                const double sc = atol + rtol * fmax(fabs(x[i]), fabs(y[i]));
                const double d = (y[i] - b.yp[i]) / sc;
                change += d * d;
                b.yp[i] = y[i];
            }
            if (change / m <= OVERLAP_TOL * OVERLAP_TOL) {
                settled = 1;
                break;
            }
            if (it + 1 >= OVERLAP_ITERATIONS)
                break;
        }
        if (!accepted || !settled) {
            if (overlap)
                pl_history_drop(&hist);
            n_rejected++;
            h = accepted ? 0.5 * h : h_next;  /* (not settled: a shorter step) */
            continue;
        }
        n_steps++;
        if (delay > 0.0 && !overlap && !pl_history_add(&hist, t, h, x, Q)) {
            status = PL_NO_MEMORY;
            break;
        }

        /* events that fired in (t, t_new]: the earliest root on the interpolant (on a
         * stop, their values just before it, as the step saw its inputs) */
        int64_t ev_hit = -1;
        double t_ev = t_new;
        const double t_look = landing ? t_new - side_of(t_new, h) : t_new;
        for (int64_t e = 0; e < n_ev; e++) {
            const int64_t kind = b.ev_kind[e];
            const double gn = pl_event_value(&cx, kind, b.ev_index[e], b.ev_side[e], t_look, y,
                                             locked);
            const double go = b.g_old[e];
            b.g_new[e] = gn;
            const int fired = run->ev_direction[kind] > 0 ? (go <= 0.0 && gn >= 0.0)
                                                          : (go >= 0.0 && gn <= 0.0);
            if (!fired)
                continue;
            const double root = pl_event_root(&cx, kind, b.ev_index[e], b.ev_side[e], t, t_new,
                                              go, gn, x, Q, h, locked);
            if (ev_hit < 0 || root < t_ev - 1e-12 * fmax(1.0, t_ev)) {
                ev_hit = e;
                t_ev = root;
            } else if (root < t_ev) {
                t_ev = root;  /* a tie within 1e-12 s: the earlier-listed event wins */
            }
        }
        int ev_at_stop = 0;  /* an event on a stop happens there (a jump of the inputs) */
        if (ev_hit >= 0 && at_stop && t_ev <= t + 1e-12 * fmax(1.0, fabs(t))) {
            t_ev = t;
            ev_at_stop = 1;
        } else if (ev_hit >= 0 && landing && t_ev >= t_new - 1e-12 * fmax(1.0, fabs(t_new))) {
            t_ev = t_new;
            ev_at_stop = 1;
        }

        /* output samples in [t, end of this piece], as the reference selects them */
        const double t_end = ev_hit >= 0 ? t_ev : t_new;
        const int inclusive = ev_hit >= 0 || t_new >= duration;
        const int64_t first_gi = gi;
        int64_t g_end = gi;
        while (g_end < T
               && (grid[g_end] < t_end - 1e-12 || (inclusive && grid[g_end] <= t_end + 1e-12)))
            g_end++;
        /* the angles (all of the state when it is stored) at the samples of this step, a
         * component at a time (independent samples: the evaluations overlap), then the
         * outcomes sample by sample; the same code for a single run and a batch row */
        const int64_t comps = out->samples ? m : n;
        /* a batch row keeps outcomes only: a step whose angles stay, by the bound |x| + Σ|q|
         * of its interpolant on [t, t + h], within both the peaks so far and the settling
         * band changes neither (its samples are not evaluated; the outcomes are the same) */
        int quiet = !out->samples && !out->fb && !inclusive && g_end > gi;
        for (int64_t i = 0; quiet && i < n; i++) {
            const double *q = Q + 4 * i;
            const double bound = fabs(x[i]) + fabs(q[0]) + fabs(q[1]) + fabs(q[2]) + fabs(q[3]);
            quiet = bound <= out->peak[i] && bound <= settle_tol;
        }
        if (quiet)
            final_outside = 0;
        for (int64_t g0 = gi; !quiet && g0 < g_end; g0 += SAMPLE_BLOCK) {
            const int64_t g1 = g0 + SAMPLE_BLOCK < g_end ? g0 + SAMPLE_BLOCK : g_end;
            const int64_t len = g1 - g0, stride = out->samples ? T + 1 : SAMPLE_BLOCK;
            const double inv_h = 1.0 / h;
            /* component i of samples g0 … g1 − 1: straight into the stored rows, or into the
             * block (a batch row keeps the angles only) */
            double *rows = out->samples ? out->samples + g0 : b.block;
            for (int64_t i = 0; i < comps; i++) {
                const double xi = x[i], q0 = Q[4 * i], q1 = Q[4 * i + 1], q2 = Q[4 * i + 2],
                             q3 = Q[4 * i + 3];
                double *restrict row = rows + i * stride;
                for (int64_t g = 0; g < len; g++) {
                    const double sg = (grid[g0 + g] - t) * inv_h;
                    row[g] = xi + sg * (q0 + sg * (q1 + sg * (q2 + sg * q3)));
                }
            }
            /* peaks, and the last sample outside the settling band */
            const int64_t last_out = scan(out, rows, stride, n, len, settle_tol);
            if (last_out >= 0) {
                last_outside = grid[g0 + last_out];
                any_outside = 1;
            }
            final_outside = last_out == len - 1;
            if (out->samples)
                memset(out->locked + g0, locked ? 1 : 0, (size_t)len);
            if (out->fb)
                for (int64_t g = g0; g < g1; g++) {
                    pl_history_at(&hist, run->before, grid[g] - delay, b.sc_x);
                    for (int64_t i = 0; i < 2 * n; i++)
                        out->fb[i * (T + 1) + g] = b.sc_x[i];
                }
        }
        gi = g_end;
        if (gi > first_gi) {
            /* the expression of the samples above (a batch row keeps no samples) */
            pl_dense_at(x, Q, 2 * n, (grid[gi - 1] - t) * (1.0 / h), out->final);
        }

        if (ev_hit >= 0) {
            pl_dense_at(x, Q, m, (t_ev - t) / h, b.ys);
            memcpy(x, b.ys, sizeof(double) * m);
            const int64_t kind = b.ev_kind[ev_hit], j = b.ev_index[ev_hit];
            t = t_ev;
            if (run->ev_ends[kind]) {
                status = PL_FELL;
                fall_time = t_ev;
                fall_kind = kind;
                fall_index = j;
                if (gi == 0 || grid[gi - 1] < t_ev - 1e-12) {
                    /* the state at the fall closes the series (off the sample grid) */
                    fall_sample = 1;
                    const int outside = scan(out, x, 1, n, 1, settle_tol) >= 0;
                    if (outside) {
                        last_outside = t_ev;
                        any_outside = 1;
                    }
                    final_outside = outside;
                    memcpy(out->final, x, sizeof(double) * 2 * n);
                    if (out->samples) {
                        for (int64_t i = 0; i < m; i++)
                            out->samples[i * (T + 1) + gi] = x[i];
                        out->locked[gi] = (uint8_t)locked;
                    }
                    if (out->fb) {
                        pl_history_at(&hist, run->before, t_ev - delay, b.sc_x);
                        for (int64_t i = 0; i < 2 * n; i++)
                            out->fb[i * (T + 1) + gi] = b.sc_x[i];
                    }
                }
                break;
            }
            if (out->switches && n_switches < out->switch_cap)
                out->switches[n_switches] = t_ev;
            n_switches++;
            if (n_switches > max_switches) {
                status = PL_CHATTERING;
                break;
            }
            /* what the switch does (pl_apply_switch, generated from model.switched); a
             * pair's activity follows the state the muscles respond to */
            const double *feedback = x;
            if (delay > 0.0 && pl_switch_needs_feedback(kind)) {
                pl_history_at(&hist, run->before, t_ev - delay, b.sc_x);
                feedback = b.sc_x;
            }
            pl_apply_switch(run, kind, j, b.ev_side[ev_hit], feedback, x, b.active, b.sat,
                            &locked, b.work);
            int stored = 1;  /* the switch's echoes: the muscles feel it τ, 2τ, … later */
            for (int64_t k = 1; delay > 0.0 && k <= run->delay_multiples; k++)
                if (t_ev + k * delay < duration)
                    stored = stored && jump_add(&jumps, t_ev + k * delay);
            if (!stored) {
                status = PL_NO_MEMORY;
                break;
            }
            restart = 1;
            at_stop = ev_at_stop;
        }
        const double *next = restart ? x : y;  /* the state the run goes on from */
        int finite = 1;
        for (int64_t i = 0; i < m; i++)
            finite = finite && isfinite(next[i]);
        if (!finite) {
            status = PL_NONFINITE;
            break;
        }
        if (restart)
            continue;
        t = t_new;
        memcpy(x, y, sizeof(double) * m);
        memcpy(me.f0, me.f_end, sizeof(double) * m);  /* the next step's first stage */
        memcpy(b.g_old, b.g_new, sizeof(double) * n_ev);
        pl_set_base(x, b.base, n);
        at_stop = landing;
        if (landing) {
            pass_stops(run, t, &bi, &di, &jumps);
            if (has_inputs && t < duration) {  /* the first stage from just after it */
                pl_inputs_at(&cx, t + side_of(t, h_next), inp);
                pl_rhs(&md, x, me.f0, inp, locked);
                n_evals++;
            }
        }
        h = h_next;
    }

    res[R_STATUS] = (double)status;
    res[R_N_SAMPLES] = (double)gi;
    res[R_FALL_KIND] = (double)fall_kind;
    res[R_FALL_INDEX] = (double)fall_index;
    res[R_FALL_TIME] = fall_time;
    res[R_N_SWITCHES] = (double)n_switches;
    res[R_T_REACHED] = t;
    res[R_N_STEPS] = (double)n_steps;
    res[R_N_REJECTED] = (double)n_rejected;
    res[R_N_EVALS] = (double)n_evals;
    res[R_LAST_OUTSIDE] = last_outside;
    res[R_ANY_OUTSIDE] = any_outside;
    res[R_FINAL_OUTSIDE] = final_outside;
    res[R_FALL_SAMPLE] = fall_sample;
    free(me.arrays);
    free(me.ws);
    free_buffers(&b);
    pl_history_free(&hist);
    free(jumps.t);
    return status;
}
