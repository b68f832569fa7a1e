/* Platform acceleration from a packed disturbance (the terms of
 * posturelab.model.platform.Primitive; layout in pl.h). */
#include <math.h>
#include "pl.h"

static const double PI = 3.14159265358979323846;

/* numpy.interp(t, xp, fp, left=0, right=0), xp = dp[first .. first+count), fp its col-th
 * block of count values after it */
static double interp0(double t, const double *dp, int64_t first, int64_t count, int64_t col)
{
    int64_t lo = first, hi = first + count - 1;
    if (!(t >= dp[lo] && t <= dp[hi]))
        return 0.0;
    const int64_t off = col * count;
    if (t == dp[hi])
        return dp[hi + off];
    while (hi - lo > 1) {
        int64_t mid = (lo + hi) >> 1;
        if (dp[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
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
