"""PRTS experiments over a population of parameter sets: simulate, estimate, fit, per run.

:func:`prts_sweep` takes a base experiment (a :class:`~posturelab.scenarios.Scenario` with
a :class:`~posturelab.model.tilt.PRTSTilt`) and the parameters to vary, as
:func:`posturelab.studies.sweep.run_sweep` does (the same grid, the same names), and runs on
each parameter set the in-silico identification experiment of
:func:`posturelab.frequency.experiment.prts_experiment` (a :class:`PRTSProtocol`): the
nonlinear model on the compiled engine for ``discard + cycles`` cycles, seeded measurement
noise on the recorded angle, the scenario's motor noise, the FRF at the bands, and, if
asked, :func:`posturelab.frequency.fit.fit_frf` of the ``fit`` parameters, started from the base
experiment's values (what an experimenter would assume before seeing the subject).

Seeds: run r's measurement noise uses the seed ``SeedSequence([seed, r])`` and its motor
noise ``SeedSequence([motor_noise.seed, r])``, so each virtual subject has its own noise and
the table does not depend on how the runs were split into chunks or spread over Dask
workers.

The table has one row per run: the varied values, ``fell``, then per band b (1 … B)
``gain_b``, ``phase_deg_b`` [deg], ``coherence_b`` [-], then per fitted parameter
``fit_NAME`` and ``se_NAME`` (its unit) and ``fit_error`` [-]. A run that fell has empty
(NaN) FRF and fit cells.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from inspect import signature
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..scenarios import Scenario
from ..simulation.options import RunOptions
from .experiment import (  # (the one experiment: its bounds and defaults)
    MAX_RECORD_RATE,
    MAX_SENSOR_NOISE,
    prts_experiment,
)

__all__ = ["PRTSProtocol", "PRTSSweepResult", "prts_sweep", "MAX_EXPERIMENTS"]

#: Most experiments one sweep may run (each is a simulation of minutes of stance). [-]
MAX_EXPERIMENTS = 100_000


#: One experiment's defaults, stated once (in :func:`prts_experiment`'s signature); a
#: :class:`PRTSProtocol` takes them, all but ``bands``.
_EXPERIMENT = {name: p.default for name, p in signature(prts_experiment).parameters.items()}


@dataclass(frozen=True)
class PRTSProtocol:
    """What each run of :func:`prts_sweep` does; by default what
    :func:`~posturelab.frequency.experiment.prts_experiment` does, but for ``bands``.

    Parameters
    ----------
    cycles, discard : int
        Cycles analysed (>= 2), and cycles run before them and dropped (>= 0). [-]
    sensor_noise : float
        Standard deviation of the white measurement noise on the recorded angle. [rad]
    seed : int
        Of the measurement noise (module notes).
    sample_rate : float
        Of the recording. [Hz]
    output : str
        The angle recorded: ``com_angle`` or ``thetaI``.
    bands : "peterka", "harmonics" or a list of lists of odd-harmonic numbers
        As for :func:`posturelab.frequency.estimate_frf`; "peterka" (the 11 bands of an
        80-state sequence) becomes the sequence's own for another length
        (:func:`posturelab.frequency.bands.sequence_bands`).
    fit : tuple of str
        Parameters for :func:`posturelab.frequency.fit.fit_frf` to estimate per run (the
        parameter table's names: ``active_stiffness:ankle``, ``feedback_delay``, …); none:
        no fit.
    """

    cycles: int = _EXPERIMENT["cycles"]
    discard: int = _EXPERIMENT["discard"]
    sensor_noise: float = _EXPERIMENT["sensor_noise"]
    seed: int = _EXPERIMENT["seed"]
    sample_rate: float = _EXPERIMENT["sample_rate"]
    output: str = _EXPERIMENT["output"]
    bands: Any = "peterka"
    fit: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name, value, least in (("cycles", self.cycles, 2), ("discard", self.discard, 0),
                                   ("seed", self.seed, 0)):
            if isinstance(value, bool) or not isinstance(value, int | np.integer) \
                    or value < least:
                raise ParameterError(f"{name} must be an integer >= {least}, got {value!r}")
        from .._validation import float_in_range

        float_in_range("sensor_noise [rad]", self.sensor_noise, 0.0, MAX_SENSOR_NOISE,
                       unit="rad")
        float_in_range("sample_rate (--record-rate) [Hz]", self.sample_rate, 1.0,
                       MAX_RECORD_RATE, unit="Hz")
        if not isinstance(self.output, str):
            raise ParameterError(f"output must be com_angle or thetaN, got {self.output!r}")
        if isinstance(self.fit, str):
            raise ParameterError("fit is a sequence of parameter names, not one string")
        object.__setattr__(self, "fit", tuple(self.fit))


def _row_seed(seed: int, row: int) -> int:
    return int(np.random.SeedSequence([int(seed), int(row)]).generate_state(1)[0])


@dataclass(frozen=True)
class _ExperimentTask:
    """What every chunk of a PRTS sweep shares."""

    scenario: Scenario
    protocol: PRTSProtocol

    def run(self, grid, lo: int, hi: int, parallel: bool) -> list[tuple]:
        from .fit import fit_frf

        sc, pr = self.scenario, self.protocol
        base = sc.muscles
        out = []
        for r in range(lo, hi):
            muscles = _run_muscles(base, grid, r)
            options = RunOptions(
                feedback_delay=float(grid.feedback_delay[r]),
                proprioceptive_weight=float(
                    sc.proprioceptive_weight if grid.proprioceptive_weight is None
                    else grid.proprioceptive_weight[r]),
                knee=sc.knee, fall=sc.fall,
                torque_limits=(None if grid.torque_limits is None
                               else tuple(grid.torque_limits[r])),
                motor_noise=(None if sc.motor_noise is None else replace(
                    sc.motor_noise, seed=_row_seed(sc.motor_noise.seed, r))))
            exp = prts_experiment(sc.body, muscles, tilt=sc.tilt, cycles=pr.cycles,
                                  discard=pr.discard, sensor_noise=pr.sensor_noise,
                                  seed=_row_seed(pr.seed, r), sample_rate=pr.sample_rate,
                                  output=pr.output, bands=pr.bands, options=options)
            fit = None
            if exp.estimate is not None and pr.fit:
                fit = fit_frf(sc.body, base, exp.estimate, pr.fit, output=pr.output,
                              feedback_delay=sc.feedback_delay,
                              proprioceptive_weight=sc.proprioceptive_weight)
            out.append((exp.fell, exp.estimate, fit))
        return out


def _run_muscles(base, grid, r: int):
    """The base layout with run r's gains."""
    pairs = tuple(replace(p, stiffness=float(grid.stiffness[r, i]),
                          viscosity=float(grid.viscosity[r, i]))
                  for i, p in enumerate(base.pairs))
    muscles = type(base)(pairs, base.n_links)
    if grid.active_stiffness is not None:
        muscles = muscles.with_active_feedback(grid.active_stiffness[r],
                                               grid.active_viscosity[r])
    return muscles


@dataclass(frozen=True)
class PRTSSweepResult:
    """One row per run of :func:`prts_sweep`.

    Attributes
    ----------
    grid : SweepGrid
        The runs and their parameters.
    protocol : PRTSProtocol
    frequency : numpy.ndarray, shape (B,)
        Band frequencies. [Hz]
    fell : numpy.ndarray of bool, shape (M,)
    frf : numpy.ndarray of complex, shape (M, B)
        The estimates (NaN for a run that fell). [rad/rad]
    coherence : numpy.ndarray, shape (M, B)
        [-]
    fit_names : tuple of str
    fit_estimates, fit_standard_errors : numpy.ndarray, shape (M, K)
        In each parameter's unit (:data:`posturelab.frequency.fit.PARAMETERS`).
    fit_error : numpy.ndarray, shape (M,)
        √(χ²/dof) of each fit (:attr:`FRFFit.fit_error`; ≈ 1 when the model explains the
        data). [-]
    """

    grid: Any
    protocol: PRTSProtocol
    frequency: np.ndarray
    fell: np.ndarray
    frf: np.ndarray
    coherence: np.ndarray
    fit_names: tuple[str, ...]
    fit_estimates: np.ndarray
    fit_standard_errors: np.ndarray
    fit_error: np.ndarray

    @property
    def gain(self) -> np.ndarray:
        """|H|, (M, B). [-]"""
        return np.abs(self.frf)

    @property
    def phase_deg(self) -> np.ndarray:
        """arg H unwrapped along the bands, (M, B). [deg]"""
        return np.degrees(np.unwrap(np.angle(self.frf), axis=1))

    def columns(self) -> list[tuple[str, np.ndarray]]:
        """(name, values) of every column, in table order (module notes)."""
        cols = [(name, self.grid.values[:, k]) for k, name in enumerate(self.grid.names)]
        cols.append(("fell", self.fell))
        B = self.frequency.size
        for label, values in (("gain", self.gain), ("phase_deg", self.phase_deg),
                              ("coherence", self.coherence)):
            cols += [(f"{label}_{b + 1}", values[:, b]) for b in range(B)]
        for k, name in enumerate(self.fit_names):
            cols.append((f"fit_{name}", self.fit_estimates[:, k]))
            cols.append((f"se_{name}", self.fit_standard_errors[:, k]))
        if self.fit_names:
            cols.append(("fit_error", self.fit_error))
        return cols

    def write(self, path: str | Path) -> None:
        """Write the table to ``path`` (.csv or .parquet by its suffix), atomically."""
        from ..studies.sweep import write_table

        write_table(path, self.columns(), self.units())

    def units(self) -> dict[str, str]:
        """The unit of each column that has one."""
        from ..parameters import unit

        units = {name: unit(name) for name in self.grid.names}
        units.update({f"phase_deg_{b + 1}": "deg" for b in range(self.frequency.size)})
        for name in self.fit_names:
            units[f"fit_{name}"] = units[f"se_{name}"] = unit(name)
        return units


def prts_sweep(scenario: Scenario, varies: Sequence, protocol: PRTSProtocol | None = None, *,
               viscosity_ratio: float | None = None, workers: int | None = None,
               scheduler: str | None = None, client: Any = None, chunk_size: int | None = None,
               progress: Callable[[int, int], None] | None = None) -> PRTSSweepResult:
    """Run a PRTS identification experiment for every parameter set of a sweep grid.

    Parameters
    ----------
    scenario : Scenario
        The base experiment; its tilt must be a PRTS (``--tilt prts:…``).
    varies : sequence of VaryRange
        As for :func:`posturelab.studies.sweep.run_sweep`.
    protocol : PRTSProtocol, optional
        Default: 5 analysed cycles after 1 discarded, no measurement noise, no fit.
    viscosity_ratio, workers, scheduler, client, chunk_size, progress
        As for :func:`posturelab.studies.sweep.run_sweep` (a chunk is 8 experiments here).

    Raises
    ------
    ParameterError
        No PRTS tilt, more than :data:`MAX_EXPERIMENTS` runs, a sweep parameter the PRTS
        experiment has no use for (``disturbance_scale``), an unknown fit parameter.
    """
    import os

    from ..model.tilt import PRTSTilt
    from ..studies.sweep import SweepInterrupted, run_chunks, sweep_grid
    from .bands import band_frequencies, resolve_bands
    from .experiment import check_length, check_output
    from .fit import _name

    protocol = PRTSProtocol() if protocol is None else protocol
    if not isinstance(scenario.tilt, PRTSTilt):
        raise ParameterError("a PRTS experiment sweep needs a PRTS tilt in the base experiment "
                             "(--tilt prts:AMPLITUDE_RAD)")
    if any(v.name == "disturbance_scale" for v in varies):
        raise ParameterError("disturbance_scale has no meaning in a PRTS experiment sweep "
                             "(the stimulus is the tilt)")
    if any(v.name == "visual_weight" for v in varies):
        raise ParameterError("visual_weight has no effect in a PRTS experiment sweep (its "
                             "stimulus is the platform tilt; W_v weighs a visual-scene tilt)")
    if scenario.options.visual_tilt is not None:
        raise ParameterError("a PRTS experiment sweep runs the platform tilt alone: leave out "
                             "the visual-scene tilt (a dual-stimulus trial is "
                             "posturelab simulate, frf and fit-frf)")
    # each fit parameter by its one spelling (the parameter table's; columns fit_NAME)
    protocol = replace(protocol, fit=tuple(_name(n, scenario.muscles) for n in protocol.fit))
    grid = sweep_grid(scenario, varies, viscosity_ratio)
    if grid.n_runs > MAX_EXPERIMENTS:
        raise ParameterError(f"the grid has {grid.n_runs:,} runs; a PRTS experiment sweep takes "
                             f"at most {MAX_EXPERIMENTS:,}")
    cycle = scenario.tilt.cycle
    check_length(protocol.cycles, protocol.discard, cycle)
    check_output(protocol.output, scenario.body.n_links)
    samples = int(round(protocol.sample_rate * cycle))
    if samples < 8 or abs(samples - protocol.sample_rate * cycle) > 1e-6 * samples:
        raise ParameterError(f"the record rate {protocol.sample_rate:g} Hz must give a whole "
                             f"number of at least 8 samples per PRTS cycle of {cycle:g} s, "
                             f"got {protocol.sample_rate * cycle:g}")
    bands = protocol.bands
    if isinstance(bands, str) and bands == "peterka" and scenario.tilt.registers != 4:
        from .bands import sequence_bands  # the 11 bands are an 80-state sequence's

        bands = sequence_bands(scenario.tilt)
    bands = resolve_bands(bands, samples // 4)
    protocol = replace(protocol, bands=bands)
    task = _ExperimentTask(scenario, protocol)
    freq = band_frequencies(bands, cycle)
    try:
        parts = run_chunks(task, grid, workers=workers, scheduler=scheduler, client=client,
                           chunk_size=chunk_size, progress=progress, largest_chunk=8,
                           threads=max(1, min(os.cpu_count() or 1, 8)))
    except SweepInterrupted as exc:  # Ctrl-C: the table of the experiments that finished
        if exc.parts:
            exc.result = _sweep_result(grid.head(exc.rows), protocol, freq, exc.parts)
        raise
    return _sweep_result(grid, protocol, freq, parts)


def _sweep_result(grid, protocol: PRTSProtocol, freq: np.ndarray, parts: list
                  ) -> PRTSSweepResult:
    """The table of ``grid``'s experiments from the chunks' rows (fell, estimate, fit)."""
    rows = [row for part in parts for row in part]
    M, B, K = len(rows), freq.size, len(protocol.fit)
    frf = np.full((M, B), np.nan + 1j * np.nan)
    coherence = np.full((M, B), np.nan)
    est, se, err = np.full((M, K), np.nan), np.full((M, K), np.nan), np.full(M, np.nan)
    for r, (_, e, f) in enumerate(rows):
        if e is not None:
            frf[r], coherence[r] = e.frf, e.coherence
        if f is not None:
            est[r], se[r], err[r] = f.estimates, f.standard_errors, f.fit_error
    fell = np.array([fl for fl, _, _ in rows], dtype=bool)
    return PRTSSweepResult(grid, protocol, np.asarray(freq, float), fell, frf, coherence,
                           protocol.fit, est, se, err)
