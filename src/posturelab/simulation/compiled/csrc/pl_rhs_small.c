/* Right-hand sides for N = 1, 2, 3 links: GENERATED, do not edit.
 *
 * python -m posturelab.simulation.compiled._codegen writes this file from the formulas of
 * posturelab.model (those of pl_rhs_general in pl_model.c, unrolled); a test regenerates
 * it and compares. */
#include "pl.h"

void pl_rhs1(const pl_model *md, const double *x, double *out, const double *inp, int locked)
{
    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + 1;
    double th[1], w[1], s[1], c[1], t[1], a[1], ax, ga;
    (void)locked;
    th[0] = x[0];
    w[0] = x[1];
    pl_rotate(th[0], md->base[0], md->base[1], md->base[2], &s[0], &c[0]);
    ax = inp[0];
    ga = bp[3] + inp[1];
    t[0] = inp[2] + (tk[0] * th[0]) + (tl[0] * w[0]);
    t[0] = ((md->sat[0] != 0.0) ? (md->sat[0]*((md->sat[0] > 0.0) ? (md->lim[1]) : (md->lim[0]))) : (t[0]));
    const double u0 = -t[0];
    const double r0 = u0 + bp[0]*(-ax*c[0] + ga*s[0]);
    const double j00 = bp[1];
    const double m00 = 1.0;
    const double inv_det = 1.0 / (j00 * m00);
    a[0] = (m00 * r0) * inv_det;
    md->tau[0] = t[0];
    out[0] = w[0];
    out[1] = a[0];
}

void pl_rhs2(const pl_model *md, const double *x, double *out, const double *inp, int locked)
{
    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + 4;
    double th[2], w[2], s[2], c[2], t[2], a[2], ax, ga;
    th[0] = x[0];
    w[0] = x[2];
    pl_rotate(th[0], md->base[0], md->base[2], md->base[4], &s[0], &c[0]);
    th[1] = x[1];
    w[1] = x[3];
    pl_rotate(th[1], md->base[1], md->base[3], md->base[5], &s[1], &c[1]);
    ax = inp[0];
    ga = bp[8] + inp[1];
    t[0] = inp[2] + (tk[0] * th[0] + tk[1] * th[1]) + (tl[0] * w[0] + tl[1] * w[1]);
    t[0] = ((md->sat[0] != 0.0) ? (md->sat[0]*((md->sat[0] > 0.0) ? (md->lim[2]) : (md->lim[0]))) : (t[0]));
    t[1] = inp[3] + (tk[2] * th[0] + tk[3] * th[1]) + (tl[2] * w[0] + tl[3] * w[1]);
    t[1] = ((md->sat[1] != 0.0) ? (md->sat[1]*((md->sat[1] > 0.0) ? (md->lim[3]) : (md->lim[1]))) : (t[1]));
    const double u0 = t[1] - t[0];
    const double u1 = -t[1];
    const double r0 = u0 - (bp[5]*(w[1] * w[1])*(-c[0]*s[1] + c[1]*s[0])) + bp[0]*(-ax*c[0] + ga*s[0]);
    const double r1 = u1 - (-bp[5]*(w[0] * w[0])*(-c[0]*s[1] + c[1]*s[0])) + bp[1]*(-ax*c[1] + ga*s[1]);
    const double j00 = bp[2];
    const double j01 = bp[5]*(c[0]*c[1] + s[0]*s[1]);
    const double j11 = bp[3];
    const double q0 = -j01;
    const double m00 = j11;
    const double m01 = q0;
    const double m10 = q0;
    const double m11 = j00;
    const double inv_det = 1.0 / (j00 * m00 + j01 * m10);
    a[0] = (m00 * r0 + m01 * r1) * inv_det;
    a[1] = (m10 * r0 + m11 * r1) * inv_det;
    if (locked) {  /* knee constraint C = (−1, 1, 0): Θ̈ −= J⁻¹C (C·Θ̈)/(C·J⁻¹C) */
        const double y0 = m01 - m00;
        const double y1 = m11 - m10;
        const double lam = (a[1] - a[0]) / (y1 - y0);
        a[0] -= y0 * lam;
        a[1] -= y1 * lam;
    }
    md->tau[0] = t[0];
    md->tau[1] = t[1];
    out[0] = w[0];
    out[1] = w[1];
    out[2] = a[0];
    out[3] = a[1];
}

void pl_rhs3(const pl_model *md, const double *x, double *out, const double *inp, int locked)
{
    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + 9;
    double th[3], w[3], s[3], c[3], t[3], a[3], ax, ga;
    th[0] = x[0];
    w[0] = x[3];
    pl_rotate(th[0], md->base[0], md->base[3], md->base[6], &s[0], &c[0]);
    th[1] = x[1];
    w[1] = x[4];
    pl_rotate(th[1], md->base[1], md->base[4], md->base[7], &s[1], &c[1]);
    th[2] = x[2];
    w[2] = x[5];
    pl_rotate(th[2], md->base[2], md->base[5], md->base[8], &s[2], &c[2]);
    ax = inp[0];
    ga = bp[15] + inp[1];
    t[0] = inp[2] + (tk[0] * th[0] + tk[1] * th[1] + tk[2] * th[2]) + (tl[0] * w[0] + tl[1] * w[1] + tl[2] * w[2]);
    t[0] = ((md->sat[0] != 0.0) ? (md->sat[0]*((md->sat[0] > 0.0) ? (md->lim[3]) : (md->lim[0]))) : (t[0]));
    t[1] = inp[3] + (tk[3] * th[0] + tk[4] * th[1] + tk[5] * th[2]) + (tl[3] * w[0] + tl[4] * w[1] + tl[5] * w[2]);
    t[1] = ((md->sat[1] != 0.0) ? (md->sat[1]*((md->sat[1] > 0.0) ? (md->lim[4]) : (md->lim[1]))) : (t[1]));
    t[2] = inp[4] + (tk[6] * th[0] + tk[7] * th[1] + tk[8] * th[2]) + (tl[6] * w[0] + tl[7] * w[1] + tl[8] * w[2]);
    t[2] = ((md->sat[2] != 0.0) ? (md->sat[2]*((md->sat[2] > 0.0) ? (md->lim[5]) : (md->lim[2]))) : (t[2]));
    const double u0 = t[1] - t[0];
    const double u1 = t[2] - t[1];
    const double u2 = -t[2];
    const double r0 = u0 - (bp[7]*(w[1] * w[1])*(-c[0]*s[1] + c[1]*s[0]) + bp[8]*(w[2] * w[2])*(-c[0]*s[2] + c[2]*s[0])) + bp[0]*(-ax*c[0] + ga*s[0]);
    const double r1 = u1 - (-bp[7]*(w[0] * w[0])*(-c[0]*s[1] + c[1]*s[0]) + bp[11]*(w[2] * w[2])*(-c[1]*s[2] + c[2]*s[1])) + bp[1]*(-ax*c[1] + ga*s[1]);
    const double r2 = u2 - (-bp[8]*(w[0] * w[0])*(-c[0]*s[2] + c[2]*s[0]) + -bp[11]*(w[1] * w[1])*(-c[1]*s[2] + c[2]*s[1])) + bp[2]*(-ax*c[2] + ga*s[2]);
    const double j00 = bp[3];
    const double j01 = bp[7]*(c[0]*c[1] + s[0]*s[1]);
    const double j02 = bp[8]*(c[0]*c[2] + s[0]*s[2]);
    const double j11 = bp[4];
    const double j12 = bp[11]*(c[1]*c[2] + s[1]*s[2]);
    const double j22 = bp[5];
    const double q0 = -j01*j22 + j02*j12;
    const double q1 = j01*j12 - j02*j11;
    const double q2 = -j00*j12 + j01*j02;
    const double m00 = j11*j22 - j12*j12;
    const double m01 = q0;
    const double m02 = q1;
    const double m10 = q0;
    const double m11 = j00*j22 - j02*j02;
    const double m12 = q2;
    const double m20 = q1;
    const double m21 = q2;
    const double m22 = j00*j11 - j01*j01;
    const double inv_det = 1.0 / (j00 * m00 + j01 * m10 + j02 * m20);
    a[0] = (m00 * r0 + m01 * r1 + m02 * r2) * inv_det;
    a[1] = (m10 * r0 + m11 * r1 + m12 * r2) * inv_det;
    a[2] = (m20 * r0 + m21 * r1 + m22 * r2) * inv_det;
    if (locked) {  /* knee constraint C = (−1, 1, 0): Θ̈ −= J⁻¹C (C·Θ̈)/(C·J⁻¹C) */
        const double y0 = m01 - m00;
        const double y1 = m11 - m10;
        const double y2 = m21 - m20;
        const double lam = (a[1] - a[0]) / (y1 - y0);
        a[0] -= y0 * lam;
        a[1] -= y1 * lam;
        a[2] -= y2 * lam;
    }
    md->tau[0] = t[0];
    md->tau[1] = t[1];
    md->tau[2] = t[2];
    out[0] = w[0];
    out[1] = w[1];
    out[2] = w[2];
    out[3] = a[0];
    out[4] = a[1];
    out[5] = a[2];
}
