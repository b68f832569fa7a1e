"""Parameter sweeps of the nonlinear simulation over the paper's pair gains.

A sweep takes a base experiment (a :class:`~posturelab.scenarios.Scenario`
with the paper's five muscle pairs) and a list of parameters to vary, each
over N evenly spaced values from LO to HI inclusive
(:class:`VaryRange`, written ``NAME=LO:HI:N`` on the command line). It
simulates the full grid (the cartesian product, the first parameter varying
slowest) with the compiled simulator (:func:`posturelab.simulation.compiled.simulate_batch`)
and returns one row per run: the varied values, then the outcomes (fell,
fall time, peak |θ_i|, settling time).

Parameters that can vary (:data:`SWEEP_PARAMETERS`; names, units and bounds from the
parameter table, :mod:`posturelab.parameters`): a pair's ``stiffness:PAIR``,
``viscosity:PAIR``, ``active_stiffness:PAIR`` and ``active_viscosity:PAIR`` (the paper's
pairs ankle, knee, hip, quadriceps, gastrocnemius), ``viscosity_ratio`` [s],
``disturbance_scale`` [-], which multiplies the base experiment's platform motion (the
velocity step's speed, a pulse's peak, a ramp's displacement, the sines' amplitudes, a
measured profile's accelerations; see :meth:`posturelab.model.platform.Disturbance.scaled`),
so that a sweep over it finds how large a perturbation each gain set absorbs,
``feedback_delay`` [s], the neural delay of the muscle feedback,
``proprioceptive_weight`` [-], and ``torque_limit:JOINT`` [N·m] (ankle, knee, hip), the
largest net muscle moment at each joint (the others keep the base experiment's
limits; none by default). Every feature of the base experiment (torque limits, a
delay, centre-of-pressure falls) carries into the sweep. The viscosity of a pair is
the varied ``viscosity:PAIR``, else the ratio times its stiffness: the varied ratio, else
the one given, else the base experiment's own ratio for that pair (0.25, the paper's,
where its stiffness is 0). The table's columns are named by the parameters verbatim.

Work can go to a Dask distributed cluster (:func:`run_sweep` with
``workers``/``scheduler``/``client``) in chunks; the results are identical to
the single-process path (each run is the same deterministic computation).
"""

from __future__ import annotations

import contextlib
import io
import itertools
import math
import os
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError, PostureLabError
from ..model.muscles import DEFAULT_VISCOSITY_RATIO
from ..model.platform import NoDisturbance
from ..parameters import PAPER_JOINTS, PAPER_PAIRS, check_value, names_for, parse_name, renamed
from ..parameters import resolve as resolve_name
from ..parameters import unit as parameter_unit
from ..scenarios import Scenario
from ..simulation.outcome import UPRIGHT_BAND
from ..simulation.results import atomic_write_bytes, atomic_write_text
from ..simulation.tolerances import DEFAULT_ATOL, DEFAULT_RTOL

if TYPE_CHECKING:  # (the engine loads when a sweep runs: posturelab --help stays light)
    from ..simulation.compiled import BatchResult

__all__ = [
    "SWEEP_PARAMETERS",
    "PARAMETER_UNITS",
    "OUTCOME_COLUMNS",
    "OUTCOME_UNITS",
    "VaryRange",
    "parse_vary",
    "SweepGrid",
    "sweep_grid",
    "SweepResult",
    "run_sweep",
    "ProgressBar",
    "SweepInterrupted",
]

#: The quantities of the parameter table a sweep can vary (all but active_viscosity_ratio).
SWEEP_QUANTITIES: tuple[str, ...] = (
    "stiffness", "viscosity", "active_stiffness", "active_viscosity", "viscosity_ratio",
    "feedback_delay", "proprioceptive_weight", "torque_limit", "disturbance_scale")
#: The joints whose torque limit a sweep can vary on the paper's body, in joint order.
TORQUE_LIMIT_PARAMETERS: tuple[str, ...] = tuple(f"torque_limit:{j}" for j in PAPER_JOINTS)
#: Names a sweep of the paper's body can vary (:data:`SWEEP_QUANTITIES` over its pairs and
#: joints). Another body's sweep has its own pairs and joints (:func:`sweep_parameters`).
SWEEP_PARAMETERS: tuple[str, ...] = names_for(PAPER_PAIRS, PAPER_JOINTS, SWEEP_QUANTITIES)


def joints_of(n_links: int) -> tuple[str, ...]:
    """The joint names of an N-link body (``torque_limit:JOINT``): ankle, knee, hip on the
    paper's three links."""
    from ..model.muscles import joint_pair_names

    return PAPER_JOINTS if n_links == 3 else joint_pair_names(n_links)[:n_links]


def sweep_parameters(muscles, n_links: int) -> tuple[str, ...]:
    """What a sweep of this pair layout and body can vary (see :data:`SWEEP_PARAMETERS`)."""
    return names_for(tuple(muscles.names), joints_of(n_links), SWEEP_QUANTITIES)


#: Unit of each parameter of a sweep of the paper's body.
PARAMETER_UNITS: dict[str, str] = {n: parameter_unit(n) for n in SWEEP_PARAMETERS}
#: Largest number of runs one sweep may ask for (a bound on the work and memory). [-]
MAX_RUNS = 10_000_000
#: Outcome columns of a sweep table (after the varied parameters), for 3 links.
OUTCOME_COLUMNS: tuple[str, ...] = ("outcome", "failure", "fell", "fall_time", "peak_theta1",
                                    "peak_theta2", "peak_theta3", "settling_time",
                                    "final_lean", "final_rate")
#: Unit of each outcome column ('' for the flag).
OUTCOME_UNITS: dict[str, str] = {"outcome": "", "failure": "", "fell": "", "fall_time": "s",
                                 "peak_theta1": "rad", "peak_theta2": "rad",
                                 "peak_theta3": "rad", "settling_time": "s",
                                 "final_lean": "rad", "final_rate": "rad/s"}
#: Columns added after :data:`OUTCOME_COLUMNS` under a sustained stimulus (periodic or PRTS
#: tilt, sum of sines, motor noise), per link i: ``steady_rms_theta{i}``,
#: ``steady_peak_theta{i}`` [rad] (RMS about upright and peak |·| over the steady part:
#: :mod:`posturelab.simulation.outcome`); ``steady_rms_cop``, ``steady_peak_cop`` [m] follow
#: only when the batch carries them (a sweep does not: single runs report them).
STEADY_COLUMN_PREFIXES = ("steady_rms_theta", "steady_peak_theta", "steady_rms_cop",
                          "steady_peak_cop")


def _steady_unit(name: str) -> str:
    if name.startswith(("steady_rms_theta", "steady_peak_theta")):
        return "rad"
    return "m" if name in ("steady_rms_cop", "steady_peak_cop") else ""


#: Angle threshold of the settling time. [rad]
SETTLE_TOLERANCE = UPRIGHT_BAND

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_VARY_RE = re.compile(rf"^\s*([A-Za-z_][A-Za-z0-9_]*(?::[A-Za-z_][A-Za-z0-9_]*)?)\s*=\s*"
                      rf"({_NUMBER})\s*:\s*({_NUMBER})\s*:\s*([^:\s]+)\s*$")


# ---------------------------------------------------------------------------
# What to vary
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class VaryRange:
    """One swept parameter: ``count`` evenly spaced values from ``low`` to ``high`` inclusive.

    Parameters
    ----------
    name : str
        A parameter name (:data:`SWEEP_PARAMETERS` for the paper's body; the base
        experiment decides which it has: :func:`sweep_parameters`).
    low, high : float
        First and last value, low <= high, both within the parameter table's bounds.
        [N·m/rad], [s] or [-]
    count : int
        Number of values, >= 1 (1 needs low = high). [-]
    """

    name: str
    low: float
    high: float
    count: int

    def __post_init__(self) -> None:
        _check_vary_name(self.name)
        unit = parameter_unit(self.name)
        for label, v in (("LO", self.low), ("HI", self.high)):
            if not (isinstance(v, int | float | np.floating) and math.isfinite(v)):
                raise ParameterError(f"{self.name} {label} [{unit}] must be a finite number, "
                                     f"got {v!r}")
            check_value(self.name, v, f"{self.name} {label}")
        if self.low > self.high:
            raise ParameterError(f"{self.name}: LO ({self.low:g}) must be <= HI "
                                 f"({self.high:g}) [{unit}]")
        if isinstance(self.count, bool) or not isinstance(self.count, int | np.integer):
            raise ParameterError(f"{self.name}: N must be an integer >= 1, got {self.count!r}")
        if self.count < 1:
            raise ParameterError(f"{self.name}: N must be an integer >= 1, got {self.count}")
        if self.count == 1 and self.low != self.high:
            raise ParameterError(f"{self.name}: N = 1 takes a single value, so LO must equal "
                                 f"HI (got {self.low:g} and {self.high:g})")
        object.__setattr__(self, "low", float(self.low))
        object.__setattr__(self, "high", float(self.high))
        object.__setattr__(self, "count", int(self.count))

    @property
    def values(self) -> np.ndarray:
        """The ``count`` values, ``low`` and ``high`` included. [N·m/rad], [s] or [-]"""
        # 15 significant digits: 0.55, not linspace's 0.5499999999999999 (the ends exact)
        values = np.array([float(f"{v:.15g}") for v in np.linspace(self.low, self.high,
                                                                        self.count)])
        values[0], values[-1] = self.low, self.high
        return values

    @property
    def unit(self) -> str:
        """Unit of the parameter."""
        return parameter_unit(self.name)


def _check_vary_name(name) -> None:
    """A name a sweep can vary, on some body (its pair is checked by :func:`check_base`);
    a former spelling gets one line naming the new one."""
    new = renamed(str(name))
    if new is not None:
        raise ParameterError(f"sweep parameter {str(name)!r} is now called {new!r}")
    try:
        quantity, _ = parse_name(str(name))
    except PostureLabError:
        raise ParameterError(f"unknown sweep parameter {str(name)!r}; known: "
                             f"{', '.join(SWEEP_PARAMETERS)}") from None
    if quantity not in SWEEP_QUANTITIES:
        raise ParameterError(f"a sweep cannot vary {str(name)!r}; it varies "
                             f"{', '.join(SWEEP_PARAMETERS)}")


def parse_vary(text: str) -> VaryRange:
    """Parse ``NAME=LO:HI:N`` (N evenly spaced values from LO to HI inclusive).

    Raises
    ------
    ParameterError
        Malformed text, an unknown name (the message lists the known ones),
        LO > HI, a negative value, or N not an integer >= 1.
    """
    m = _VARY_RE.match(str(text))
    if not m:
        name = str(text).split("=", 1)[0].strip()
        if "=" in str(text) and name and not re.fullmatch(r"[a-z][a-z0-9_:]*", name):
            raise ParameterError(f"unknown sweep parameter {name!r} in --vary {text!r}; known: "
                                 f"{', '.join(SWEEP_PARAMETERS)}")
        raise ParameterError(f"--vary must be NAME=LO:HI:N (N evenly spaced values from LO to "
                             f"HI inclusive), got {text!r}")
    name, low, high, count = m.groups()
    name = name.lower()
    _check_vary_name(name)
    if not re.fullmatch(r"\d+", count):
        raise ParameterError(f"--vary {text!r}: N must be an integer >= 1, got {count!r}")
    return VaryRange(name, float(low), float(high), int(count))


# ---------------------------------------------------------------------------
# The grid
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepGrid:
    """The runs of a sweep.

    Attributes
    ----------
    names : tuple of str
        The varied parameters, in the order given.
    values : numpy.ndarray, shape (M, K)
        Row r holds run r's values of the K varied parameters (the cartesian
        product, the first parameter varying slowest). [N·m/rad], [s] or [-]
    stiffness : numpy.ndarray, shape (M, P)
        Pair stiffness of each run, in the base experiment's pair order. [N·m/rad]
    viscosity : numpy.ndarray, shape (M, P)
        Pair viscosity of each run. [N·m·s/rad]
    disturbance_scale : numpy.ndarray, shape (M,), optional
        Factor on the base experiment's platform motion per run; None when not
        varied (every run has the base motion). [-]
    feedback_delay : numpy.ndarray, shape (M,)
        Neural delay of the muscle feedback per run. [s]
    torque_limits : numpy.ndarray, shape (M, N), optional
        Largest net moment at each joint per run (inf for none); None when no run has a
        limit. [N·m]
    active_stiffness, active_viscosity : numpy.ndarray, shape (M, P), optional
        Active (delayed) pair gains per run; None when the base experiment has none and
        none is varied. [N·m/rad], [N·m·s/rad]
    proprioceptive_weight : numpy.ndarray, shape (M,), optional
        W per run; None for the base experiment's. [-]
    """

    names: tuple[str, ...]
    values: np.ndarray
    stiffness: np.ndarray
    viscosity: np.ndarray
    disturbance_scale: np.ndarray | None = None
    feedback_delay: np.ndarray | None = None
    torque_limits: np.ndarray | None = None
    active_stiffness: np.ndarray | None = None
    active_viscosity: np.ndarray | None = None
    proprioceptive_weight: np.ndarray | None = None

    @property
    def n_runs(self) -> int:
        """Number of runs M. [-]"""
        return int(self.values.shape[0])

    def head(self, count: int) -> SweepGrid:
        """The grid of the first ``count`` runs (what an interrupted sweep finished)."""
        from dataclasses import fields

        return SweepGrid(**{f.name: (value[:count] if isinstance(value, np.ndarray) else value)
                            for f in fields(self) for value in [getattr(self, f.name)]})

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values of each varied parameter. [-]"""
        return tuple(len(np.unique(self.values[:, k])) for k in range(len(self.names)))


def _base_ratios(scenario: Scenario, viscosity_ratio: float | None) -> np.ndarray:
    """Viscosity/stiffness of each pair of the base experiment (or the given ratio). [s]"""
    if viscosity_ratio is not None:
        return np.full(len(scenario.muscles.pairs), check_value("viscosity_ratio",
                                                                viscosity_ratio))
    k = np.asarray(scenario.muscles.stiffnesses, dtype=float)
    v = np.asarray(scenario.muscles.viscosities, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(k > 0, v / np.where(k > 0, k, 1.0), DEFAULT_VISCOSITY_RATIO)


def check_base(scenario: Scenario, names: Sequence[str] = ()) -> list[str]:
    """Every varied name must be one the base experiment has (:func:`sweep_parameters`);
    returns each name's one spelling (:func:`posturelab.parameters.resolve`)."""
    joints = joints_of(scenario.body.n_links)
    return [resolve_name(name, scenario.muscles.names, joints, accepts=SWEEP_QUANTITIES,
                         what="sweep parameter") for name in names]


def sweep_grid(scenario: Scenario, varies: Sequence[VaryRange],
               viscosity_ratio: float | None = None) -> SweepGrid:
    """The full grid of a sweep around ``scenario`` (see the module docstring).

    Parameters
    ----------
    scenario : Scenario
        The base experiment (the paper's five pairs).
    varies : sequence of VaryRange
        The parameters to vary; each name at most once.
    viscosity_ratio : float, optional
        Viscosity/stiffness for every pair when ``viscosity_ratio`` is not
        varied; default: the base experiment's ratio per pair. [s]
    """
    varies = list(varies)
    if not varies:
        raise ParameterError("give at least one --vary NAME=LO:HI:N")
    names = check_base(scenario, [v.name for v in varies])
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ParameterError(f"--vary names a parameter more than once: {', '.join(dup)}")
    pair_viscosities = [n for n in names if n.startswith("viscosity:")]
    if "viscosity_ratio" in names and pair_viscosities:
        given = ", --vary ".join(pair_viscosities)
        raise ParameterError(f"--vary viscosity_ratio or --vary {given}, not both (a pair's "
                             "viscosity is either varied or the ratio times its stiffness)")
    m = math.prod(v.count for v in varies)
    if m > MAX_RUNS:
        raise ParameterError(f"the grid has {m:,} runs ({' × '.join(str(v.count) for v in varies)})"
                             f"; a sweep takes at most {MAX_RUNS:,}")
    values = np.array(list(itertools.product(*[v.values for v in varies])), dtype=float)
    values = values.reshape(-1, len(varies))
    stiffness = np.tile(np.asarray(scenario.muscles.stiffnesses, dtype=float), (m, 1))
    ratios = np.tile(_base_ratios(scenario, viscosity_ratio), (m, 1))
    if "disturbance_scale" in names and isinstance(scenario.disturbance, NoDisturbance):
        raise ParameterError("disturbance_scale multiplies the base experiment's platform "
                             "motion, and it has none: give --disturbance, a profile or a "
                             "scenario with a disturbance")
    scale = None
    delay = np.full(m, float(scenario.feedback_delay))
    n = scenario.body.n_links
    base_limits = (np.full(n, math.inf) if scenario.torque_limits is None
                   else np.asarray(scenario.torque_limits, dtype=float))
    limits = np.tile(base_limits, (m, 1))
    muscles = scenario.muscles
    pairs = list(muscles.names)
    joints = list(joints_of(n))
    varies_active = any(nm.startswith("active_") for nm in names)
    ka = va = weight = None
    if muscles.has_active_feedback or varies_active:
        ka = np.tile(muscles.active_stiffnesses, (m, 1))
        va = np.tile(muscles.active_viscosities, (m, 1))
    viscosity: dict[int, np.ndarray] = {}
    for k, name in enumerate(names):
        column = values[:, k]
        quantity, _, member = name.partition(":")
        if quantity == "viscosity_ratio":
            ratios[:] = column[:, None]
        elif quantity == "disturbance_scale":
            scale = np.ascontiguousarray(column)
        elif quantity == "feedback_delay":
            delay = np.ascontiguousarray(column)
        elif quantity == "proprioceptive_weight":
            weight = np.ascontiguousarray(column)
        elif quantity == "torque_limit":
            limits[:, joints.index(member)] = column
        elif quantity == "active_viscosity":
            va[:, pairs.index(member)] = column
        elif quantity == "active_stiffness":
            ka[:, pairs.index(member)] = column
        elif quantity == "viscosity":
            viscosity[pairs.index(member)] = column
        else:
            stiffness[:, pairs.index(member)] = column
    pair_viscosity = ratios * stiffness
    for j, column in viscosity.items():
        pair_viscosity[:, j] = column
    return SweepGrid(tuple(names), values, stiffness, pair_viscosity, scale, delay,
                     None if np.all(np.isinf(limits)) else limits, ka, va, weight)


# ---------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepResult:
    """One row per run: the varied values, then the outcomes.

    Attributes
    ----------
    grid : SweepGrid
        The runs.
    outcomes : BatchResult
        Their outcomes (row r is run r).
    """

    grid: SweepGrid
    outcomes: BatchResult

    def columns(self) -> list[tuple[str, np.ndarray]]:
        """(name, values) of every column, in table order (units: :data:`PARAMETER_UNITS`,
        :data:`OUTCOME_UNITS`)."""
        cols = [(name, self.grid.values[:, k]) for k, name in enumerate(self.grid.names)]
        o = self.outcomes
        n = o.final_state.shape[1] // 2
        cols.append(("outcome", o.outcome))
        cols.append(("failure", o.failure))
        cols.append(("fell", o.fell))
        cols.append(("fall_time", o.fall_time))
        for i in range(o.peak_theta.shape[1]):
            cols.append((f"peak_theta{i + 1}", o.peak_theta[:, i]))
        cols.append(("settling_time", o.settling_time))
        cols.append(("final_lean", np.abs(o.final_state[:, :n]).max(axis=1)))
        cols.append(("final_rate", np.abs(o.final_state[:, n:]).max(axis=1)))
        if o.steady_rms_theta is not None:  # a sustained stimulus: the steady sway
            for i in range(n):
                cols.append((f"steady_rms_theta{i + 1}", o.steady_rms_theta[:, i]))
                cols.append((f"steady_peak_theta{i + 1}", o.steady_peak_theta[:, i]))
            if o.steady_rms_cop is not None:
                cols.append(("steady_rms_cop", o.steady_rms_cop))
                cols.append(("steady_peak_cop", o.steady_peak_cop))
        return cols

    def units(self) -> dict[str, str]:
        """The unit of each column that has one."""
        varied = set(self.grid.names)
        return {name: parameter_unit(name) if name in varied
                else OUTCOME_UNITS.get(name, _steady_unit(name))
                for name, _ in self.columns()}

    def to_csv_text(self) -> str:
        """CSV: a header row, then one row per run; ``fell`` is true/false, a missing fall or
        settling time is an empty cell, numbers have 17 significant digits (exact)."""
        return table_csv_text(self.columns())

    def to_parquet_bytes(self) -> bytes:
        """The table as Parquet (pyarrow): float64 columns (NaN as null), ``fell`` boolean;
        each field's unit in its metadata."""
        return table_parquet_bytes(self.columns(), self.units())

    def write(self, path: str | Path) -> None:
        """Write the table to ``path`` (.csv or .parquet by its suffix), atomically."""
        write_table(path, self.columns(), self.units())


def table_csv_text(columns: Sequence[tuple[str, np.ndarray]]) -> str:
    """A table as CSV: a header row, then one row per entry; boolean columns are true/false,
    NaN an empty cell, numbers with 17 significant digits (exact)."""
    buf = io.StringIO()
    buf.write(",".join(name for name, _ in columns) + "\n")
    text_cols = []
    for _, values in columns:
        values = np.asarray(values)
        if values.dtype == bool:
            text_cols.append(np.where(values, "true", "false"))
        elif values.dtype.kind in "US":
            text_cols.append(values.astype(str))
        else:
            text_cols.append(np.array([_number(v) for v in values.tolist()], dtype=object))
    for row in zip(*text_cols, strict=True):
        buf.write(",".join(row) + "\n")
    return buf.getvalue()


def table_parquet_bytes(columns: Sequence[tuple[str, np.ndarray]], units: dict[str, str]
                        ) -> bytes:
    """A table as Parquet (pyarrow): float64 columns (NaN as null), boolean columns boolean;
    each field's unit (``units``) in its metadata."""
    pa, pq = _pyarrow()
    fields, arrays = [], []
    for name, values in columns:
        unit = units.get(name, "")
        if np.asarray(values).dtype == bool:
            arr = pa.array(np.asarray(values, dtype=bool))
            typ = pa.bool_()
        elif np.asarray(values).dtype.kind in "US":
            arr = pa.array(np.asarray(values).astype(str).tolist(), type=pa.string())
            typ = pa.string()
        else:
            values = np.asarray(values, dtype=float)
            arr = pa.array(values, mask=np.isnan(values), type=pa.float64())
            typ = pa.float64()
        fields.append(pa.field(name, typ, metadata={"unit": unit} if unit else None))
        arrays.append(arr)
    table = pa.Table.from_arrays(arrays, schema=pa.schema(fields))
    sink = io.BytesIO()
    pq.write_table(table, sink)
    return sink.getvalue()


def write_table(path: str | Path, columns: Sequence[tuple[str, np.ndarray]],
                units: dict[str, str]) -> None:
    """Write a table to ``path``, .csv or .parquet by its suffix, atomically (a temporary
    file renamed: nothing half-written is left)."""
    kind = table_format(path)
    if kind == "csv":
        atomic_write_text(path, table_csv_text(columns))
    else:
        atomic_write_bytes(path, table_parquet_bytes(columns, units))


def _number(v: float) -> str:
    return "" if math.isnan(v) else repr(float(v))


def _pyarrow():
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise PostureLabError("writing Parquet needs pyarrow: pip install pyarrow (or "
                              "'posturelab[parquet]'); or write .csv") from None
    return pa, pq


def table_format(path: str | Path) -> str:
    """'csv' or 'parquet' from the file suffix; anything else is a ParameterError."""
    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        return "csv"
    if suffix in (".parquet", ".pq"):
        return "parquet"
    raise ParameterError(f"the output file must end in .csv or .parquet, got {str(path)!r}")


# ---------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class _Task:
    """What every chunk of a sweep shares (sent once to each Dask worker)."""

    scenario: Scenario
    rtol: float
    atol: float

    def run(self, grid: SweepGrid, lo: int, hi: int, parallel: bool) -> BatchResult:
        result = self._batch(grid, lo, hi, parallel)
        if result.stimulus is not None and result.stimulus.sustained:
            result = self._with_steady_sway(result, grid, lo, hi)
        return result

    def _steady_row(self, grid: SweepGrid, r: int):
        """Row ``r`` run alone on the compiled engine: its steady sway (or None)."""
        from dataclasses import replace

        from ..simulation.engines import simulate

        sc = self.scenario
        pairs = []
        for j, pair in enumerate(sc.muscles.pairs):
            extra = {} if grid.active_stiffness is None else {
                "active_stiffness": float(grid.active_stiffness[r, j]),
                "active_viscosity": float(grid.active_viscosity[r, j])}
            pairs.append(replace(pair, stiffness=float(grid.stiffness[r, j]),
                                 viscosity=float(grid.viscosity[r, j]), **extra))
        muscles = type(sc.muscles)(tuple(pairs), sc.muscles.n_links)
        disturbance = sc.disturbance
        if grid.disturbance_scale is not None:
            disturbance = disturbance.scaled(float(grid.disturbance_scale[r]))
        limits = None if grid.torque_limits is None else grid.torque_limits[r]
        weight = (sc.proprioceptive_weight if grid.proprioceptive_weight is None
                  else float(grid.proprioceptive_weight[r]))
        run = simulate(
            sc.body, muscles, disturbance, sc.duration, initial_state=sc.initial_state,
            rates_from=sc.rates_from, knee=sc.knee, fall=sc.fall, torque_limits=limits,
            feedback_delay=float(grid.feedback_delay[r]), rtol=self.rtol, atol=self.atol,
            sample_rate=sc.sample_rate, engine="compiled", tilt=sc.tilt,
            proprioceptive_weight=weight, tilt_axis_depth=sc.tilt_axis_depth,
            motor_noise=sc.motor_noise, max_steps=sc.max_steps, time_limit=sc.time_limit)
        return run.steady_sway(centre_of_pressure=False)

    def _with_steady_sway(self, result: BatchResult, grid: SweepGrid, lo: int,
                          hi: int) -> BatchResult:
        """The batch's rows with their steady sway: under a sustained stimulus each row that
        completed is run again, alone on the compiled engine, for its trajectory (the batch
        keeps none), and the RMS and peak of its angles over the steady part are computed as
        for one run (:meth:`SimulationResult.steady_sway`; the centre of pressure's would
        cost ten times the run, so a sweep leaves it to single runs)."""
        from dataclasses import replace

        n = self.scenario.body.n_links
        m = hi - lo
        rms, peak = np.full((m, n), np.nan), np.full((m, n), np.nan)
        rows = [int(k) for k in np.nonzero(result.status == "completed")[0]]
        # (one at a time: the rerun is mostly Python, which threads would not speed up)
        sways = [self._steady_row(grid, lo + k) for k in rows]
        for k, sway in zip(rows, sways, strict=True):
            if sway is None:
                continue
            rms[k], peak[k] = sway.rms_theta, sway.peak_theta
        return replace(result, steady_rms_theta=rms, steady_peak_theta=peak)

    def _batch(self, grid: SweepGrid, lo: int, hi: int, parallel: bool) -> BatchResult:
        from ..simulation.compiled import simulate_batch

        sc = self.scenario
        return simulate_batch(
            sc.body, grid.stiffness[lo:hi], grid.viscosity[lo:hi], sc.disturbance,
            sc.duration, sc.initial_state, muscles=sc.muscles, rates_from=sc.rates_from,
            knee=sc.knee, fall=sc.fall, torque_limits=_rows(grid.torque_limits, lo, hi),
            feedback_delay=grid.feedback_delay[lo:hi], rtol=self.rtol, atol=self.atol,
            sample_rate=sc.sample_rate, settle_tolerance=SETTLE_TOLERANCE, parallel=parallel,
            disturbance_scale=_rows(grid.disturbance_scale, lo, hi),
            tilt=sc.tilt, tilt_axis_depth=sc.tilt_axis_depth, motor_noise=sc.motor_noise,
            max_steps=sc.max_steps, time_limit=sc.time_limit, method=sc.method,
            proprioceptive_weight=(sc.proprioceptive_weight if grid.proprioceptive_weight is None
                                   else grid.proprioceptive_weight[lo:hi]),
            active_stiffness=_rows(grid.active_stiffness, lo, hi),
            active_viscosity=_rows(grid.active_viscosity, lo, hi))


def _run_chunk(task: _Task, grid: SweepGrid, lo: int, hi: int) -> BatchResult:
    """A chunk on a Dask worker: one thread per task (the worker's threads run tasks)."""
    return task.run(grid, lo, hi, parallel=False)


def _rows(values: np.ndarray | None, lo: int, hi: int) -> np.ndarray | None:
    return None if values is None else values[lo:hi]


def _concatenate(parts: list[BatchResult]) -> BatchResult:
    from ..simulation.compiled import BatchResult

    if len(parts) == 1:
        return parts[0]
    fields = ("fell", "fall_time", "peak_theta", "settling_time", "final_state", "status_code",
              "n_steps", "n_switches")
    steady = ("steady_rms_theta", "steady_peak_theta", "steady_rms_cop", "steady_peak_cop")
    return BatchResult(**{f: np.concatenate([getattr(p, f) for p in parts]) for f in fields},
                       settle_tolerance=parts[0].settle_tolerance,
                       stimulus=parts[0].stimulus,
                       **{f: (None if getattr(parts[0], f) is None else
                              np.concatenate([getattr(p, f) for p in parts])) for f in steady})


def ProgressBar(total: int, stream: IO[str] | None = None, width: int = 30,
                unit: str = "runs"):
    """A one-line progress bar of ``total`` runs on ``stream`` (standard error by default):
    :class:`posturelab._progress.Progress`, the bar every command draws; ``update(done)``
    sets the finished count, ``close()`` ends the line."""
    from .._progress import Progress

    return Progress(total, unit=unit, stream=stream, width=width)


def run_sweep(
    scenario: Scenario,
    varies: Sequence[VaryRange],
    *,
    viscosity_ratio: float | None = None,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    chunk_size: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> SweepResult:
    """Simulate every run of the grid and collect the outcomes.

    Parameters
    ----------
    scenario : Scenario
        The base experiment (the paper's five pairs, 3 links).
    varies : sequence of VaryRange
        The parameters to vary.
    viscosity_ratio : float, optional
        See :func:`sweep_grid`. [s]
    rtol : float
        Relative tolerance of the fast simulator. [-]
    atol : float
        Absolute tolerance. [rad, rad/s]
    workers : int, optional
        Run on a Dask LocalCluster of this many single-threaded worker
        processes (unless ``scheduler`` or ``client`` is given), 1 …
        :func:`max_workers` (4 × the CPUs). [-]
    scheduler : str, optional
        Address of a running Dask scheduler (``[tcp://]host:port``, checked before
        connecting; one that does not answer within :data:`SCHEDULER_TIMEOUT` s is
        refused); its workers need posturelab installed.
    client : distributed.Client, optional
        An existing Dask client to use.
    chunk_size : int, optional
        Runs per chunk (a progress step, a Dask task). [-]
    progress : callable, optional
        ``progress(done, total)`` after each finished chunk.

    Returns
    -------
    SweepResult
        The same numbers whichever way the runs were spread.
    """
    scenario.method_for("compiled")  # a solver.method the compiled engine lacks: one line
    grid = sweep_grid(scenario, varies, viscosity_ratio)
    try:
        parts = run_chunks(_Task(scenario, rtol, atol), grid, workers=workers,
                           scheduler=scheduler, client=client, chunk_size=chunk_size,
                           progress=progress)
    except SweepInterrupted as exc:
        if exc.parts:
            exc.result = SweepResult(grid.head(exc.rows), _concatenate(exc.parts))
        raise
    return SweepResult(grid, _concatenate(parts))


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM) stopped a sweep: the chunks not started were dropped, those
    running finished. ``parts`` are the finished chunks' results, a prefix of the grid's
    rows (``rows`` of ``total``); ``terminated`` tells SIGTERM from Ctrl-C; the sweep
    function sets ``result`` to the table of the finished rows."""

    def __init__(self, parts: list, rows: int, total: int, terminated: bool) -> None:
        super().__init__(f"interrupted after {rows} of {total} runs")
        self.parts, self.rows, self.total, self.terminated = parts, rows, total, terminated
        self.result: Any = None


class _RowsKept:
    """Rows of the leading finished chunks: what an interrupt keeps, and so what progress
    counts (chunks finish out of order; one finished after a running one is not kept)."""

    def __init__(self, parts: list, bounds: list) -> None:
        self.parts, self.bounds, self.leading = parts, bounds, 0

    def __call__(self) -> int:
        """The rows kept now. [-]"""
        while self.leading < len(self.parts) and self.parts[self.leading] is not None:
            self.leading += 1
        return self.bounds[self.leading - 1][1] if self.leading else 0


def _interrupted(exc: BaseException, parts: list, bounds: list, total: int
                 ) -> SweepInterrupted:
    """The SweepInterrupted of ``exc`` with the leading finished ``parts``."""
    done = []
    for part in parts:
        if part is None:
            break
        done.append(part)
    rows = bounds[len(done) - 1][1] if done else 0
    return SweepInterrupted(done, rows, total, type(exc).__name__ == "Terminated")


#: Dask worker processes a local sweep may start, per CPU. [-]
WORKERS_PER_CPU = 4
#: Seconds to wait for a Dask scheduler to answer before giving up. [s]
SCHEDULER_TIMEOUT = 10


def max_workers() -> int:
    """The most Dask worker processes a local sweep starts: 4 per CPU. [-]"""
    return WORKERS_PER_CPU * (os.cpu_count() or 1)


#: Protocols a Dask scheduler address may name.
SCHEDULER_PROTOCOLS = ("tcp", "tls", "ucx", "ws", "wss", "inproc")


def check_scheduler_address(address: str) -> None:
    """Refuse a Dask scheduler address that is not ``[PROTOCOL://]HOST:PORT`` (one line
    naming it), before any connection is tried."""
    form = "[tcp://]HOST:PORT, e.g. tcp://127.0.0.1:8786"
    protocol, sep, rest = address.partition("://")
    if not sep:
        protocol, rest = "tcp", address
    host, colon, port = rest.rpartition(":")
    if protocol not in SCHEDULER_PROTOCOLS:
        raise ParameterError(f"--scheduler {address!r}: unknown protocol {protocol!r} (one of "
                             f"{', '.join(SCHEDULER_PROTOCOLS)}); the form is {form}")
    if protocol == "inproc":
        return
    if not colon or not host or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ParameterError(f"--scheduler {address!r} is not an address of the form {form} "
                             "(PORT 1 … 65535)")


def run_chunks(task, grid: SweepGrid, *, workers: int | None = None, scheduler: str | None = None,
               client: Any = None, chunk_size: int | None = None,
               progress: Callable[[int, int], None] | None = None, largest_chunk: int = 2048,
               threads: int = 1) -> list:
    """Run the rows of ``grid`` in chunks: ``task.run(grid, lo, hi, parallel)`` for each, here
    (``parallel=True``; ``threads`` chunks at a time) or on Dask (``parallel=False``, one
    chunk per single-threaded worker task); the parts in row order.

    ``progress(done, total)`` after each finished chunk. The same parts whichever way.
    Ctrl-C or SIGTERM drops the chunks not started, waits for those running and raises
    :class:`SweepInterrupted` with the finished ones.
    """
    m = grid.n_runs
    distributed_run = client is not None or scheduler is not None or workers is not None
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or not 1 <= workers <= max_workers()):
        raise ParameterError(f"--workers must be an integer in 1 … {max_workers()} (4 × the "
                             f"{os.cpu_count() or 1} CPUs), got {workers!r}")
    if scheduler is not None:
        check_scheduler_address(scheduler)
    if chunk_size is None:
        chunk_size = largest_chunk if not distributed_run else max(
            min(64, largest_chunk), min(largest_chunk, -(-m // (8 * (workers or 4)))))
    if chunk_size < 1:
        raise ParameterError(f"chunk size must be >= 1, got {chunk_size}")
    bounds = [(lo, min(m, lo + chunk_size)) for lo in range(0, m, chunk_size)]
    parts: list = [None] * len(bounds)
    if distributed_run:
        try:
            return _run_on_dask(task, grid, bounds, workers, scheduler, client, progress,
                                parts)
        except SweepInterrupted:
            raise
        except KeyboardInterrupt as exc:
            raise _interrupted(exc, parts, bounds, m) from None
    done = 0
    if threads <= 1:
        try:
            for k, (lo, hi) in enumerate(bounds):
                parts[k] = task.run(grid, lo, hi, parallel=True)
                done += hi - lo
                if progress is not None:
                    progress(done, m)
        except KeyboardInterrupt as exc:
            raise _interrupted(exc, parts, bounds, m) from None
        return parts
    from concurrent.futures import ThreadPoolExecutor, as_completed

    pool = ThreadPoolExecutor(threads)
    futures: dict = {}
    kept = _RowsKept(parts, bounds)
    try:
        futures = {pool.submit(task.run, grid, lo, hi, True): k
                   for k, (lo, hi) in enumerate(bounds)}
        for fut in as_completed(futures):
            parts[futures[fut]] = fut.result()
            if progress is not None:
                progress(kept(), m)
    except KeyboardInterrupt as exc:
        pool.shutdown(wait=True, cancel_futures=True)  # the running chunks finish
        for fut, k in futures.items():
            if parts[k] is None and fut.done() and not fut.cancelled() \
                    and fut.exception() is None:
                parts[k] = fut.result()
        raise _interrupted(exc, parts, bounds, m) from None
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    return parts


@contextlib.contextmanager
def _quiet_dask():
    """Every logger silent for the block (distributed's, tornado's and asyncio's report the
    connections a shutdown after Ctrl-C cuts, as errors with tracebacks)."""
    import logging

    previous = logging.root.manager.disable
    logging.disable(logging.CRITICAL)
    try:
        yield
    finally:
        logging.disable(previous)


@contextlib.contextmanager
def _sigint_held():
    """Ctrl-C held back for the block and delivered after it (at once if it came meanwhile),
    so that a cluster is not left half-started; the worker processes started in the block
    ignore SIGINT (a terminal's Ctrl-C, or ``timeout -s INT``, reaches the whole process
    group: only this process is to handle it, and then close the cluster)."""
    import signal
    import threading

    hold = hasattr(signal, "pthread_sigmask") and \
        threading.current_thread() is threading.main_thread()
    if not hold:
        yield
        return
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # (inherited by the workers; on
    try:  # Linux a blocked signal stays pending though ignored)
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _close_dask(client, cluster, quiet: bool) -> None:
    """Close the client, then the cluster (each at most a few seconds); after Ctrl-C with
    every logger silent."""
    with _quiet_dask() if quiet else contextlib.nullcontext():
        for closing in (client, cluster):
            if closing is None:
                continue
            try:
                closing.close(timeout=5) if closing is client else closing.close()
            except Exception:  # (a shutdown after Ctrl-C: the connections may be gone)
                if not quiet:
                    raise


def _run_on_dask(task, grid, bounds, workers, scheduler, client, progress,
                 parts: list) -> list[BatchResult]:
    try:
        import distributed
    except ImportError:
        raise PostureLabError("--workers/--scheduler need Dask: pip install 'dask[distributed]' "
                              "(or 'posturelab[dask]')") from None
    own_client = own_cluster = None
    interrupted = False
    try:
        if client is None:
            if scheduler is not None:
                try:
                    with _quiet_dask():
                        own_client = client = distributed.Client(
                            scheduler, timeout=SCHEDULER_TIMEOUT)
                except (OSError, TimeoutError, ValueError) as exc:
                    reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                    raise PostureLabError(
                        f"cannot reach the Dask scheduler at {scheduler!r} within "
                        f"{SCHEDULER_TIMEOUT} s: {reason}") from None
            else:
                import logging

                with _sigint_held():
                    own_cluster = distributed.LocalCluster(
                        n_workers=workers, threads_per_worker=1, processes=True,
                        dashboard_address=None, silence_logs=logging.CRITICAL)
                    own_client = client = distributed.Client(own_cluster)
        shared = client.scatter(task, broadcast=True)
        shared_grid = client.scatter(grid, broadcast=True)
        futures = [client.submit(_run_chunk, shared, shared_grid, lo, hi, pure=False)
                   for lo, hi in bounds]
        index = {f.key: k for k, f in enumerate(futures)}
        kept = _RowsKept(parts, bounds)
        try:
            for fut in distributed.as_completed(futures):
                parts[index[fut.key]] = fut.result()
                if progress is not None:
                    progress(kept(), grid.n_runs)
        except KeyboardInterrupt:
            interrupted = True
            with _quiet_dask():  # keep the chunks that finished, drop the rest
                for k, fut in enumerate(futures):
                    try:
                        if parts[k] is None and fut.status == "finished":
                            parts[k] = fut.result(timeout=5)
                    except Exception:
                        pass
                with contextlib.suppress(Exception):
                    client.cancel(futures)
            raise
        return parts  # type: ignore[return-value]
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        _close_dask(own_client, own_cluster, quiet=interrupted)
