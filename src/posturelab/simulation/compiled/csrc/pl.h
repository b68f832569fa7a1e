/* posturelab's compiled engine: shared declarations.
 *
 * The physics is that of posturelab.model (the equation of motion of an N-link chain on a
 * moving platform under muscle-pair feedback), the events those of posturelab.model.events,
 * the run set-up that of posturelab.simulation.setup; Python packs them into the structs
 * below (posturelab/simulation/compiled/_binding.py mirrors them field by field).
 *
 * Units: SI throughout (m, kg, s, rad, N·m). Arrays are C-ordered doubles unless stated.
 */
#ifndef PL_H
#define PL_H

#include <math.h>
#include <stdint.h>

#include "pl_codes.h"  /* the codes and layouts (generated; _layout.py states the same) */

/* Packed motor noise (posturelab.model.noise.TorqueSeries): mp[0] = K intervals (0: none),
 * then K + 1 knots, then K·4·n coefficients, interval-major, ascending powers of t − knot,
 * joint fastest. */

#include "pl_model.h"  /* pl_run, pl_out, the model's structs and functions (generated) */

/* linear algebra (pl_linalg.c) */
void pl_solve_into(double *M, int64_t n, int64_t ncol, int64_t stride);
void pl_lu_factor(double *A, int64_t *piv, int64_t n);
void pl_lu_solve(const double *A, const int64_t *piv, double *b, int64_t n);
void pl_inverse3(const double *a, double *out);
void pl_inverse3_complex(const double *ar, const double *ai, double *outr, double *outi);

/* history of a delayed run (pl_history.c) */
typedef struct pl_history {
    int64_t m, count, cap;  /* m: the first m components of a state ([Θ, Θ̇]) */
    double *t, *h, *x, *q;   /* (cap), (cap), (cap, m), (cap, m, 4) */
} pl_history;
int pl_history_init(pl_history *hist, int64_t m, int64_t cap);
int pl_history_add(pl_history *hist, double t, double h, const double *x, const double *Q);
void pl_history_at(const pl_history *hist, const double *before, double s, double *out);
void pl_history_drop(pl_history *hist);  /* the last step out again (overlapping steps) */
void pl_history_extrapolate(const pl_history *hist, double t, double h, const double *x,
                            double *Q);
void pl_history_free(pl_history *hist);

/* dense output of a step: x + Q·(σ, σ², σ³, σ⁴) */
void pl_dense_at(const double *restrict x, const double *restrict Q, int64_t m, double t0,
                 double h, double t, double *restrict out);

/* the integration loop (pl_driver.c) and the methods (pl_explicit.c, pl_radau.c) */
int64_t pl_integrate(const pl_run *run, pl_out *out);

typedef struct pl_method pl_method;
struct pl_method {
    int64_t n_nodes;
    const double *nodes;
    void *ws;
    double (*start)(pl_method *me, const pl_model *md, double t, const double *x,
                    double t_stop, double max_step, double rtol, double atol, int locked,
                    const double *inp, int64_t *evals);
    double (*limit)(pl_method *me, double h, double max_step);
    int (*attempt)(pl_method *me, const pl_model *md, double t, double h, const double *x,
                   double *y, double *Q, const double *inp, double rtol, double atol,
                   int locked, double *h_next, int64_t *evals);
    void (*commit)(pl_method *me);
    void (*release)(pl_method *me);
    /* after a step onto a breakpoint: the first stage again, from the inputs just after it */
    void (*refresh)(pl_method *me, const pl_model *md, const double *x, const double *inp,
                    int locked, int64_t *evals);
};
int pl_explicit_init(pl_method *me, const pl_run *run, int64_t n);
int pl_radau_init(pl_method *me, int64_t n, int64_t m);
void pl_radau_constants(void);  /* once, at import */
double pl_initial_step(const pl_model *md, double t0, const double *y0, const double *f0,
                       double t_bound, double max_step, double rtol, double atol, int locked,
                       const double *inp, double *y1, double *f1, int64_t m, int order);

#endif
