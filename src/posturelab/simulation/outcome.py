"""What a run's outcome was, in one of four words, stated once for runs and sweep rows.

* ``recovered``: the run completed, and at its last sample every |θ_i| is within
  :data:`UPRIGHT_BAND` of upright and every |θ̇_i| within :data:`REST_RATE`; the settling
  time is the last sample time at which some |θ_i| was outside the band.
* ``not recovered``: the run completed but ended outside that band of upright, or still
  moving; the final lean max |θ_i| [rad] and rate max |θ̇_i| [rad/s] say how far. Under a
  stimulus that lasts to the end (a held or periodic tilt, motor noise) this is expected.
* ``fell``: a fall criterion fired; its reason and time.
* ``failed``: the integration failed; its message.

:func:`classify` is the rule; :class:`Outcome` the frozen record of one run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["UPRIGHT_BAND", "REST_RATE", "OUTCOMES", "Outcome", "classify", "classify_rows"]

#: Half-width of the band about upright a recovered run ends in (and of the settling time). [rad]
UPRIGHT_BAND = 0.01
#: Largest |θ̇_i| at the end of a recovered run. [rad/s]
REST_RATE = 0.05
#: The four outcomes.
OUTCOMES = ("recovered", "not recovered", "fell", "failed")


@dataclass(frozen=True)
class Outcome:
    """The outcome of one run (module notes).

    Attributes
    ----------
    kind : {"recovered", "not recovered", "fell", "failed"}
    settling_time : float or None
        Last sample time outside the upright band; None unless recovered. [s]
    fall_time : float or None
        [s]
    fall_reason : str or None
    final_lean : float
        max |θ_i| at the last sample. [rad]
    final_rate : float
        max |θ̇_i| at the last sample. [rad/s]
    message : str
        The outcome in words.
    """

    kind: str
    settling_time: float | None
    fall_time: float | None
    fall_reason: str | None
    final_lean: float
    final_rate: float
    message: str

    def to_dict(self) -> dict:
        """Plain-Python form (times [s], lean [rad], rate [rad/s])."""
        return {"outcome": self.kind, "settling_time": self.settling_time,
                "fall_time": self.fall_time, "fall_reason": self.fall_reason,
                "final_lean": self.final_lean, "final_rate": self.final_rate,
                "outcome_message": self.message}


def classify_rows(status: np.ndarray, settling_time: np.ndarray, final_state: np.ndarray
                  ) -> np.ndarray:
    """The outcome word of many runs: ``status`` ("completed", "fell", "failed") (M,),
    ``settling_time`` [s] (M,) (NaN: never settled), ``final_state`` [rad, rad/s] (M, 2N).
    Returns an array of str, (M,)."""
    status = np.asarray(status)
    final_state = np.asarray(final_state, dtype=float)
    n = final_state.shape[-1] // 2
    lean = np.abs(final_state[..., :n]).max(axis=-1)
    rate = np.abs(final_state[..., n:]).max(axis=-1)
    at_rest = (lean <= UPRIGHT_BAND) & (rate <= REST_RATE) & np.isfinite(
        np.asarray(settling_time, dtype=float))
    return np.where(status == "failed", "failed", np.where(
        status == "fell", "fell", np.where(at_rest, "recovered", "not recovered")))


def classify(status: str, settling_time: float | None, final_state, *, fall_time=None,
             fall_reason=None, message: str = "") -> Outcome:
    """The :class:`Outcome` of one run (arguments as for :func:`classify_rows`, one run;
    ``message``: the run's own words, kept for a failure)."""
    final_state = np.asarray(final_state, dtype=float)
    n = final_state.size // 2
    lean = float(np.abs(final_state[:n]).max())
    rate = float(np.abs(final_state[n:]).max())
    kind = str(classify_rows(np.array([status]), np.array(
        [np.nan if settling_time is None else settling_time]), final_state[None])[0])
    if kind == "recovered":
        words = f"recovered: within ±{UPRIGHT_BAND:g} rad of upright from {settling_time:.3f} s"
    elif kind == "not recovered":
        words = (f"not recovered: ended {lean:.4g} rad from upright, moving at up to "
                 f"{rate:.4g} rad/s (recovered means within ±{UPRIGHT_BAND:g} rad and "
                 f"{REST_RATE:g} rad/s)")
    elif kind == "fell":
        words = message or f"fell at t = {fall_time} s: {fall_reason}"
    else:
        words = f"failed: {message}" if message else "failed"
    return Outcome(kind, settling_time if kind == "recovered" else None,
                   fall_time if kind == "fell" else None,
                   fall_reason if kind == "fell" else None, lean, rate, words)
