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

#include "pl_model.h"  /* pl_run, pl_out, the model's structs and functions (generated) */

/* linear algebra and work arrays (pl_linalg.c) */
int pl_alloc_block(double **const *slots, const int64_t *sizes, int64_t count);
int64_t pl_interval_of(const double *x, int64_t lo, int64_t hi, double t);
void pl_solve_into(double *M, int64_t n, int64_t ncol, int64_t stride);
void pl_lu_factor(double *A, int64_t *piv, int64_t n);
void pl_lu_solve(const double *A, const int64_t *piv, double *b, int64_t n);
void pl_inverse3(const double *a, double *out);
void pl_inverse3_complex(const double *ar, const double *ai, double *outr, double *outi);

/* history of a delayed run (pl_history.c) */
typedef struct pl_history {
    int64_t m, count, cap;  /* m: the first m components of a state ([Θ, Θ̇]) */
    double *t, *rec;        /* (cap) step starts; (cap, 1 + 5m) records: h, x (m), Q (m, 4) */
} pl_history;
int pl_history_init(pl_history *hist, int64_t m, int64_t cap);
int pl_history_add(pl_history *hist, double t, double h, const double *x, const double *Q);
void pl_history_at(const pl_history *hist, const double *before, double s, double *out);
void pl_history_drop(pl_history *hist);  /* the last step out again (overlapping steps) */
void pl_history_extrapolate(const pl_history *hist, double t, double h, double *Q);
void pl_history_free(pl_history *hist);

/* dense output of a step at σ = (t − t0)/h: x + Q·(σ, σ², σ³, σ⁴) */
void pl_dense_at(const double *restrict x, const double *restrict Q, int64_t m, double s,
                 double *restrict out);

/* the integration loop (pl_driver.c), the roots of events (pl_events.c) and the methods
 * (pl_explicit.c, pl_radau.c) */
int64_t pl_integrate(const pl_run *run, pl_out *out);
double pl_event_root(const pl_ctx *cx, int64_t kind, int64_t idx, double side, double t0,
                     double t1, double g0, double g1, const double *x, const double *Q,
                     double h, int locked);

typedef struct pl_method pl_method;
struct pl_method {
    int64_t n_nodes, order;  /* order: of the error estimate, for the first step's size */
    const double *nodes;
    /* f(t, x) at the step's start, which the loop evaluates (at a segment's start, and after
     * a step onto a breakpoint from the inputs just after it), and at the end of the step
     * just taken, which becomes the next one's f0 when the step is kept */
    double *f0, *f_end;
    void *ws, *arrays;  /* the method's state and its work arrays (freed by the loop) */
    /* a smooth segment starts at x (f0 evaluated): the method's own start-up */
    void (*start)(pl_method *me, const pl_model *md, const double *x, const double *inp,
                  int locked, double rtol, int64_t *evals);
    void (*capped)(pl_method *me);  /* a step cut to the largest step (NULL: nothing to do) */
    int (*attempt)(pl_method *me, const pl_model *md, double t, double h, const double *x,
                   double *y, double *Q, const double *inp, double rtol, double atol,
                   int locked, double *h_next, int64_t *evals);
};
int pl_explicit_init(pl_method *me, const pl_run *run, int64_t n);
int pl_radau_init(pl_method *me, int64_t n, int64_t m);

#endif
