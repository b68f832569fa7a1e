"""FRFs given as tables: gain and phase per band (published tables, group means), with
optional standard errors, for :func:`posturelab.frequency.fit.fit_frf`.

A table gives, per band, the frequency [Hz] and the FRF either as ``gain`` [-] and
``phase_deg`` [deg] or as ``frf`` ({re, im} pairs, what ``posturelab frf --json`` writes).
Its precision, optional, is either

* ``gain_se`` and ``phase_se_deg``: the standard errors of the gain [-] and of the phase
  [deg], as published group means give them (both or neither); or
* ``frf_se``: the standard error of the complex value, √E|Ĥ − H|² [-] (``posturelab frf
  --json`` writes it, with ``dof``);

``dof`` gives their degrees of freedom (absent: taken as known). Without either the fit
weights every band by 1/|H| and says so (:mod:`.fit`). ``coherence`` [-] is optional and
only used for warnings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .model import MAX_FREQUENCY  # the highest frequency a model FRF is taken at [Hz]

__all__ = ["FRFTable", "frf_table_from_json", "read_frf_json", "read_frf_json_stimuli",
           "MAX_BANDS"]

#: Most bands a table may have. [-]
MAX_BANDS = 10_000
#: Largest gain (or standard error) a table may give. [-]
MAX_GAIN = 1e6


@dataclass(frozen=True)
class FRFTable:
    """An FRF given per band (module notes).

    Attributes
    ----------
    frequency : numpy.ndarray, shape (B,)
        [Hz], in (0, MAX_FREQUENCY].
    frf : numpy.ndarray of complex, shape (B,)
        gain · e^{i·phase}. [-]
    gain_se, phase_se_deg : numpy.ndarray, shape (B,), or None
        [-], [deg]
    frf_se : numpy.ndarray, shape (B,), or None
        [-]
    dof : numpy.ndarray, shape (B,), or None
        [-]
    coherence : numpy.ndarray, shape (B,), or None
        [-]
    response_sign : int or None
        The sign the table's response was taken with, when it says. [-]
    frf_covariance : numpy.ndarray, shape (B, B), or None
        E[ΔĤ_a ΔĤ_b*] of bands that share harmonics (``posturelab frf --json`` writes it;
        its diagonal is frf_se²). [-]
    harmonic_frequency, harmonic_weight : tuple of numpy.ndarray
        Per band, its harmonics [Hz] and their share of the band's stimulus power [-], when
        given: the fit then averages the model over them as the estimate did.
    kind : str
        What the table is: ``"frf --json"`` (an estimate ``posturelab frf --json`` wrote:
        it gives frf_se or the bands' harmonics) or ``"table"`` (gain and phase per band).
    """

    frequency: np.ndarray
    frf: np.ndarray
    gain_se: np.ndarray | None = None
    phase_se_deg: np.ndarray | None = None
    frf_se: np.ndarray | None = None
    dof: np.ndarray | None = None
    coherence: np.ndarray | None = None
    response_sign: int | None = None
    harmonic_frequency: tuple = ()
    harmonic_weight: tuple = ()
    frf_covariance: np.ndarray | None = None
    kind: str = "table"

    def band_average(self, frf_at) -> np.ndarray:
        """Σ w H(f) / Σ w over each band's harmonics when the table gives them (``posturelab
        frf --json`` does), else H at the band frequencies."""
        if not self.harmonic_weight:
            return np.asarray(frf_at(self.frequency))
        values = np.asarray(frf_at(np.concatenate(self.harmonic_frequency)))
        out, start = [], 0
        for w in self.harmonic_weight:
            out.append(np.sum(w * values[start:start + w.size]) / np.sum(w))
            start += w.size
        return np.array(out)

    def __post_init__(self) -> None:
        f = np.asarray(self.frequency)
        H = np.asarray(self.frf)
        if f.ndim != 1 or H.shape != f.shape or f.dtype == bool or H.dtype == bool:
            raise ParameterError("FRFTable: frequency and frf must be 1-D numbers of one "
                                 "length (use FRFTable.from_gain_phase)")
        if not (np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.isfinite(H))):
            raise ParameterError("FRFTable: frequency must be finite and > 0, frf finite")
        _refuse_repeated_frequency(f, "FRFTable")
        for name in ("gain_se", "phase_se_deg", "frf_se", "dof", "coherence"):
            v = getattr(self, name)
            if v is not None and (np.shape(v) != f.shape or not np.all(np.isfinite(v))):
                raise ParameterError(f"FRFTable: {name} must be finite, one per band")

    @property
    def gain(self) -> np.ndarray:
        """|H|. [-]"""
        return np.abs(self.frf)

    @property
    def phase_deg(self) -> np.ndarray:
        """arg H unwrapped across the bands. [deg]"""
        return np.degrees(np.unwrap(np.angle(self.frf)))

    @classmethod
    def from_gain_phase(cls, frequency, gain, phase_deg, *, gain_se=None, phase_se_deg=None,
                        frf_se=None, dof=None, coherence=None) -> FRFTable:
        """A table from gain and phase per band (each checked, module notes)."""
        f = _numbers("frequency [Hz]", frequency, None, 0.0, MAX_FREQUENCY, low_open=True)
        B = f.size
        g = _numbers("gain [-]", gain, B, 0.0, MAX_GAIN)
        p = _numbers("phase_deg [deg]", phase_deg, B, -1e5, 1e5)
        return cls._with_precision(f, g * np.exp(1j * np.radians(p)), gain_se, phase_se_deg,
                                   frf_se, dof, coherence)

    @classmethod
    def _with_precision(cls, f, H, gain_se, phase_se_deg, frf_se, dof, coherence,
                        response_sign=None) -> FRFTable:
        B = f.size
        if np.any(np.abs(H) == 0):
            raise ParameterError("gain must be > 0 at every band (a zero gain has no phase)")
        if (gain_se is None) != (phase_se_deg is None):
            raise ParameterError("give gain_se and phase_se_deg together (or neither)")
        if frf_se is not None and gain_se is not None:
            raise ParameterError("give either frf_se or gain_se and phase_se_deg, not both")
        gs = None if gain_se is None else _numbers("gain_se [-]", gain_se, B, 0.0, MAX_GAIN,
                                                   low_open=True)
        ps = None if phase_se_deg is None else _numbers("phase_se_deg [deg]", phase_se_deg, B,
                                                        0.0, 180.0, low_open=True)
        fs = None if frf_se is None else _numbers("frf_se [-]", frf_se, B, 0.0, MAX_GAIN,
                                                  low_open=True)
        nu = None if dof is None else _numbers("dof [-]", dof, B, 2.0, 1e9)
        coh = None if coherence is None else _numbers("coherence [-]", coherence, B, 0.0, 1.0)
        return cls(f, H, gs, ps, fs, nu, coh, response_sign)


def _refuse_repeated_frequency(f: np.ndarray, what: str) -> None:
    """Each band's frequency given once (a band given twice would count twice in a fit)."""
    values, counts = np.unique(f, return_counts=True)
    if np.any(counts > 1):
        twice = float(values[np.argmax(counts > 1)])
        where = [str(k + 1) for k in np.flatnonzero(f == twice)]
        raise ParameterError(f"{what}: the frequency {twice:g} Hz is given {len(where)} "
                             f"times (bands {', '.join(where)}); give each band once")


def _numbers(name: str, values, size: int | None, low: float, high: float, *,
             low_open: bool = False) -> np.ndarray:
    """A flat list of finite numbers (no booleans, no strings) within [low, high]."""
    if not isinstance(values, list | tuple | np.ndarray):
        raise ParameterError(f"{name} must be a list of numbers, got {type(values).__name__}")
    out = []
    for i, v in enumerate(values):
        if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
            raise ParameterError(f"{name} entry {i + 1} must be a number, got {v!r}"[:200])
        x = float(v)
        if not math.isfinite(x) or x < low or x > high or (low_open and x == low):
            lb = "(" if low_open else "["
            raise ParameterError(f"{name} entry {i + 1} must be in {lb}{low:g}, {high:g}], "
                                 f"got {x:g}")
        out.append(x)
    if not out or len(out) > MAX_BANDS:
        raise ParameterError(f"{name} must have 1 … {MAX_BANDS:,} entries, got {len(out)}")
    if size is not None and len(out) != size:
        raise ParameterError(f"{name} has {len(out)} entries, frequency has {size}")
    return np.array(out)


def frf_table_from_json(obj, what: str = "FRF JSON") -> FRFTable:
    """An :class:`FRFTable` from a parsed JSON object (module notes)."""
    if not isinstance(obj, dict):
        raise ParameterError(f"{what} must be one JSON object, got {type(obj).__name__}")
    known = {"frequency", "frf", "gain", "phase_deg", "gain_se", "phase_se_deg", "frf_se",
             "dof", "coherence", "gain_ci95", "phase_ci95_deg", "response_sign",
             "sign_convention", "warnings", "harmonic_frequency", "harmonic_weight",
             "frf_covariance"}
    if "frequency" not in obj:
        if _is_dual(obj):
            raise ParameterError(f"{what} holds one FRF per stimulus ({', '.join(obj)}): "
                                 "posturelab fit-frf reads each as a condition; here give "
                                 "one FRF object")
        raise ParameterError(f"{what} has no 'frequency'; it needs frequency and either frf "
                             "or gain and phase_deg")
    f = _numbers("frequency [Hz]", obj["frequency"], None, 0.0, MAX_FREQUENCY, low_open=True)
    _refuse_repeated_frequency(f, what)
    B = f.size
    if "frf" in obj:
        pairs = obj["frf"]
        if not isinstance(pairs, list) or not all(
                isinstance(z, dict) and set(z) == {"re", "im"} for z in pairs):
            raise ParameterError(f"{what}: frf must be a list of {{\"re\", \"im\"}} objects")
        re = _numbers("frf re", [z["re"] for z in pairs], B, -MAX_GAIN, MAX_GAIN)
        im = _numbers("frf im", [z["im"] for z in pairs], B, -MAX_GAIN, MAX_GAIN)
        H = re + 1j * im
    elif "gain" in obj and "phase_deg" in obj:
        H = (_numbers("gain [-]", obj["gain"], B, 0.0, MAX_GAIN)
             * np.exp(1j * np.radians(_numbers("phase_deg [deg]", obj["phase_deg"], B,
                                               -1e5, 1e5))))
    else:
        raise ParameterError(f"{what} needs frf, or gain and phase_deg")
    if "frf" in obj:
        _agrees_with_frf(what, obj, f, H)
    sign = obj.get("response_sign")
    if sign is not None and (isinstance(sign, bool) or sign not in (1, -1)):
        raise ParameterError(f"{what}: response_sign must be 1 or -1, got {sign!r}"[:200])
    extra = sorted(set(obj) - known)
    if extra:
        raise ParameterError(f"{what} has unknown key(s) {', '.join(map(repr, extra))}"[:300])

    def opt(key):  # null entries (an undefined bound or error) are not a precision
        v = obj.get(key)
        if isinstance(v, list) and any(x is None or (isinstance(x, list) and None in x)
                                       for x in v):
            return None
        return v

    table = FRFTable._with_precision(f, H, opt("gain_se"), opt("phase_se_deg"),
                                     opt("frf_se"), opt("dof"), opt("coherence"), sign)
    if "harmonic_frequency" in obj or "frf_se" in obj:
        from dataclasses import replace

        table = replace(table, kind="frf --json")
    if ("harmonic_frequency" in obj) != ("harmonic_weight" in obj):
        raise ParameterError(f"{what}: give harmonic_frequency and harmonic_weight together")
    if "harmonic_frequency" in obj:
        hf, hw = obj["harmonic_frequency"], obj["harmonic_weight"]
        if not (isinstance(hf, list) and isinstance(hw, list) and len(hf) == len(hw) == B):
            raise ParameterError(f"{what}: harmonic_frequency and harmonic_weight need one "
                                 "list per band")
        freqs = tuple(_numbers(f"harmonic_frequency band {k + 1} [Hz]", v, None, 0.0,
                               MAX_FREQUENCY, low_open=True) for k, v in enumerate(hf))
        weights = tuple(_numbers(f"harmonic_weight band {k + 1} [-]", v, freqs[k].size, 0.0,
                                 1.0, low_open=True) for k, v in enumerate(hw))
        from dataclasses import replace

        table = replace(table, harmonic_frequency=freqs, harmonic_weight=weights)
    cov = opt("frf_covariance")
    if cov is not None and table.frf_se is not None:
        if not isinstance(cov, list) or len(cov) != B:
            raise ParameterError(f"{what}: frf_covariance must be {B} rows of {B}")
        V = np.array([_numbers(f"frf_covariance row {k + 1}", row, B, -MAX_GAIN ** 2,
                               MAX_GAIN ** 2) for k, row in enumerate(cov)])
        if not np.allclose(V, V.T, rtol=1e-9, atol=0) or not np.allclose(
                np.diag(V), table.frf_se ** 2, rtol=1e-6):
            raise ParameterError(f"{what}: frf_covariance must be symmetric with frf_se² on "
                                 "its diagonal")
        if np.linalg.eigvalsh(V).min() <= 0:
            raise ParameterError(f"{what}: frf_covariance must be positive definite")
        from dataclasses import replace

        table = replace(table, frf_covariance=V)
    return table


#: How far a JSON's gain and phase_deg may stray from |frf| and arg frf (what rounding to
#: 4 significant digits could do) before they contradict it: relative gain, phase [deg]. [-]
GAIN_RTOL, PHASE_ATOL_DEG = 1e-3, 0.1


def _agrees_with_frf(what: str, obj: dict, f: np.ndarray, H: np.ndarray) -> None:
    """A JSON giving frf and also gain (phase_deg) must give |frf| (arg frf, modulo 360°)
    within rounding; a contradiction is refused naming the band (the fit reads frf)."""
    B = f.size
    if "gain" in obj:
        g = _numbers("gain [-]", obj["gain"], B, 0.0, MAX_GAIN)
        bad = np.flatnonzero(np.abs(g - np.abs(H)) > GAIN_RTOL * np.maximum(np.abs(H), 1e-12))
        if bad.size:
            k = int(bad[0])
            raise ParameterError(f"{what}: gain {g[k]:.6g} at band {k + 1} ({f[k]:.4g} Hz) "
                                 f"contradicts |frf| = {abs(H[k]):.6g}; give one of them, "
                                 "or both alike")
    if "phase_deg" in obj:
        p = _numbers("phase_deg [deg]", obj["phase_deg"], B, -1e5, 1e5)
        off = np.abs((p - np.degrees(np.angle(H)) + 180.0) % 360.0 - 180.0)
        bad = np.flatnonzero((off > PHASE_ATOL_DEG) & (np.abs(H) > 0))
        if bad.size:
            k = int(bad[0])
            raise ParameterError(f"{what}: phase_deg {p[k]:.6g} at band {k + 1} ({f[k]:.4g} "
                                 f"Hz) contradicts arg frf = "
                                 f"{float(np.degrees(np.angle(H[k]))):.6g} deg; give one of "
                                 "them, or both alike")


def read_frf_json(path, what: str = "FRF JSON") -> FRFTable:
    """:func:`frf_table_from_json` of a file (at most 16 MB)."""
    obj, name = _load_json(path, what)
    return frf_table_from_json(obj, name)


def read_frf_json_stimuli(path, what: str = "FRF JSON") -> dict[str | None, FRFTable]:
    """The FRFs of a JSON file by stimulus: ``{None: table}`` for one FRF object, or each
    stimulus column's FRF of a dual-stimulus trial's ``{"tilt": {...}, "visual_tilt": {...}}``
    (what ``posturelab frf --json`` prints for one: :mod:`posturelab.frequency.dual`), in
    the file's order; each object as :func:`frf_table_from_json` reads it."""
    obj, name = _load_json(path, what)
    if isinstance(obj, dict) and _is_dual(obj):
        return {str(key): frf_table_from_json(value, f"{name} [{key}]")
                for key, value in obj.items()}
    return {None: frf_table_from_json(obj, name)}


def _is_dual(obj: dict) -> bool:
    """Whether a JSON object is one FRF object per stimulus (no frequency of its own)."""
    return ("frequency" not in obj and 1 <= len(obj) <= 4
            and all(isinstance(v, dict) and "frequency" in v for v in obj.values()))


def _load_json(path, what: str):
    """The parsed JSON of a file (at most 16 MB) and the name its messages use."""
    import json

    from .._files import read_text

    text = read_text(path, what, max_bytes=16 * 2**20, error=ParameterError)
    name = f"{what} {str(path)!r}"
    try:
        obj = json.loads(text, parse_constant=_refuse_constant,
                         object_pairs_hook=_refuse_repeated_keys)
    except RecursionError:
        raise ParameterError(f"{name} is nested too deeply") from None
    except ValueError as exc:
        raise ParameterError(f"{name} is not valid JSON: {exc}"[:300]) from None
    return obj, name


def _refuse_repeated_keys(pairs: list) -> dict:
    """A JSON object whose keys are each given once (a repeated key would let the last one
    win silently)."""
    out: dict = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"the key {key!r} is given twice in one object")
        out[key] = value
    return out


def _refuse_constant(name: str):
    raise ValueError(f"{name} is not a number JSON allows")
