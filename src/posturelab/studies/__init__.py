"""Studies built on the simulators: parameter sweeps (:mod:`.sweep`), the largest
recoverable perturbation (:mod:`.recovery`), the largest translation withstood without a
step (:mod:`.stepping`) and identification of the gains from
measured angles (:mod:`.identification`). Each module is imported on first use."""

from .._lazy import submodule_getattr  # noqa: E402

__getattr__ = submodule_getattr(__name__, __path__)
