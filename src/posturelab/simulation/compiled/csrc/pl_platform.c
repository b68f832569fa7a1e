/* Platform acceleration from a packed disturbance (the terms of
 * posturelab.model.platform.Primitive), the tilt angle and rate from a packed tilt (the
 * terms of posturelab.model.tilt.TiltTerm) and the motor-noise torque from a packed
 * posturelab.model.noise.TorqueSeries; layouts in pl.h. */
#include <math.h>
#include "pl.h"

static const double PI = 3.14159265358979323846;

/* the largest k in [lo, hi) with x[k] <= t, by bisection (x increasing; lo if none) */
static int64_t interval_of(const double *x, int64_t lo, int64_t hi, double t)
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
    const int64_t lo = interval_of(dp, first, hi, t);
    const double slope = (dp[lo + 1 + off] - dp[lo + off]) / (dp[lo + 1] - dp[lo]);
    return slope * (t - dp[lo]) + dp[lo + off];
}

void pl_platform_acceleration(double t, const double *dp, double *ax, double *ay)
{
    double sx = 0.0, sy = 0.0;
    const int64_t nq = (int64_t)dp[0];
    for (int64_t q = 0; q < nq; q++) {
        const double *r = dp + 1 + DIST_ROW * q;
        const int kind = (int)r[0];
        double v = 0.0;
        if (kind == DIST_WINDOWED_SINE) {
            const double s = (t - r[4]) / r[3];
            if (s >= 0.0 && s <= 1.0)
                v = r[2] * sin(2.0 * PI * r[5] * s);
        } else if (kind == DIST_SINE) {
            v = r[2] * sin(2.0 * PI * r[3] * t + r[4]);
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

/* α and α̇ of one piecewise cubic: knots x[0..K], coefficients c[4k .. 4k+3] */
static void ppoly(double t, const double *x, const double *c, int64_t K, double period,
                  double *angle, double *rate, double *accel)
{
    if (period > 0.0 && t >= x[0])
        t = x[0] + fmod(t - x[0], period);
    int inside = t >= x[0] && t <= x[K];
    if (t < x[0])
        t = x[0];
    if (t > x[K])
        t = x[K];
    const int64_t lo = interval_of(x, 0, K, t);
    const double u = t - x[lo], *q = c + 4 * lo;
    *angle = q[0] + u * (q[1] + u * (q[2] + u * q[3]));
    *rate = inside ? q[1] + u * (2.0 * q[2] + u * 3.0 * q[3]) : 0.0;
    *accel = inside ? 2.0 * q[2] + 6.0 * u * q[3] : 0.0;
}

void pl_tilt(double t, const double *tp, double *angle, double *rate, double *accel)
{
    double a = 0.0, ad = 0.0, add = 0.0;
    const int64_t nq = (int64_t)tp[0];
    for (int64_t q = 0; q < nq; q++) {
        const double *r = tp + 1 + TILT_ROW * q;
        const int kind = (int)r[0];
        if (kind == TILT_SINE) {
            const double w = 2.0 * PI * r[2], tt = t > 0.0 ? t : 0.0;
            a += r[1] * sin(w * tt + r[3]);
            if (t >= 0.0) {
                ad += r[1] * w * cos(w * tt + r[3]);
                add -= r[1] * w * w * sin(w * tt + r[3]);
            }
        } else if (kind == TILT_RAISED_COSINE) {
            double s = (t - r[2]) / r[3];
            const int inside = t > r[2] && t < r[2] + r[3];
            s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
            a += r[1] * 0.5 * (1.0 - cos(PI * s));
            if (inside) {
                const double k = PI / r[3];
                ad += r[1] * 0.5 * k * sin(PI * s);
                add += r[1] * 0.5 * k * k * cos(PI * s);
            }
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

/* tau[j] += the motor noise at joint j (posturelab.model.noise.torque_at: the interval whose
 * knot is the last at or before t, the end intervals carried on outside the knots) */
void pl_motor_noise_add(double t, const double *mp, int64_t n, double *tau)
{
    const int64_t K = (int64_t)mp[0];
    const double *x = mp + 1, *c = mp + 2 + K;
    const int64_t lo = interval_of(x, 0, K, t);  /* in [0, K - 1] */
    const double u = t - x[lo], *q = c + lo * 4 * n;
    for (int64_t j = 0; j < n; j++)
        tau[j] += q[j] + u * (q[n + j] + u * (q[2 * n + j] + u * q[3 * n + j]));
}
