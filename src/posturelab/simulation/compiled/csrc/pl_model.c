/* The switched model for any N links: GENERATED, do not edit.
 *
 * python -m posturelab.simulation.compiled._codegen writes this file from the formulas of
 * posturelab.model (dynamics, platform, tilt, switched), printed by sympy into the loops of
 * _codegen/model_c.py; a test regenerates it and compares. Layouts: pl.h, pl_codes.h.
 *
 *   J(Θ)Θ̈ + B(Θ,Θ̇)Θ̇ − (g + ÿ_d)G(Θ) + ẍ_d H(Θ) = U,   U_i = τ_{i+1} − τ_i,
 *
 * τ the net muscle moments at the joints: τ = T_K Θ + T_L Θ̇ + inp[2 + j] (T_K = Cᵀ
 * diag(k·active) E, pl_moment_gains), or its positive or negative limit (pl_model.lim)
 * while joint j saturates;
 * inp = (ẍ_d, ÿ_d, delayed, tilt and noise moments, then each torque feedback filter's
 * input), from pl_inputs_at; with torque feedback the state is [Θ, Θ̇, Y] (filters_c.py). */
#include <math.h>
#include "pl.h"

/* numpy.interp(t, xp, fp, left=0, right=0), xp = dp[first .. first+count), fp its col-th
 * block of count values after it */
static double interp0(double t, const double *dp, int64_t first, int64_t count, int64_t col)
{
    const int64_t hi = first + count - 1;
    if (!(t >= dp[first] && t <= dp[hi]))
        return 0.0;
    const int64_t off = col * count;
    if (t == dp[hi])
        return dp[hi + off];
    const int64_t lo = pl_interval_of(dp, first, hi, t);
    const double slope = (dp[lo + 1 + off] - dp[lo + off]) / (dp[lo + 1] - dp[lo]);
    return slope * (t - dp[lo]) + dp[lo + off];
}

/* the platform acceleration: the sum of the disturbance's terms (model.platform.Primitive) */
void pl_platform_acceleration(double t, const double *dp, double *ax, double *ay)
{
    double sx = 0.0, sy = 0.0;
    const int64_t nq = (int64_t)dp[0];
    for (int64_t q = 0; q < nq; q++) {
        const double *r = dp + 1 + DIST_ROW * q;
        const int kind = (int)r[0];
        double v = 0.0;
        if (kind == DIST_WINDOWED_SINE) {
            v = (((-r[4] + t)/r[3] >= 0.0 && (-r[4] + t)/r[3] <= 1.0) ? (r[2]*sin(6.2831853071795862*r[5]*(-r[4] + t)/r[3])) : (0.0));
        } else if (kind == DIST_SINE) {
            v = r[2]*sin(6.2831853071795862*r[3]*t + r[4]);
        } else if (kind == DIST_SAMPLES) {
            const int64_t first = (int64_t)r[2], count = (int64_t)r[3];
            sx += interp0(t, dp, first, count, 1);
            sy += interp0(t, dp, first, count, 2);
            continue;
        }
        if (r[1] == 0.0)
            sx += v;
        else
            sy += v;
    }
    *ax = sx;
    *ay = sy;
}

/* α, α̇, α̈ of one piecewise cubic: knots x[0..K], coefficients c[4k .. 4k+3] */
static void ppoly(double t, const double *x, const double *c, int64_t K, double period,
                  double *angle, double *rate, double *accel)
{
    if (period > 0.0 && t >= x[0])
        t = x[0] + fmod(t - x[0], period);
    const int inside = t >= x[0] && t <= x[K];
    if (t < x[0])
        t = x[0];
    if (t > x[K])
        t = x[K];
    const int64_t lo = pl_interval_of(x, 0, K, t);
    const double u = t - x[lo], *q = c + 4 * lo;
    *angle = q[0] + u*(q[1] + u*(q[2] + q[3]*u));
    *rate = inside ? q[1] + u*(2.0*q[2] + 3.0*q[3]*u) : 0.0;
    *accel = inside ? 2.0*q[2] + 6.0*q[3]*u : 0.0;
}

/* the tilt: the sum of its terms (model.tilt.TiltTerm) */
void pl_tilt(double t, const double *tp, double *angle, double *rate, double *accel)
{
    double a = 0.0, ad = 0.0, add = 0.0;
    const int64_t nq = (int64_t)tp[0];
    for (int64_t q = 0; q < nq; q++) {
        const double *r = tp + 1 + TILT_ROW * q;
        const int kind = (int)r[0];
        if (kind == TILT_SINE) {
            a += r[1]*sin(6.2831853071795862*r[2]*fmax(0.0, t) + r[3]);
            ad += ((t >= 0.0) ? (6.2831853071795862*r[1]*r[2]*cos(6.2831853071795862*r[2]*fmax(0.0, t) + r[3])) : (0.0));
            add += ((t >= 0.0) ? (-39.478417604357432*r[1]*(r[2] * r[2])*sin(6.2831853071795862*r[2]*fmax(0.0, t) + r[3])) : (0.0));
        } else if (kind == TILT_RAISED_COSINE) {
            a += 0.5*r[1]*(1.0 - cos(3.1415926535897931*fmin(1.0, fmax(0.0, (-r[2] + t)/r[3]))));
            ad += ((r[2] < t && t < r[2] + r[3]) ? (1.5707963267948966*r[1]*sin(3.1415926535897931*fmin(1.0, fmax(0.0, (-r[2] + t)/r[3])))/r[3]) : (0.0));
            add += ((r[2] < t && t < r[2] + r[3]) ? (4.934802200544679*r[1]*cos(3.1415926535897931*fmin(1.0, fmax(0.0, (-r[2] + t)/r[3])))/(r[3] * r[3])) : (0.0));
        } else if (kind == TILT_PPOLY) {
            const int64_t off = (int64_t)r[1], K = (int64_t)r[2];
            double pa, pr, pq;
            ppoly(t, tp + off, tp + off + K + 1, K, r[3], &pa, &pr, &pq);
            a += pa;
            ad += pr;
            add += pq;
        }
    }
    *angle = a;
    *rate = ad;
    *accel = add;
}

/* tau[j] += the motor noise at joint j (model.noise.torque_at: the interval whose knot is the
 * last at or before t, the end intervals carried on outside the knots) */
void pl_motor_noise_add(double t, const double *mp, int64_t n, double *tau)
{
    const int64_t K = (int64_t)mp[0];
    const double *x = mp + 1, *c = mp + 2 + K;
    const int64_t lo = pl_interval_of(x, 0, K, t);  /* in [0, K - 1] */
    const double u = t - x[lo], *q = c + lo * 4 * n;
    for (int64_t j = 0; j < n; j++)
        tau[j] += q[j] + u*(q[n + j] + u*(q[2 * n + j] + q[3 * n + j]*u));
}

/* The inputs at t: inp = (ẍ_d, ÿ_d, the moments that do not depend on the state now: the
 * delayed part of the feedback on x(t − τ), the tilt's part, the visual scene's part, the
 * motor noise). */
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
        ax += -cx->tilt_depth*(-(ad * ad)*sin(a) + add*cos(a));
        ay += -cx->tilt_depth*((ad * ad)*cos(a) + add*sin(a));
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
        for (int64_t q = 0; q < cx->md->nf; q++) {  /* the filters' inputs */
            double st = 0.0, sd = 0.0;
            for (int64_t k = 0; k < n; k++) {
                st += cx->E[q * n + k] * cx->sc_x[k];
                sd += cx->E[q * n + k] * cx->sc_x[n + k];
            }
            out[2 + n + q] = cx->md->active[q]*(cx->gains[GAIN_DELAYED_STIFFNESS * cx->p + q]*st + cx->gains[GAIN_DELAYED_VISCOSITY * cx->p + q]*sd);
        }
    } else {
        for (int64_t j = 0; j < n; j++)
            out[2 + j] = 0.0;
    }
    if (cx->tp[0] > 0.0) {  /* the tilt's moments: now, and as the delayed part felt it */
        const double *g = cx->tilt_gain;
        double a_d = 0.0, ad_d = 0.0, add_d = 0.0;
        if (cx->delay > 0.0)
            pl_tilt(t - cx->delay, cx->tp, &a_d, &ad_d, &add_d);
        for (int64_t j = 0; j < n; j++)
            out[2 + j] += a*g[GAIN_IMMEDIATE_STIFFNESS * n + j] + a_d*g[GAIN_DELAYED_STIFFNESS * n + j] + ad*g[GAIN_IMMEDIATE_VISCOSITY * n + j] + ad_d*g[GAIN_DELAYED_VISCOSITY * n + j];
        for (int64_t q = 0; q < cx->md->nf; q++)
            out[2 + n + q] += a_d*cx->tilt_pair_gain[GAIN_DELAYED_STIFFNESS * cx->p + q] + ad_d*cx->tilt_pair_gain[GAIN_DELAYED_VISCOSITY * cx->p + q];
    }
    if (cx->vp[0] > 0.0) {  /* the visual scene's moments: through the active part only */
        const double *g = cx->visual_gain;
        double v = 0.0, vd = 0.0, vdd = 0.0, v_d = 0.0, vd_d = 0.0, vdd_d = 0.0;
        pl_tilt(t, cx->vp, &v, &vd, &vdd);
        if (cx->delay > 0.0)
            pl_tilt(t - cx->delay, cx->vp, &v_d, &vd_d, &vdd_d);
        for (int64_t j = 0; j < n; j++)
            out[2 + j] += g[GAIN_DELAYED_STIFFNESS * n + j]*v_d + g[GAIN_DELAYED_VISCOSITY * n + j]*vd_d + g[GAIN_IMMEDIATE_STIFFNESS * n + j]*v + g[GAIN_IMMEDIATE_VISCOSITY * n + j]*vd;
        for (int64_t q = 0; q < cx->md->nf; q++)
            out[2 + n + q] += cx->visual_pair_gain[GAIN_DELAYED_STIFFNESS * cx->p + q]*v_d + cx->visual_pair_gain[GAIN_DELAYED_VISCOSITY * cx->p + q]*vd_d;
    }
    if (cx->mp[0] > 0.0)  /* the motor noise, on the motor command */
        pl_motor_noise_add(t, cx->mp, n, out + 2);
}

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
        tau[j] = ((md->sat[j] != 0.0) ? (md->sat[j]*((md->sat[j] > 0.0) ? (md->lim[n + j]) : (md->lim[j]))) : (t));
    }
    for (int64_t i = 0; i < n; i++) {
        const double si = work[i * w + n + 2], ci = work[i * w + n + 3];
        double r = (i + 1 < n ? tau[i + 1] : 0.0) - tau[i] + bp[i]*(-ax*ci + ga*si);
        for (int64_t j = 0; j < n; j++) {
            if (j == i) {
                work[i * w + j] = bp[n + i];
                continue;
            }
            const double sj = work[j * w + n + 2], cj = work[j * w + n + 3];
            const double cij = bp[oc + i * n + j];
            r -= cij*(x[n + j] * x[n + j])*(-ci*sj + cj*si);
            work[i * w + j] = cij*(ci*cj + si*sj);
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

/* [Θ̇, Θ̈, Ẏ] at x = [Θ, Θ̇, Y]: the N-link right-hand side, with the torque feedback filters'
 * moments added to the inputs' and their rates after it (model.switched.raw_moments,
 * torque_feedback_rate) */
void pl_rhs(const pl_model *md, const double *x, double *out, const double *inp, int locked)
{
    const int64_t n = md->n, nf = md->nf;
    double *fs = md->fscr;
    if (nf > 0) {
        for (int64_t k = 0; k < 2 + n; k++)
            fs[k] = inp[k];
        for (int64_t q = 0; q < nf; q++) {
            for (int64_t j = 0; j < n; j++)
                fs[2 + j] += md->C[q * n + j] * (md->active[q]*x[2 * n + q]);
            fs[2 + n + q] = (md->tf_gain*(inp[2 + n + q] + md->active[q]*x[2 * n + q]) - x[2 * n + q])/md->tf_time;
        }
        inp = fs;
    }
    switch (n) {
    case 3: pl_rhs3(md, x, out, inp, locked); break;
    case 2: pl_rhs2(md, x, out, inp, locked); break;
    case 1: pl_rhs1(md, x, out, inp, locked); break;
    default: pl_rhs_general(md, x, out, inp, locked);
    }
    for (int64_t q = 0; q < nf; q++)
        out[2 * n + q] = fs[2 + n + q];
}

/* A segment's moment gains tm (GAIN_ROWS, n, n): T_K, T_L and their delayed parts,
 * T = Cᵀ diag(g·active) E for each row g of the pair gains (GAIN_ROWS, p), plus the
 * joint-space controller's rows jg (model.joint_feedback; NULL: none). */
void pl_moment_gains(const double *E, const double *C, const double *gains, const double *jg,
                     const double *active, int64_t p, int64_t n, double *tm)
{
    for (int64_t r = 0; r < 4; r++)
        for (int64_t j = 0; j < n; j++)
            for (int64_t k = 0; k < n; k++) {
                double sum = 0.0;
                for (int64_t q = 0; q < p; q++)
                    sum += C[q * n + j] * E[q * n + k] * active[q] * gains[r * p + q];
                tm[(r * n + j) * n + k] = sum;
            }
    for (int64_t k = 0; jg && k < 4 * n * n; k++)
        tm[k] = jg[k] + tm[k];
}

/* Plastic impact onto the knee constraint, in place on x's rates:
 * Θ̇ − J⁻¹C (C·Θ̇)/(C·J⁻¹C), C = (−1, 1, 0, …). work holds at least n·(n + 1). */
void pl_project_velocity(double *x, const double *bp, double *work, int64_t n)
{
    const int64_t s = n + 1;
    for (int64_t i = 0; i < n; i++) {
        for (int64_t j = 0; j < n; j++)
            work[i * s + j] = i == j ? bp[n + i] : bp[2 * n + i * n + j]*cos(x[i] - x[j]);
        work[i * s + n] = 0.0;
    }
    work[n] = -1.0;
    work[s + n] = 1.0;
    pl_solve_into(work, n, 1, s);
    const double lam = (x[n + 1] - x[n]) / (work[s + n] - work[n]);
    for (int64_t i = 0; i < n; i++)
        x[n + i] -= work[i * s + n] * lam;
}

/* The stretch of pair idx (its row of E times the angles) and its rate, on the state the
 * feedback sees: x(t − τ) when it is delayed, y otherwise. */
static void pair_stretch(const pl_ctx *cx, int64_t idx, double t, const double *y,
                         double *stretch, double *stretch_rate)
{
    const int64_t n = cx->md->n;
    const double *fb = y;
    if (cx->delay > 0.0) {
        pl_history_at(cx->hist, cx->before, t - cx->delay, cx->sc_x);
        fb = cx->sc_x;
    }
    double st = 0.0, sd = 0.0;
    for (int64_t j = 0; j < n; j++) {
        st += cx->E[idx * n + j] * fb[j];
        sd += cx->E[idx * n + j] * fb[n + j];
    }
    *stretch = st;
    *stretch_rate = sd;
}

/* pair idx's stiffness and viscosity: its immediate and delayed gains together */
static void pair_gains(const pl_ctx *cx, int64_t idx, double *stiffness, double *viscosity)
{
    const double *gn = cx->gains;
    const int64_t p = cx->p;
    *stiffness = gn[GAIN_IMMEDIATE_STIFFNESS * p + idx] + gn[GAIN_DELAYED_STIFFNESS * p + idx];
    *viscosity = gn[GAIN_IMMEDIATE_VISCOSITY * p + idx] + gn[GAIN_DELAYED_VISCOSITY * p + idx];
}

/* the centre of gravity's x at the angles y [m] */
static double cog_x(const pl_model *md, const double *y)
{
    const int64_t n = md->n;
    const double *bp = md->bp;
    double xc = 0.0;
    for (int64_t i = 0; i < n; i++)
        xc += bp[i]*sin(y[i]);
    return xc / bp[2 * n + n * n + 1];
}

/* the vertical ground reaction [N], once pl_rhs has left Θ̈ in cx->sc_out and the
 * platform's vertical acceleration is in cx->sc_inp */
static double vertical_reaction(const pl_ctx *cx, const double *y)
{
    const int64_t n = cx->md->n;
    const double *bp = cx->md->bp;
    double fy = bp[2 * n + n * n + 1] * (bp[2 * n + n * n] + cx->sc_inp[1]);
    for (int64_t i = 0; i < n; i++)
        fy += -bp[i]*(cx->sc_out[n + i]*sin(y[i]) + (y[n + i] * y[n + i])*cos(y[i]));
    return fy;
}

/* The value of an event function (model.switched.EVENT_VALUES, plus the kind's offset of
 * model.events) at (t, y) with the segment's switches. */
double pl_event_value(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t,
                      const double *y, int locked)
{
    const pl_model *md = cx->md;
    const int64_t n = md->n;
    const double *fpar = cx->fpar;
    (void)locked;
    (void)side;
    double st = 0.0, sd = 0.0, pk = 0.0, pv = 0.0, xc = 0.0, fy = 0.0, g = 0.0;
    switch (kind) {
    case EV_LINK_ANGLE: {
        g = fpar[F_MAX_ANGLE] - fabs(y[idx]);
        break;
    }
    case EV_COG_TOE: {
        xc = cog_x(md, y);
        g = fpar[F_TOE] - xc;
        break;
    }
    case EV_COG_HEEL: {
        xc = cog_x(md, y);
        g = -fpar[F_HEEL] + xc;
        break;
    }
    case EV_COP_TOE: {
        pl_inputs_at(cx, t, cx->sc_inp);
        pl_rhs(md, y, cx->sc_out, cx->sc_inp, locked);
        fy = vertical_reaction(cx, y);
        g = fpar[F_TOE]*fy - md->tau[0];
        break;
    }
    case EV_COP_HEEL: {
        pl_inputs_at(cx, t, cx->sc_inp);
        pl_rhs(md, y, cx->sc_out, cx->sc_inp, locked);
        fy = vertical_reaction(cx, y);
        g = -fpar[F_HEEL]*fy + md->tau[0];
        break;
    }
    case EV_SATURATES:
    case EV_LETS_GO: {
        pl_inputs_at(cx, t, cx->sc_inp);
        const double *tk = md->tm, *tl = md->tm + n * n;
        double tau = cx->sc_inp[2 + idx];
        for (int64_t k = 0; k < n; k++)
            tau += tk[idx * n + k] * y[k] + tl[idx * n + k] * y[n + k];
        for (int64_t q = 0; q < md->nf; q++)
            tau += md->C[q * n + idx] * (md->active[q]*y[2 * n + q]);
        g = side*tau - ((side > 0.0) ? (md->lim[n + idx]) : (md->lim[idx]));
        break;
    }
    case EV_PAIR_SLACKENS:
    case EV_PAIR_ENGAGES: {
        pair_stretch(cx, idx, t, y, &st, &sd);
        g = st;
        break;
    }
    case EV_KNEE_HITS_STOP: {
        g = (y[1] - y[0]) - fpar[F_STOP_ANGLE];
        break;
    }
    case EV_KNEE_LEAVES_STOP: {
        pl_inputs_at(cx, t, cx->sc_inp);
        pl_rhs(md, y, cx->sc_out, cx->sc_inp, 0);
        g = (cx->sc_out[n + 1] - cx->sc_out[n]);
        break;
    }
    case EV_PAIR_PUSHES: {
        pair_stretch(cx, idx, t, y, &st, &sd);
        pair_gains(cx, idx, &pk, &pv);
        g = pk*st + pv*sd;
        break;
    }
    case EV_PAIR_PULLS: {
        pair_stretch(cx, idx, t, y, &st, &sd);
        pair_gains(cx, idx, &pk, &pv);
        g = fmin(pk*st + pv*sd, st*((pk > 0.0) ? (pk) : (1.0)));
        break;
    }
    default:
        break;
    }
    return g + cx->ev_offset[kind];
}

/* The side of an event slot of kind `kind` at joint or pair i in a segment that starts with
 * joint saturation `sat` (model.events.SIDE_IS_SATURATION: a joint lets go from the side it
 * is saturated at), else the slot's `side`. */
double pl_slot_side(int64_t kind, int64_t i, double side, const double *sat)
{
    switch (kind) {
    case EV_LETS_GO:
        return sat[i];
    default:
        return side;
    }
}

/* Whether switch `kind` reads the state the muscles respond to (model.switched.SWITCH_EFFECTS:
 * a pair's activity follows its fed-back stretch rate). */
int pl_switch_needs_feedback(int64_t kind)
{
    switch (kind) {
    case EV_PAIR_SLACKENS:
    case EV_PAIR_ENGAGES:
    case EV_PAIR_PUSHES:
    case EV_PAIR_PULLS:
        return 1;
    default:
        return 0;
    }
}

/* What switch `kind` (index j, side `side`) does (model.switched.apply_switch): x, active,
 * sat and *locked updated in place, `feedback` the state the muscles respond to (x, or the
 * delayed state), `work` pl_project_velocity's scratch. */
void pl_apply_switch(const pl_run *run, int64_t kind, int64_t j, double side,
                     const double *feedback, double *x, double *active, double *sat,
                     int *locked, double *work)
{
    const int64_t n = run->n;
    const double stop_angle = run->fpar[F_STOP_ANGLE];
    (void)side;
    (void)feedback;
    (void)stop_angle;
    switch (kind) {
    case EV_PAIR_SLACKENS:
    case EV_PAIR_ENGAGES: {
        double sd = 0.0;
        for (int64_t k = 0; k < n; k++)
            sd += run->E[j * n + k] * feedback[n + k];
        active[j] = ((sd >= 0.0) ? (1.0) : (0.0));
        break;
    }
    case EV_PAIR_PUSHES: {
        active[j] = 0.0;
        break;
    }
    case EV_PAIR_PULLS: {
        active[j] = 1.0;
        break;
    }
    case EV_SATURATES: {
        sat[j] = side;
        break;
    }
    case EV_LETS_GO: {
        sat[j] = 0.0;
        break;
    }
    case EV_KNEE_HITS_STOP: {
        x[1] = stop_angle + x[0];
        pl_project_velocity(x, run->bp, work, n);
        *locked = 1;
        break;
    }
    case EV_KNEE_LEAVES_STOP: {
        *locked = 0;
        break;
    }
    default:
        break;
    }
}

/* Whether an event slot with condition `cond` (at joint or pair i) is part of a segment that
 * starts with these switches (model.events.SLOT_CONDITIONS). */
int pl_slot_on(int64_t cond, int64_t i, const double *sat, const double *active, int locked)
{
    switch (cond) {
    case COND_JOINT_FREE: return sat[i] == 0.0;
    case COND_JOINT_SATURATED: return sat[i] != 0.0;
    case COND_PAIR_ACTIVE: return active[i] > 0.0;
    case COND_PAIR_SLACK: return !(active[i] > 0.0);
    case COND_KNEE_FREE: return !locked;
    case COND_KNEE_LOCKED: return locked;
    default: return 1;
    }
}

/* Run r of a batch and where its outputs go (headers.BATCH_ROWS, BATCH_OUTS) */
void pl_batch_row(const pl_batch *b, int64_t r, pl_run *run, pl_out *out)
{
    const int64_t n = b->base.n, p = b->base.p, level = b->which[r];
    *run = b->base;
    run->x0 = b->x0_all + level * (2 * n);
    run->before = b->before_all + level * (2 * n);
    run->dp = b->dp_all + level * (b->dp_stride);
    run->ipar = b->ipar_all + level * (N_IPAR);
    run->active0 = b->active0_all + level * (p);
    run->gains = b->gains_all + r * (4 * p);
    run->lim = b->lim_all + r * (2 * n);
    run->delay = b->delay_all[r];
    run->sat0 = b->sat0_all + r * (n);
    run->method = b->method_all[r];
    run->tilt_gain = b->tilt_gain_all + r * (4 * n);
    run->tilt_pair_gain = b->tilt_pair_gain_all + r * (4 * p);
    run->visual_gain = b->visual_gain_all + r * (4 * n);
    run->visual_pair_gain = b->visual_pair_gain_all + r * (4 * p);
    *out = (pl_out){.peak = b->peaks + r * (n),
                     .final = b->finals + r * (2 * n),
                     .res = b->results + r * (N_RESULT)};
}
