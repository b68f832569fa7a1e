"""The grid and the table of a sweep: what can vary (:data:`SWEEP_PARAMETERS`),
``NAME=LO:HI:N`` (:class:`VaryRange`, :func:`parse_vary`), the runs' gains, delays, limits and
scales (:class:`SweepGrid`, :func:`sweep_grid`), and the outcomes (:class:`SweepResult`, its
CSV / Parquet writers). Public through :mod:`posturelab.studies.sweep`.
"""

from __future__ import annotations

import io
import itertools
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._files import atomic_write_bytes, atomic_write_text
from ..errors import ParameterError, PostureLabError
from ..model.muscles import DEFAULT_VISCOSITY_RATIO
from ..model.platform import NoDisturbance
from ..parameters import PAPER_JOINTS, PAPER_PAIRS, check_value, names_for, parse_name, renamed
from ..parameters import resolve as resolve_name
from ..parameters import unit as parameter_unit
from ..scenarios import Scenario
from ..simulation.outcome import UPRIGHT_BAND

if TYPE_CHECKING:  # (the engine loads when a sweep runs: posturelab --help stays light)
    from ..simulation.compiled import BatchResult


#: The quantities of the parameter table a sweep can vary (all but active_viscosity_ratio).
SWEEP_QUANTITIES: tuple[str, ...] = (
    "stiffness", "viscosity", "active_stiffness", "active_viscosity", "viscosity_ratio",
    "feedback_delay", "proprioceptive_weight", "visual_weight", "torque_limit",
    "disturbance_scale", "joint_feedback_scale")
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
    if name == "hip_fraction":
        return "-"
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
    torque_limits : numpy.ndarray, shape (M, N) or (M, N, 2), optional
        Largest net moment at each joint per run, both ways (inf for none), or (lower,
        upper) per joint when the base experiment's limits differ by side
        (:mod:`posturelab.model.limits`); None when no run has a limit. [N·m]
    active_stiffness, active_viscosity : numpy.ndarray, shape (M, P), optional
        Active (delayed) pair gains per run; None when the base experiment has none and
        none is varied. [N·m/rad], [N·m·s/rad]
    proprioceptive_weight : numpy.ndarray, shape (M,), optional
        W per run; None for the base experiment's. [-]
    visual_weight : numpy.ndarray, shape (M,), optional
        W_v per run (the visual-scene tilt's weight); None for the base experiment's. [-]
    joint_feedback_scale : numpy.ndarray, shape (M,), optional
        The factor on the base experiment's joint controller per run; None when not varied.
        [-]
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
    joint_feedback_scale: np.ndarray | None = None
    visual_weight: np.ndarray | None = None

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



def _base_limits(scenario, n: int) -> np.ndarray:
    """The base experiment's limits: (N,) both ways, or (N, 2) (lower, upper) when a joint's
    differ by side or the ankle's come from the foot. [N·m]"""
    from ..model.limits import NEGATIVE, POSITIVE, body_torque_limits

    given = scenario.torque_limits
    if given is None:
        return np.full(n, math.inf)
    if all(isinstance(e, float) for e in given):
        return np.asarray(given, dtype=float)
    bounds = body_torque_limits(given, scenario.body, scenario.fall.base_of_support)
    bounds = np.full((2, n), math.inf) if bounds is None else bounds
    return np.stack([-bounds[NEGATIVE], bounds[POSITIVE]], axis=1)

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
    scale = control = None
    if "joint_feedback_scale" in names and scenario.options.joint_feedback is None:
        raise ParameterError("joint_feedback_scale multiplies the base experiment's joint "
                             "controller, and it has none: give --controller "
                             "multijoint-default or [muscles] controller")
    delay = np.full(m, float(scenario.feedback_delay))
    n = scenario.body.n_links
    base_limits = _base_limits(scenario, n)
    limits = np.tile(base_limits, (m,) + (1,) * base_limits.ndim)
    muscles = scenario.muscles
    pairs = list(muscles.names)
    joints = list(joints_of(n))
    varies_active = any(nm.startswith("active_") for nm in names)
    ka = va = weight = visual = None
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
            _check_scales(scenario.disturbance, column)
        elif quantity == "feedback_delay":
            delay = np.ascontiguousarray(column)
        elif quantity == "proprioceptive_weight":
            weight = np.ascontiguousarray(column)
        elif quantity == "visual_weight":
            visual = np.ascontiguousarray(column)
        elif quantity == "joint_feedback_scale":
            control = np.ascontiguousarray(column)
        elif quantity == "torque_limit":  # (both ways)
            j = joints.index(member)
            if limits.ndim == 3:
                limits[:, j, 0], limits[:, j, 1] = -column, column
            else:
                limits[:, j] = column
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
    _check_weights(scenario, weight, visual, values, names)
    return SweepGrid(tuple(names), values, stiffness, pair_viscosity, scale, delay,
                     None if np.all(np.isinf(limits)) else limits, ka, va, weight, control,
                     visual)


def _check_scales(disturbance, scales: np.ndarray) -> None:
    """Each disturbance_scale's motion within its bounds: refused in one line naming the
    scale (the value given), the base motion and the bound it breaks."""
    for factor in sorted({float(scales.min()), float(scales.max())}):
        try:
            disturbance.scaled(factor)
        except ParameterError as exc:
            raise ParameterError(f"disturbance_scale {factor:g} × the base experiment's "
                                 f"{type(disturbance).__name__} is out of bounds: {exc} "
                                 "(narrow --vary disturbance_scale)") from None


def _check_weights(scenario: Scenario, weight: np.ndarray | None, visual: np.ndarray | None,
                   values: np.ndarray, names: Sequence[str]) -> None:
    """Every run's W_p + W_v <= 1 (one line naming both and the first run over), and a
    varied W_v needs the base experiment's visual-scene tilt (it acts on nothing else)."""
    if visual is not None and scenario.options.visual_tilt is None:
        raise ParameterError("visual_weight weighs the base experiment's visual-scene tilt, "
                             "and it has none: give --visual-tilt or a scenario with "
                             "[visual_tilt]")
    if weight is None and visual is None:
        return
    wp = np.full(values.shape[0], scenario.options.proprioceptive_weight) if weight is None \
        else weight
    wv = np.full(values.shape[0], scenario.options.visual_weight) if visual is None else visual
    over = np.nonzero(wp + wv > 1.0 + 1e-12)[0]
    if over.size:
        r = int(over[0])
        raise ParameterError(
            f"proprioceptive_weight + visual_weight [-] must be at most 1 (the rest is "
            f"graviceptive); {over.size:,} runs of the grid exceed it, the first "
            f"{wp[r]:g} + {wv[r]:g} = {wp[r] + wv[r]:g} (narrow --vary "
            + " or --vary ".join(n for n in names if n in ("proprioceptive_weight",
                                                            "visual_weight")) + ")")


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
        if o.hip_fraction is not None:  # asked for: the share of the hip mode
            cols.append(("hip_fraction", o.hip_fraction))
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


