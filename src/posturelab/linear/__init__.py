"""Linear analysis about upright: state matrix, poles, stability, delay margins, disturbance
sensitivity.

Everything derives from one batched delayed linear system (:mod:`.system`:
:func:`linear_system` builds a :class:`LinearSystem` from a body and muscles, or from
arrays of gains). :mod:`.analysis` handles one parameter set (numpy); :mod:`.delay` the
delay margin and rightmost roots of one set; :mod:`.margins` the delay margins of many
sets (:func:`batch_delay_margin`); :mod:`.batch` evaluates millions of sets at once with
compiled kernels (imported on first use); :mod:`.verdict` gives the one verdict about
upright.
"""

from .._lazy import submodule_getattr  # noqa: E402
from .analysis import (
    LinearAnalysis,
    OneSided,
    analyse,
    analyse_both_sides,
    disturbance_sensitivity,
    finite_difference_state_matrix,
    sorted_poles,
    state_matrix,
)
from .margins import BatchDelayMargin, batch_delay_margin
from .system import LinearSystem, linear_system

__getattr__ = submodule_getattr(__name__, __path__)
