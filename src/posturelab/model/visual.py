"""The visual channel: a visual-scene tilt v(t) and the pair gains it acts through.

Peterka's independent-channel model (Peterka 2002, "Sensorimotor integration in human
postural control", J Neurophysiol 88:1097–1118) senses body orientation by three channels
with weights that sum to 1: proprioceptive W_p (relative to the support surface), visual W_v
(relative to the visual scene) and graviceptive W_g = 1 − W_p − W_v (relative to the
vertical). In posturelab's signs (docs/conventions.md: θ positive leaning forward, a tilt
positive toes-up) a surface tilted toes-up by α has its "vertical" leaning back by α, so a
pair that spans the foot is stretched by θ_hi + α; the scene v is positive in the same sense
(pitched toes-up: its vertical leans back by v, about the ankle axis), so a body aligned with
the scene has θ = −v. The active (neural) part of a pair that spans the foot then feels

    W_p·(θ_hi + α) + W_v·(θ_hi + v) + W_g·θ_hi = θ_hi + W_p·α + W_v·v,

and the scene acts only through that delayed active feedback: it has no mechanical effect
(the intrinsic part feels the foot, not the scene). For one link with intrinsic gains K_i,
L_i and active C(s) = (K_a + L_a s)e^{−sτ} the scene-to-sway FRF, in the literature's sign
(−θ/v: following the scene reads 1), is W_v·C/(J s² − mgh + K_i + L_i s + C).

The profiles are those of a surface tilt (:mod:`.tilt`: sine, raised cosine, PRTS, measured).
"""

from __future__ import annotations

import numpy as np

from .tilt import tilt_pair_gains

__all__ = ["visual_pair_gains"]


def visual_pair_gains(split_gains: np.ndarray, spans_foot: np.ndarray, delay,
                      visual_weight) -> np.ndarray:
    """Pair gains on the visual-scene tilt, (…, 4, P): on v(t), v̇(t), v(t − τ), v̇(t − τ).

    The scene has no mechanical effect: only the active part of a pair that spans the foot
    feels it, as W_v·v in its sensory-weighted error (module notes). Without a delay the
    active gains act at once (rows 0, 1), as :func:`.tilt.tilt_pair_gains` places them.

    Parameters
    ----------
    split_gains : numpy.ndarray, shape (..., 4, P)
        As for :func:`.tilt.tilt_pair_gains`. [N·m/rad], [N·m·s/rad]
    spans_foot : numpy.ndarray of bool, shape (P,)
    delay : float or array_like, shape (...)
        τ. [s]
    visual_weight : float or array_like, shape (...)
        W_v in [0, 1]. [-]

    Returns
    -------
    numpy.ndarray, shape (..., 4, P)
        [N·m/rad], [N·m·s/rad], [N·m/rad], [N·m·s/rad]
    """
    from .gains import IMMEDIATE_STIFFNESS, IMMEDIATE_VISCOSITY

    active_only = np.array(split_gains, dtype=float)
    active_only[..., [IMMEDIATE_STIFFNESS, IMMEDIATE_VISCOSITY], :] = 0.0
    return tilt_pair_gains(active_only, spans_foot, delay, visual_weight)
