/* The whole engine as one translation unit, so that the compiler can inline across what the
 * other files split by topic (setup.py compiles only this file). */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L /* clock_gettime, for a run's time limit (as Python.h sets it) */
#endif
#include "pl_linalg.c"
#include "pl_model.c"
#include "pl_rhs_small.c"
#include "pl_history.c"
#include "pl_explicit.c"
#include "pl_radau.c"
#include "pl_events.c"
#include "pl_driver.c"
#include "pl_module.c"
