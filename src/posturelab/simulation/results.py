"""Frozen result objects with units on every field, and their export."""

from __future__ import annotations

import csv
import functools
import io
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._files import (  # (re-exported: the writers keep this public path)
    atomic_write_bytes,
    atomic_write_files,
    atomic_write_text,
    new_file_mode,
)
from ..errors import PostureLabError
from .outcome import StimulusTiming

__all__ = ["SimulationResult", "DerivedSeries", "DERIVED_SERIES", "atomic_write_text",
           "atomic_write_bytes", "atomic_write_files", "new_file_mode", "read_run_csv"]


#: Each series a run derives from its states, time first: its name, shape and meaning [unit].
#: The fields of :class:`DerivedSeries` and the properties of :class:`SimulationResult` of
#: the same names, in this order; a DerivedSeries may hold None from ``angular_acceleration``
#: on.
DERIVED_SERIES: tuple[tuple[str, str, str], ...] = (
    ("pair_torques", "(T, P)",
     "Muscle-pair torques M (zero while a one-sided pair is slack). [N·m]"),
    ("joint_torques", "(T, N)", "Generalised torques U = −EᵀM on the link angles. [N·m]"),
    ("joint_moments", "(T, N)", "Net muscle moment at the ankle, knee, hip, …: the sum of "
     "the torques of the pairs that cross each joint. [N·m]"),
    ("cog_position", "(T, 2)", "Centre of gravity (x_c, y_c) relative to the ankle. [m]"),
    ("cog_velocity", "(T, 2)", "Its velocity relative to the ankle (ẋ_c, ẏ_c). [m/s]"),
    ("platform_acceleration", "(T, 2)", "Platform acceleration (ẍ_d, ÿ_d). [m/s²]"),
    ("platform_velocity", "(T, 2)",
     "Platform velocity (ẋ_d, ẏ_d), including any velocity step at t = 0. [m/s]"),
    ("platform_position", "(T, 2)", "Platform position (x_d, y_d) from 0 at t = 0. [m]"),
    ("angular_acceleration", "(T, N)", "Link angular accelerations. [rad/s²]"),
    ("ground_reaction", "(T, 2)",
     "Horizontal and vertical force of the platform on the foot (F_x, F_y). [N]"),
    ("centre_of_pressure", "(T,)", "Centre of pressure under the massless foot, x_p = "
     "τ_ankle / F_y, relative to the ankle. [m]"),
    ("com_angle", "(T,)", "Centre-of-mass angle Σ a_i θ_i / Σ a_i. [rad]"),
    ("tilt", "(T,)", "Support-surface tilt α (positive toes-up), None without one. [rad]"),
    ("visual_tilt", "(T,)", "Visual-scene tilt v (positive toes-up), None without one. [rad]"),
)


def _series_doc(head: str) -> str:
    """``head`` and a numpydoc Attributes entry per row of :data:`DERIVED_SERIES`."""
    return head + "\n\n    Attributes\n    ----------\n" + "".join(
        f"    {name} : numpy.ndarray, shape {shape}\n        {meaning}\n"
        for name, shape, meaning in DERIVED_SERIES)


@dataclass(frozen=True)
class DerivedSeries:
    __doc__ = _series_doc("The series a :class:`SimulationResult` derives from its states "
                          "(:data:`DERIVED_SERIES`).")

    pair_torques: np.ndarray
    joint_torques: np.ndarray
    joint_moments: np.ndarray
    cog_position: np.ndarray
    cog_velocity: np.ndarray
    platform_acceleration: np.ndarray
    platform_velocity: np.ndarray
    platform_position: np.ndarray
    angular_acceleration: np.ndarray | None = None
    ground_reaction: np.ndarray | None = None
    centre_of_pressure: np.ndarray | None = None
    com_angle: np.ndarray | None = None
    tilt: np.ndarray | None = None
    visual_tilt: np.ndarray | None = None


def _derived(name: str, doc: str) -> property:
    def get(self: SimulationResult):
        return getattr(self._series, name)

    get.__name__ = name
    return property(get, doc=doc)


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """The outcome of one nonlinear simulation; arrays have time as the first axis.

    The states (``time``, ``theta``, ``omega``) and the outcome are stored; the
    series derived from them (properties, one per row of :data:`DERIVED_SERIES`:
    ``pair_torques`` … ``visual_tilt``) come from ``derived``: a :class:`DerivedSeries`,
    or a function that computes one, called on the first access of any of them and then
    kept. The compiled simulator defers them this way, so that a run whose angles are all
    that is read (a sweep, a fit, a bisection) does not pay for them.

    Attributes
    ----------
    time : numpy.ndarray, shape (T,)
        Output sample times. [s]
    theta : numpy.ndarray, shape (T, N)
        Absolute link angles, forward positive. [rad]
    omega : numpy.ndarray, shape (T, N)
        Link angular rates. [rad/s]
    pair_names : tuple of str
        Names of the pairs, in column order of ``pair_torques``.
    status : str
        "completed" (ran to the end), "fell" (a fall criterion fired) or
        "failed" (the integrator failed or the state diverged).
    message : str
        What happened, in words.
    fell : bool
        True when a fall criterion fired.
    fall_time : float or None
        Time of the fall event. [s]
    fall_reason : str or None
        Which criterion fired.
    switch_times : tuple of float
        Times at which a one-sided pair or the knee stop switched. [s]
    description : str
        The run's set-up in words (body, muscles, disturbance).
    derived : DerivedSeries or callable returning one
        Where the derived series come from (see above).
    stimulus : StimulusTiming or None
        When the perturbation acts (:mod:`posturelab.simulation.outcome`): a transient one
        ends (settling is counted from then), a sustained one lasts the run (its outcome is
        a steady sway). None: a transient one that ends at t = 0.
    """

    time: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    pair_names: tuple[str, ...]
    status: str
    message: str
    fell: bool
    fall_time: float | None
    fall_reason: str | None
    switch_times: tuple[float, ...] = ()
    description: str = ""
    derived: DerivedSeries | Callable[[], DerivedSeries] | None = field(
        default=None, repr=False)
    stimulus: StimulusTiming | None = None

    @functools.cached_property
    def _series(self) -> DerivedSeries:
        source = self.derived
        if source is None:
            raise PostureLabError("this result was built without its derived series")
        series = source() if callable(source) else source
        if not isinstance(series, DerivedSeries):
            raise PostureLabError(f"derived series must be a DerivedSeries, got "
                                  f"{type(series).__name__}")
        return series

    @property
    def n_links(self) -> int:
        """Number of links N. [-]"""
        return int(self.theta.shape[1])

    @property
    def success(self) -> bool:
        """True unless the integration failed (a fall is a successful simulation)."""
        return self.status != "failed"

    @property
    def state(self) -> np.ndarray:
        """``[Θ, Θ̇]`` at every sample, shape (T, 2N). [rad], [rad/s]"""
        return np.concatenate([self.theta, self.omega], axis=1)

    @property
    def final_state(self) -> np.ndarray:
        """State at the last sample, shape (2N,). [rad], [rad/s]"""
        return self.state[-1]

    @property
    def max_abs_theta(self) -> np.ndarray:
        """Peak |θ_i| over the run, shape (N,). [rad]"""
        return np.abs(self.theta).max(axis=0)

    @property
    def hip_fraction(self) -> float:
        """Share of the anti-phase (hip) mode of leg and trunk in the run's motion, in
        [0, 1]; NaN for a one-link body (:func:`posturelab.model.kinematics.hip_fraction`:
        the definition, after Creath et al. 2005). [-]"""
        from ..model.kinematics import hip_fraction

        return hip_fraction(self.theta)

    def settling_time(self, tolerance: float = 0.01) -> float | None:
        """Time from the end of the perturbation (``stimulus.end``; 0 for a velocity step)
        to the last sample after it at which some |θ_i| exceeded ``tolerance`` [rad] (0 if
        none did); None if the run fell, ended outside or before the perturbation ended, or
        the stimulus is sustained. [s]"""
        timing = self.stimulus or StimulusTiming()
        if timing.sustained:
            return None
        outside = np.any(np.abs(self.theta) > tolerance, axis=1)
        if self.fell or outside[-1] or timing.end > float(self.time[-1]) + 1e-9:
            return None  # (also when the run ended before its perturbation did)
        after = outside & (self.time >= timing.end)
        if not after.any():
            return 0.0
        return float(self.time[np.nonzero(after)[0][-1]]) - timing.end

    def steady_sway(self, centre_of_pressure: bool = True):
        """RMS and peak of each θ_i [rad] and of the centre of pressure [m] over the steady
        part of a run under a sustained stimulus
        (:class:`posturelab.simulation.outcome.SteadySway`); None for a transient one.
        ``centre_of_pressure=False`` leaves the centre of pressure out (it needs the derived
        series, which cost about ten times the compiled run itself)."""
        from .outcome import steady_sway

        timing = self.stimulus
        if timing is None or not timing.sustained:
            return None
        cop = None
        if centre_of_pressure:
            try:
                cop = self.centre_of_pressure
            except PostureLabError:  # built without its derived series
                cop = None
        return steady_sway(self.time, self.theta, cop,
                           timing.steady_start(float(self.time[-1])))

    @property
    def outcome(self):
        """What happened: recovered, not recovered, steady sway, fell or failed, with the
        settling time, the steady sway, the fall's reason and time, the final lean and rate
        (:class:`posturelab.simulation.outcome.Outcome`; the rules there)."""
        from .outcome import UPRIGHT_BAND, classify

        timing = self.stimulus or StimulusTiming()
        steady = self.steady_sway() if self.status == "completed" else None
        return classify(self.status, self.settling_time(UPRIGHT_BAND), self.final_state,
                        fall_time=self.fall_time, fall_reason=self.fall_reason,
                        message=self.message, timing=timing, steady=steady,
                        run_end=float(self.time[-1]),
                        started_at_rest=not np.any(self.theta[0]) and not np.any(self.omega[0]))

    def summary(self) -> dict:
        """Plain-Python summary (the CLI's ``--json``): the outcome (``outcome``,
        ``settling_time``, ``fall_time``, ``fall_reason``, ``final_lean``, ``final_rate``,
        ``outcome_message``, ``perturbation_end``, and for a steady sway ``steady_from``,
        ``steady_rms_theta``, ``steady_peak_theta`` [rad], ``steady_rms_cop``,
        ``steady_peak_cop`` [m]), angles [rad], rates [rad/s], times [s], the hip fraction
        [-] (None for one link)."""
        return {
            **self.outcome.to_dict(),
            "fell": bool(self.fell),
            "fall_time": None if self.fall_time is None else float(self.fall_time),
            "status": self.status,
            "message": self.message,
            "max_abs_theta": [float(x) for x in self.max_abs_theta],
            "final_state": [float(x) for x in self.final_state],
            "hip_fraction": None if self.n_links < 2 else float(self.hip_fraction),
        }

    def columns(self) -> tuple[list[str], np.ndarray]:
        """CSV column names (with units documented in the README) and the data table."""
        n = self.n_links
        names = ["t"] + [f"theta{i + 1}" for i in range(n)] + [f"omega{i + 1}" for i in range(n)]
        cols = [self.time[:, None], self.theta, self.omega]
        names += [f"M_{p}" for p in self.pair_names]
        cols.append(self.pair_torques)
        names += [f"U{i + 1}" for i in range(n)]
        cols.append(self.joint_torques)
        names += [f"joint_moment{i + 1}" for i in range(n)]
        cols.append(self.joint_moments)
        names += ["cog_x", "cog_y", "cog_vx", "cog_vy",
                  "platform_ax", "platform_ay", "platform_vx", "platform_vy",
                  "platform_x", "platform_y"]
        cols += [self.cog_position, self.cog_velocity, self.platform_acceleration,
                 self.platform_velocity, self.platform_position]
        if self.centre_of_pressure is not None:
            names += ["cop_x", "ground_fx", "ground_fy"]
            cols += [self.centre_of_pressure[:, None], self.ground_reaction]
        if self.tilt is not None:  # (a tilt experiment: the columns an FRF is made of)
            names += ["tilt"]
            cols += [self.tilt[:, None]]
        if self.visual_tilt is not None:
            names += ["visual_tilt"]
            cols += [self.visual_tilt[:, None]]
        if self.tilt is not None or self.visual_tilt is not None:
            names += ["com_angle"]
            cols += [self.com_angle[:, None]]
        return names, np.concatenate(cols, axis=1)

    def to_dataframe(self):
        """The CSV's columns as a pandas DataFrame, indexed by time ``t`` [s] (units as in
        the README's table). Needs pandas: ``pip install 'posturelab[pandas]'``."""
        try:
            import pandas as pd
        except ImportError:
            raise PostureLabError("to_dataframe needs pandas: pip install pandas (or "
                                  "'posturelab[pandas]')") from None
        names, table = self.columns()
        return pd.DataFrame(table[:, 1:], columns=names[1:],
                            index=pd.Index(table[:, 0], name=names[0]))

    def to_csv_text(self) -> str:
        """The CSV as text: a header row, then one row per output sample."""
        names, table = self.columns()
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(names)
        for row in table:
            w.writerow([f"{v:.10g}" for v in row])
        return buf.getvalue()

    def to_csv(self, path: str | Path) -> None:
        """Write the CSV atomically (temporary file, then rename), a block of rows at a time;
        refused (nothing written) over the rows or bytes posturelab reads back."""
        from .._files import atomic_write_csv

        names, table = self.columns()
        atomic_write_csv(path, names, table.T, cell=lambda v: f"{v:.10g}",
                         fix="write .parquet, or lower the sample rate or the duration")

    def column_units(self) -> dict[str, str]:
        """The unit of each column of :meth:`columns`."""
        names, _ = self.columns()
        units = {"t": "s", "cog_x": "m", "cog_y": "m", "cog_vx": "m/s", "cog_vy": "m/s",
                 "platform_ax": "m/s²", "platform_ay": "m/s²", "platform_vx": "m/s",
                 "platform_vy": "m/s", "platform_x": "m", "platform_y": "m", "cop_x": "m",
                 "ground_fx": "N", "ground_fy": "N", "tilt": "rad", "visual_tilt": "rad",
                 "com_angle": "rad"}
        for n in names:
            if n.startswith("theta"):
                units[n] = "rad"
            elif n.startswith("omega"):
                units[n] = "rad/s"
            elif n.startswith(("M_", "U", "joint_moment")):
                units[n] = "N·m"
        return {n: units.get(n, "") for n in names}


# the derived series read through the result (its ``_series``), one property per row
for _name, _shape, _meaning in DERIVED_SERIES:
    setattr(SimulationResult, _name, _derived(_name, f"Shape {_shape}. {_meaning}"))
del _name, _shape, _meaning


def read_run_csv(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A run saved by ``posturelab simulate --out`` (CSV or Parquet): time ``t`` [s],
    ``theta1..N`` [rad] and ``omega1..N`` [rad/s] (other columns ignored; N from the header).

    Returns
    -------
    (time (T,), theta (T, N), omega (T, N))

    Raises
    ------
    DataFileError
        Not such a file (the file and the problem named).
    """
    from .._files import csv_rows, read_text
    from .._parquet import is_parquet, parquet_rows
    from ..errors import DataFileError

    what = f"run {str(path)!r}"
    rows = list(parquet_rows(path, what) if is_parquet(path)
                else csv_rows(read_text(path, "run"), what))
    if len(rows) < 3:
        raise DataFileError(f"{what} needs a header row and at least 2 samples")
    header = [h.split("[")[0].strip() for h in rows[0][1]]
    n = 0
    while f"theta{n + 1}" in header and f"omega{n + 1}" in header:
        n += 1
    if "t" not in header or n == 0:
        raise DataFileError(f"{what} is not a run written by posturelab simulate --out (it "
                            "needs the columns t, theta1, omega1, …)")
    idx = [header.index(c) for c in ["t", *(f"theta{i + 1}" for i in range(n)),
                                     *(f"omega{i + 1}" for i in range(n))]]
    data = np.empty((len(rows) - 1, len(idx)))
    for r, (line, cells) in enumerate(rows[1:]):
        try:
            data[r] = [float(cells[j]) for j in idx]
        except (IndexError, ValueError):
            raise DataFileError(f"{what} line {line}: a missing or non-numeric value") from None
    if not np.all(np.isfinite(data)) or np.any(np.diff(data[:, 0]) < 0):
        raise DataFileError(f"{what}: values must be finite and t must not decrease")
    return data[:, 0], data[:, 1:1 + n], data[:, 1 + n:]
