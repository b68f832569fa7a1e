"""The words of a run's outcome (both engines): :func:`outcome_message`."""

from __future__ import annotations

from typing import Protocol


class RunSetup(Protocol):
    """What the words of an outcome read of a run's set-up
    (:class:`posturelab.simulation.setup.RunSetup`)."""

    @property
    def duration(self) -> float: ...  # [s]

    @property
    def max_switches(self) -> int: ...  # [-]

    @property
    def max_steps(self) -> int: ...  # [-]

    @property
    def time_limit(self) -> float: ...  # [s]

__all__ = ["IMPLICIT_METHODS", "outcome_message"]

#: The implicit integrators (of scipy's solve_ivp and the compiled engine's Radau IIA).
IMPLICIT_METHODS = ("Radau", "BDF", "LSODA")


def outcome_message(status: str, t: float, setup: RunSetup, *, fall_reason: str = "",
                    detail: str = "", method: str | None = None) -> str:
    """The words of a run's outcome.

    Parameters
    ----------
    status : str
        What happened: one of "completed", "fell", "step-too-small", "non-finite",
        "chattering", "no-memory", "step-budget", "time-budget", "failed" ("failed" takes
        its words from ``detail``).
    t : float
        When it happened (the fall, the failure). [s]
    method : str, optional
        The integrator that ran ("Radau", "RK45", "DOP853", …): a spent step budget suggests
        an implicit method only to a run that had an explicit one.
    """
    if status == "completed":
        return f"ran to {setup.duration:g} s"
    if status == "fell":
        when = "0 s" if t == 0.0 else f"{t:.4f} s"
        return f"fell at t = {when}: {fall_reason}"
    if status == "step-too-small":
        return (f"integrator failed at t = {t:.6g} s: required step size is less than "
                "spacing between numbers")
    if status == "non-finite":
        return f"state diverged (non-finite) at t = {t:.6g} s"
    if status == "chattering":
        return f"more than {setup.max_switches} switches by t = {t:.6g} s (chattering)"
    if status == "no-memory":
        return f"ran out of memory at t = {t:.6g} s"
    if status == "step-budget":
        if method in IMPLICIT_METHODS:
            advice = f"raise max_steps; the {method} method that ran is already implicit"
        else:
            advice = ("raise max_steps; for very stiff or viscous gains an implicit method "
                      "such as Radau needs far fewer steps")
        return (f"stopped at t = {t:.6g} s: the step budget of {setup.max_steps:,} integrator "
                f"steps ran out ({advice})")
    if status == "time-budget":
        return (f"stopped at t = {t:.6g} s: the time limit of {setup.time_limit:g} s "
                "(wall clock) ran out (raise time_limit)")
    return detail
