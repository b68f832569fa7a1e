"""Frequency-domain identification: PRTS stimuli analysed as frequency response functions.

:mod:`.bands` states the stimulus harmonics and the frequency bands (the 80-state COMTEST
protocol's and others), :mod:`.estimate` estimates an FRF with coherence and 95 % bounds
from measured series, :mod:`.model` computes
the linearised model's FRF exactly (the delay as e^{−sτ}), :mod:`.table` holds FRFs given as
gain and phase (published tables), :mod:`.fit` fits a controller to either;
:mod:`.dual` estimates the surface-tilt and visual-scene FRFs of one dual-stimulus trial.
"""

from .bands import PETERKA_BAND_HARMONICS, band_frequencies, harmonic_bands, peterka_bands
from .estimate import FRFEstimate, estimate_frf
from .model import model_frf, model_frf_batch
from .table import FRFTable

__all__ = ["PETERKA_BAND_HARMONICS", "band_frequencies", "harmonic_bands", "peterka_bands",
           "FRFEstimate", "estimate_frf", "model_frf", "model_frf_batch", "FRFTable"]

from .._lazy import submodule_getattr  # noqa: E402

__getattr__ = submodule_getattr(__name__, __path__)
