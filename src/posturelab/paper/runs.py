"""The simulations behind the reproduction report: the paper's four built-in scenarios
(Figs. 3–10) and the runs added beyond the paper.

:func:`run_paper` runs them once; :class:`PaperRuns` holds the results, which
:mod:`posturelab.paper.checks` turns into verdicts and findings and :mod:`.figures` draws.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..model.muscles import paper_muscles
from ..model.options import FOOT_FROM_LITERATURE, BaseOfSupport, FallCriteria
from ..simulation.results import SimulationResult

if TYPE_CHECKING:
    from ..scenarios import Scenario

__all__ = ["PAPER_SCENARIOS", "CASE3_LONG_DURATION", "RUN_STEPS", "PaperRuns", "run_paper"]

#: Key of a run -> (built-in scenario name, the paper's figures it gives).
PAPER_SCENARIOS: dict[str, tuple[str, str]] = {
    "backward": ("paper-backward-case1", "Figs. 3–7"),
    "forward1": ("paper-forward-case1", "Fig. 8"),
    "forward2": ("paper-forward-case2", "Fig. 9"),
    "forward3": ("paper-forward-case3", "Fig. 10"),
}
#: The gastrocnemius of the finding beyond the paper: the paper's real one (section V.C),
#: acting only while θ2 >= 0 (``--gastrocnemius one-sided``; GASTROCNEMIUS_FORMS).
ONE_SIDED_FORM = "one-sided"

#: Duration of the continued Fig. 10 run (case 3), to see whether it settles at all. [s]
CASE3_LONG_DURATION = 60.0
#: Sampling rate of the continued Fig. 10 run. [Hz]
CASE3_LONG_SAMPLE_RATE = 100.0
#: Progress steps :func:`run_paper` reports. [-]
RUN_STEPS = len(PAPER_SCENARIOS) + 2


@dataclass(frozen=True)
class PaperRuns:
    """The simulation results of the report.

    Attributes
    ----------
    backward, forward1, forward2, forward3 : SimulationResult
        The built-in scenarios of Figs. 3–7, 8, 9 and 10, as the paper ran them.
    forward3_long : SimulationResult
        ``forward3`` continued to :data:`CASE3_LONG_DURATION` [s].
    one_sided : SimulationResult
        ``forward1`` with the real, one-sided gastrocnemius (beyond the paper).
    backward_with_foot, forward1_with_foot : SimulationResult
        ``backward`` and ``forward1`` with posturelab's base-of-support fall check
        on ``foot``.
    foot : BaseOfSupport
        The typical foot of the foot findings (heel and toe from the ankle [m]).
    scenarios : mapping of str to Scenario
        The built-in scenarios, by the keys of :data:`PAPER_SCENARIOS`.
    """

    backward: SimulationResult
    forward1: SimulationResult
    forward2: SimulationResult
    forward3: SimulationResult
    forward3_long: SimulationResult
    one_sided: SimulationResult
    backward_with_foot: SimulationResult
    forward1_with_foot: SimulationResult
    foot: BaseOfSupport
    scenarios: Mapping[str, Scenario]

    @property
    def paper(self) -> dict[str, SimulationResult]:
        """The four runs of the paper's figures, by the keys of :data:`PAPER_SCENARIOS`."""
        return {"backward": self.backward, "forward1": self.forward1,
                "forward2": self.forward2, "forward3": self.forward3}


def run_paper(tick: Callable[[str], None] | None = None,
              foot: BaseOfSupport = FOOT_FROM_LITERATURE) -> PaperRuns:
    """Run the paper's scenarios and the runs beyond the paper.

    Parameters
    ----------
    tick : callable(message), optional
        Called before each of the :data:`RUN_STEPS` steps.
    foot : BaseOfSupport
        The foot of the base-of-support runs (heel and toe from the ankle [m]).

    Returns
    -------
    PaperRuns
    """
    from ..scenarios import builtin_scenario

    def step(message: str) -> None:
        if tick is not None:
            tick(message)

    runs: dict[str, SimulationResult] = {}
    scen = {}
    for key, (sname, figs) in PAPER_SCENARIOS.items():
        step(f"simulate {sname} ({figs})")
        scen[key] = builtin_scenario(sname)
        runs[key] = scen[key].run()
    step(f"simulate paper-forward-case3 continued to {CASE3_LONG_DURATION:g} s")
    # (60 s of a slowly settling run: the compiled engine, at the scenario's tolerances)
    long3 = scen["forward3"].run(duration=CASE3_LONG_DURATION,
                                 sample_rate=CASE3_LONG_SAMPLE_RATE, engine="compiled")
    step("simulate forward case 1 with the real one-sided gastrocnemius (beyond the paper)")
    # the runs beyond the paper on the compiled engine, at the scenarios' tolerances; the
    # gastrocnemius of the finding is the paper's real one (ONE_SIDED_FORM)
    one_sided = scen["forward1"].run(muscles=paper_muscles("1", gastrocnemius=ONE_SIDED_FORM),
                                     engine="compiled")
    # the same runs with posturelab's own base-of-support fall check (an independent path to
    # the foot finding: events in the integrator instead of post-processing)
    with_foot = {k: scen[k].run(fall=FallCriteria(scen[k].fall.max_link_angle, foot),
                                engine="compiled")
                 for k in ("backward", "forward1")}
    return PaperRuns(
        backward=runs["backward"], forward1=runs["forward1"], forward2=runs["forward2"],
        forward3=runs["forward3"], forward3_long=long3, one_sided=one_sided,
        backward_with_foot=with_foot["backward"], forward1_with_foot=with_foot["forward1"],
        foot=foot, scenarios=scen,
    )
