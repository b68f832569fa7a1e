"""Linear analysis about upright: state matrix, poles, stability, disturbance sensitivity.

:mod:`.analysis` handles one parameter set (numpy); :mod:`.batch` evaluates
millions of sets at once with compiled kernels (imported on first use).
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

__getattr__ = submodule_getattr(__name__, __path__)
