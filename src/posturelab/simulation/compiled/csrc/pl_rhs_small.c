/* Right-hand sides for N = 1, 2, 3 links: GENERATED, do not edit.
 *
 * python -m posturelab.simulation.compiled._codegen writes this file from the formulas of
 * posturelab.model (those of pl_rhs_general in pl_model.c, unrolled); a test regenerates
 * it and compares. */
#include "pl.h"

void pl_rhs1(const pl_model *md, const double *x, double *out, const double *inp,
             int locked)
{
    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + 1;
    const double *base = md->base;
    (void)locked;
    const double th0 = x[0], w0 = x[1];
    double s0, c0;
    pl_rotate(th0, base[0], base[1], base[2], &s0, &c0);
    const double ax = inp[0];
    const double ga = bp[3] + inp[1];
    double t0 = inp[2] + (tk[0] * th0) + (tl[0] * w0);
    t0 = ((md->sat[0] != 0.0) ? (md->lim[0]*md->sat[0]) : (t0));
    const double u0 = -t0;
    const double r0 = u0 + bp[0]*(-ax*c0 + ga*s0);
    const double j00 = bp[1];
    const double m00 = 1.0;
    const double inv_det = 1.0 / (j00 * m00);
    double a0 = (m00 * r0) * inv_det;
    md->tau[0] = t0;
    out[0] = w0;
    out[1] = a0;
}

void pl_rhs2(const pl_model *md, const double *x, double *out, const double *inp,
             int locked)
{
    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + 4;
    const double *base = md->base;
    const double th0 = x[0], w0 = x[2];
    const double th1 = x[1], w1 = x[3];
    double s0, c0;
    pl_rotate(th0, base[0], base[2], base[4], &s0, &c0);
    double s1, c1;
    pl_rotate(th1, base[1], base[3], base[5], &s1, &c1);
    const double ax = inp[0];
    const double ga = bp[8] + inp[1];
    double t0 = inp[2] + (tk[0] * th0 + tk[1] * th1) + (tl[0] * w0 + tl[1] * w1);
    t0 = ((md->sat[0] != 0.0) ? (md->lim[0]*md->sat[0]) : (t0));
    double t1 = inp[3] + (tk[2] * th0 + tk[3] * th1) + (tl[2] * w0 + tl[3] * w1);
    t1 = ((md->sat[1] != 0.0) ? (md->lim[1]*md->sat[1]) : (t1));
    const double u0 = t1 - t0;
    const double u1 = -t1;
    const double r0 = u0 - (bp[5]*(w1 * w1)*(-c0*s1 + c1*s0)) + bp[0]*(-ax*c0 + ga*s0);
    const double r1 = u1 - (-bp[5]*(w0 * w0)*(-c0*s1 + c1*s0)) + bp[1]*(-ax*c1 + ga*s1);
    const double j00 = bp[2];
    const double j01 = bp[5]*(c0*c1 + s0*s1);
    const double j11 = bp[3];
    const double q0 = -j01;
    const double m00 = j11;
    const double m01 = q0;
    const double m10 = q0;
    const double m11 = j00;
    const double inv_det = 1.0 / (j00 * m00 + j01 * m10);
    double a0 = (m00 * r0 + m01 * r1) * inv_det;
    double a1 = (m10 * r0 + m11 * r1) * inv_det;
    if (locked) {  /* knee constraint C = (−1, 1, 0): Θ̈ −= J⁻¹C (C·Θ̈)/(C·J⁻¹C) */
        const double y0 = m01 - m00;
        const double y1 = m11 - m10;
        const double lam = (a1 - a0) / (y1 - y0);
        a0 -= y0 * lam;
        a1 -= y1 * lam;
    }
    md->tau[0] = t0;
    md->tau[1] = t1;
    out[0] = w0;
    out[1] = w1;
    out[2] = a0;
    out[3] = a1;
}

void pl_rhs3(const pl_model *md, const double *x, double *out, const double *inp,
             int locked)
{
    const double *bp = md->bp, *tk = md->tm, *tl = md->tm + 9;
    const double *base = md->base;
    const double th0 = x[0], w0 = x[3];
    const double th1 = x[1], w1 = x[4];
    const double th2 = x[2], w2 = x[5];
    double s0, c0;
    pl_rotate(th0, base[0], base[3], base[6], &s0, &c0);
    double s1, c1;
    pl_rotate(th1, base[1], base[4], base[7], &s1, &c1);
    double s2, c2;
    pl_rotate(th2, base[2], base[5], base[8], &s2, &c2);
    const double ax = inp[0];
    const double ga = bp[15] + inp[1];
    double t0 = inp[2] + (tk[0] * th0 + tk[1] * th1 + tk[2] * th2) + (tl[0] * w0 + tl[1] * w1 + tl[2] * w2);
    t0 = ((md->sat[0] != 0.0) ? (md->lim[0]*md->sat[0]) : (t0));
    double t1 = inp[3] + (tk[3] * th0 + tk[4] * th1 + tk[5] * th2) + (tl[3] * w0 + tl[4] * w1 + tl[5] * w2);
    t1 = ((md->sat[1] != 0.0) ? (md->lim[1]*md->sat[1]) : (t1));
    double t2 = inp[4] + (tk[6] * th0 + tk[7] * th1 + tk[8] * th2) + (tl[6] * w0 + tl[7] * w1 + tl[8] * w2);
    t2 = ((md->sat[2] != 0.0) ? (md->lim[2]*md->sat[2]) : (t2));
    const double u0 = t1 - t0;
    const double u1 = t2 - t1;
    const double u2 = -t2;
    const double r0 = u0 - (bp[7]*(w1 * w1)*(-c0*s1 + c1*s0) + bp[8]*(w2 * w2)*(-c0*s2 + c2*s0)) + bp[0]*(-ax*c0 + ga*s0);
    const double r1 = u1 - (-bp[7]*(w0 * w0)*(-c0*s1 + c1*s0) + bp[11]*(w2 * w2)*(-c1*s2 + c2*s1)) + bp[1]*(-ax*c1 + ga*s1);
    const double r2 = u2 - (-bp[8]*(w0 * w0)*(-c0*s2 + c2*s0) + -bp[11]*(w1 * w1)*(-c1*s2 + c2*s1)) + bp[2]*(-ax*c2 + ga*s2);
    const double j00 = bp[3];
    const double j01 = bp[7]*(c0*c1 + s0*s1);
    const double j02 = bp[8]*(c0*c2 + s0*s2);
    const double j11 = bp[4];
    const double j12 = bp[11]*(c1*c2 + s1*s2);
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
    double a0 = (m00 * r0 + m01 * r1 + m02 * r2) * inv_det;
    double a1 = (m10 * r0 + m11 * r1 + m12 * r2) * inv_det;
    double a2 = (m20 * r0 + m21 * r1 + m22 * r2) * inv_det;
    if (locked) {  /* knee constraint C = (−1, 1, 0): Θ̈ −= J⁻¹C (C·Θ̈)/(C·J⁻¹C) */
        const double y0 = m01 - m00;
        const double y1 = m11 - m10;
        const double y2 = m21 - m20;
        const double lam = (a1 - a0) / (y1 - y0);
        a0 -= y0 * lam;
        a1 -= y1 * lam;
        a2 -= y2 * lam;
    }
    md->tau[0] = t0;
    md->tau[1] = t1;
    md->tau[2] = t2;
    out[0] = w0;
    out[1] = w1;
    out[2] = w2;
    out[3] = a0;
    out[4] = a1;
    out[5] = a2;
}
