/* The whole engine as one translation unit, so that the compiler can inline across what the
 * other files split by topic (setup.py compiles only this file). */
#include "pl_linalg.c"
#include "pl_platform.c"
#include "pl_rhs.c"
#include "pl_rhs_small.c"
#include "pl_history.c"
#include "pl_explicit.c"
#include "pl_radau.c"
#include "pl_events.c"
#include "pl_driver.c"
#include "pl_module.c"
