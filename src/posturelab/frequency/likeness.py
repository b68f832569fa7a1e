"""Human-likeness: the weighted Mahalanobis distance of an FRF to a human reference.

The Eurobench COMTEST protocol scores a tilt response by its distance to the FRFs of
healthy people (Lippi, Maurer and Mergner 2021, "Evaluating robot posture control and
balance by comparison to human subjects using human likeness measures",
arXiv:2110.14395; the code: github.com/VittorioFreiburg/COMTEST,
ANALYSIS/OCTAVE/src/PRTSinfo.m):

    D = √(d · S · Σ⁻¹ · S · dᵀ),   d = [Re H − Re m, Im H − Im m]

over the B bands (a row of 2B numbers: the real parts of the bands, then the imaginary
parts), m the reference mean FRF, Σ⁻¹ the inverse covariance of [Re H, Im H] over the
reference subjects (2B × 2B), S = diag([s, s]) the per-band weights s (B). With S = I,
D² of a subject drawn from the reference population is about χ² with 2B degrees of
freedom (mean 2B = 22 for the 11 bands).

**The preset** ``comtest-eyes-closed`` (:func:`likeness_reference`) is COMTEST's own:
m, Σ⁻¹ and s as ``PRTSinfo.m`` prints them ("values computed on EC TILT DATASET"), for
the 11 bands of the 80-state PRTS (0.05 … 2.20 Hz, :data:`~.bands.PETERKA_BAND_HARMONICS`).
It ships in ``posturelab/data/likeness/`` under that file's licence, the GNU GPL version 3
or later (the data README states the repository, the commit and the licence; the rest of
posturelab is MIT). :func:`read_prtsinfo` reads the same numbers from one's own copy of
``PRTSinfo.m``.

**COMTEST's FRF, and how a posturelab FRF maps onto it.** ``PRTSinfo.m`` divides the DFT
of the recorded sway (its CSV's second column, as recorded) by that of the ideal PRTS
scaled to peaks +0.5 and −0.504 (peak-to-peak 1.004): its FRF is the sway per unit
peak-to-peak of the tilt, in the recording's unit (the reference's sway unit and its
dataset's tilt amplitude are not stated in the file). Both its DFT (``dft.m``) and
posturelab's take e^{−iωt}, so a lag is a negative phase in both; the reference mean's
phase at 0.05 Hz is +24° with a positive real part at the lowest bands, so a body that
follows the surface reads a phase near 0, as posturelab's tilt FRF (response sign −1:
following the surface is H = 1) does. A posturelab tilt FRF H (rad/rad) therefore maps
onto COMTEST's as H_COMTEST = A · H, with A the tilt's peak-to-peak amplitude in the unit
of the recorded sway: ``scale`` (``posturelab likeness --scale``) is that A. The sign is
the same; posturelab does not guess A.

**One's own reference** (:func:`build_likeness_reference`): m the mean of the cohort's
FRFs, Σ their sample covariance over [Re H, Im H] (2B numbers), inverted; invertible only
with at least 2B + 1 subjects. With fewer, it is refused, unless a shrinkage λ in (0, 1]
is given: Σ_λ = (1 − λ) Σ + λ diag(Σ) (towards its diagonal; Ledoit and Wolf 2004, J
Multivar Anal 88:365–411, for the form), stated in the reference.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..errors import DataFileError, ParameterError, UnknownNameError

__all__ = ["LikenessReference", "LikenessResult", "likeness", "likeness_score",
           "likeness_reference", "read_likeness_reference", "read_prtsinfo",
           "build_likeness_reference", "LIKENESS_PRESETS", "MAX_REFERENCE_BANDS"]

#: The shipped references: name -> file under ``posturelab/data/likeness``.
LIKENESS_PRESETS: dict[str, str] = {"comtest-eyes-closed": "comtest-eyes-closed.json"}
#: Most bands a reference may have. [-]
MAX_REFERENCE_BANDS = 200
#: Largest |value| in a reference. [-]
_MAX_VALUE = 1e12


@dataclass(frozen=True)
class LikenessReference:
    """A human reference for :func:`likeness` (module notes).

    Attributes
    ----------
    name : str
    frequency : numpy.ndarray, shape (B,)
        Band frequencies. [Hz]
    mean : numpy.ndarray of complex, shape (B,)
        m. [FRF unit]
    inverse_covariance : numpy.ndarray, shape (2B, 2B)
        Σ⁻¹ of [Re H, Im H]. [FRF unit⁻²]
    weights : numpy.ndarray, shape (B,)
        s, per band. [-]
    source : str
        Where the numbers come from (citation, commit, licence).
    sign_convention : str
        The sign and scale of the FRFs it was computed from.
    subjects : int or None
        Cohort size, when known. [-]
    shrinkage : float
        λ applied to the covariance (0: none). [-]
    """

    name: str
    frequency: np.ndarray
    mean: np.ndarray
    inverse_covariance: np.ndarray
    weights: np.ndarray
    source: str = ""
    sign_convention: str = ""
    subjects: int | None = None
    shrinkage: float = 0.0

    def __post_init__(self) -> None:
        f = np.asarray(self.frequency, dtype=float)
        m = np.asarray(self.mean, dtype=complex)
        V = np.asarray(self.inverse_covariance, dtype=float)
        s = np.asarray(self.weights, dtype=float)
        B = m.size
        if not 1 <= B <= MAX_REFERENCE_BANDS or m.ndim != 1:
            raise ParameterError(f"a likeness reference needs 1 … {MAX_REFERENCE_BANDS} "
                                 f"bands, got {m.shape}")
        if f.shape != (B,) or s.shape != (B,) or V.shape != (2 * B, 2 * B):
            raise ParameterError(f"likeness reference {self.name!r}: frequency and weights "
                                 f"need {B} values and the inverse covariance {2 * B}×{2 * B}"
                                 f"; got {f.shape}, {s.shape}, {V.shape}")
        for label, v in (("frequency", f), ("mean", m), ("inverse_covariance", V),
                         ("weights", s)):
            if not np.all(np.isfinite(v)) or np.max(np.abs(v)) > _MAX_VALUE:
                raise ParameterError(f"likeness reference {self.name!r}: {label} must be "
                                     f"finite, at most {_MAX_VALUE:g} in size")
        if np.any(f <= 0) or np.any(s < 0):
            raise ParameterError(f"likeness reference {self.name!r}: frequencies must be "
                                 "> 0 and weights >= 0")
        scale = max(float(np.max(np.abs(V))), 1e-300)
        if np.max(np.abs(V - V.T)) > 1e-9 * scale:
            raise ParameterError(f"likeness reference {self.name!r}: the inverse covariance "
                                 "must be symmetric")
        for name, v in (("frequency", f), ("mean", m), ("inverse_covariance", V),
                        ("weights", s)):
            object.__setattr__(self, name, v)

    def to_dict(self) -> dict:
        """The JSON form :func:`read_likeness_reference` reads (and
        ``posturelab likeness-reference`` writes)."""
        return {"name": self.name, "frequency": [float(v) for v in self.frequency],
                "mean": {"re": [float(v) for v in self.mean.real],
                         "im": [float(v) for v in self.mean.imag]},
                "inverse_covariance": [[float(v) for v in row]
                                       for row in self.inverse_covariance],
                "weights": [float(v) for v in self.weights], "source": self.source,
                "sign_convention": self.sign_convention, "subjects": self.subjects,
                "shrinkage": self.shrinkage}


@dataclass(frozen=True)
class LikenessResult:
    """The distance of one FRF to a reference.

    Attributes
    ----------
    score : float
        D (module notes). [-]
    difference : numpy.ndarray of complex, shape (B,)
        H·scale − m per band. [FRF unit]
    scale : float
        The factor H was multiplied by. [-]
    reference : str
        The reference's name.
    """

    score: float
    difference: np.ndarray
    scale: float
    reference: str

    def to_dict(self) -> dict:
        """What ``posturelab likeness --json`` prints (with the reference's source)."""
        return {"score": self.score, "reference": self.reference, "scale": self.scale,
                "difference": [{"re": float(z.real), "im": float(z.imag)}
                               for z in self.difference]}


def likeness_score(frf, reference: LikenessReference, *, scale: float = 1.0) -> float:
    """D of ``frf`` (B complex values, or an FRF object with ``frf``) to ``reference``
    (module notes); ``scale`` multiplies the FRF first. [-]"""
    return likeness(frf, reference, scale=scale).score


def likeness(frf, reference: LikenessReference, *, scale: float = 1.0) -> LikenessResult:
    """The distance D of one FRF to a reference, and the per-band difference (module
    notes).

    Parameters
    ----------
    frf : array_like of complex, shape (B,), or an FRFEstimate / FRFTable
        Over the reference's bands (an FRF object's frequencies must match within 1 %).
    reference : LikenessReference
    scale : float
        Multiplies the FRF before the distance (for the COMTEST preset: the tilt's
        peak-to-peak amplitude in the unit of the recorded sway). [-]

    Returns
    -------
    LikenessResult
    """
    from .._validation import float_in_range

    k = float_in_range("scale", scale, 0.0, 1e9)
    if k == 0:  # a peak-to-peak amplitude; the FRF's sign is the response sign's, not this
        raise ParameterError("scale must be > 0 (the stimulus's peak-to-peak amplitude; the "
                             "sign is set by the response sign), got 0")
    if hasattr(frf, "frf") and hasattr(frf, "frequency"):
        f = np.asarray(frf.frequency, dtype=float)
        if f.shape != reference.frequency.shape or not np.allclose(
                f, reference.frequency, rtol=0.01):
            raise ParameterError(
                f"the FRF's bands ({', '.join(f'{v:.3g}' for v in f)} Hz) are not the "
                f"reference {reference.name!r}'s ("
                f"{', '.join(f'{v:.3g}' for v in reference.frequency)} Hz)")
        frf = frf.frf
    H = np.asarray(frf)
    if H.dtype == bool or not np.issubdtype(H.dtype, np.number):
        raise ParameterError("the FRF must be complex numbers")
    H = H.astype(complex)
    if H.shape != reference.mean.shape or not np.all(np.isfinite(H)):
        raise ParameterError(f"the FRF must be {reference.mean.size} finite values (the "
                             f"reference {reference.name!r}'s bands), got shape {H.shape}")
    diff = k * H - reference.mean
    d = np.concatenate([diff.real, diff.imag])
    S = np.concatenate([reference.weights, reference.weights])
    q = float((d * S) @ reference.inverse_covariance @ (S * d))
    return LikenessResult(math.sqrt(abs(q)), diff, k, reference.name)


def _preset_text(name: str) -> str:
    from importlib import resources

    return (resources.files("posturelab") / "data" / "likeness"
            / LIKENESS_PRESETS[name]).read_text(encoding="utf-8")


def likeness_reference(name_or_path) -> LikenessReference:
    """A shipped reference by name (:data:`LIKENESS_PRESETS`) or one read from a file
    (:func:`read_likeness_reference`: what ``posturelab likeness-reference`` writes, or a
    COMTEST ``PRTSinfo.m``, read by :func:`read_prtsinfo`).

    Raises
    ------
    UnknownNameError
        A name that is neither a preset nor an existing file; the presets are listed.
    """
    import json
    from pathlib import Path

    text = str(name_or_path)
    if text in LIKENESS_PRESETS:
        return _reference_from_json(json.loads(_preset_text(text)), f"preset {text!r}")
    if Path(text).suffix.lower() in (".json", ".m"):
        if not Path(text).exists():
            raise DataFileError(f"cannot read likeness reference {text!r}: no such file")
        return read_prtsinfo(text) if text.lower().endswith(".m") \
            else read_likeness_reference(text)
    raise UnknownNameError(f"unknown likeness reference {text!r} (neither a preset nor a "
                           f".json or PRTSinfo.m file); known presets: "
                           f"{', '.join(LIKENESS_PRESETS)}")


def read_likeness_reference(path) -> LikenessReference:
    """A reference from its JSON file (:meth:`LikenessReference.to_dict`'s form; at most
    16 MB)."""
    import json

    from .._files import read_text

    raw = read_text(path, "likeness reference", max_bytes=16 * 2**20, error=ParameterError)
    try:
        obj = json.loads(raw, parse_constant=_refuse_constant)
    except RecursionError:
        raise ParameterError(f"likeness reference {str(path)!r} is nested too deeply") \
            from None
    except ValueError as exc:
        raise ParameterError(f"likeness reference {str(path)!r} is not valid JSON: "
                             f"{exc}"[:300]) from None
    return _reference_from_json(obj, f"likeness reference {str(path)!r}")


def _refuse_constant(name: str):
    raise ValueError(f"{name} is not a number JSON allows")


def _reference_from_json(obj, what: str) -> LikenessReference:
    known = {"name", "frequency", "mean", "inverse_covariance", "weights", "source",
             "sign_convention", "subjects", "shrinkage", "licence", "notes"}
    if not isinstance(obj, dict):
        raise ParameterError(f"{what} must be one JSON object")
    missing = [k for k in ("frequency", "mean", "inverse_covariance", "weights")
               if k not in obj]
    extra = sorted(set(obj) - known)
    if missing or extra:
        raise ParameterError(f"{what}: " + "; ".join(
            ([f"missing {', '.join(missing)}"] if missing else [])
            + ([f"unknown key(s) {', '.join(map(repr, extra))}"] if extra else []))[:300])
    mean = obj["mean"]
    if not isinstance(mean, dict) or set(mean) != {"re", "im"}:
        raise ParameterError(f"{what}: mean must be {{\"re\": [...], \"im\": [...]}}")
    try:
        def numbers(v, label):
            a = np.array(v)
            if a.dtype == bool or not np.issubdtype(a.dtype, np.number):
                raise ParameterError(f"{what}: {label} must be numbers")
            return a.astype(float)

        re_, im_ = numbers(mean["re"], "mean re"), numbers(mean["im"], "mean im")
        if re_.shape != im_.shape:
            raise ParameterError(f"{what}: mean re and im differ in length")
        subjects = obj.get("subjects")
        if subjects is not None and (isinstance(subjects, bool)
                                     or not isinstance(subjects, int) or subjects < 1):
            raise ParameterError(f"{what}: subjects must be a whole number >= 1 or null")
        shrinkage = obj.get("shrinkage", 0.0)
        if isinstance(shrinkage, bool) or not isinstance(shrinkage, int | float) \
                or not 0 <= shrinkage <= 1:
            raise ParameterError(f"{what}: shrinkage must be in [0, 1]")
        return LikenessReference(
            str(obj.get("name", "file")), numbers(obj["frequency"], "frequency"),
            re_ + 1j * im_, numbers(obj["inverse_covariance"], "inverse_covariance"),
            numbers(obj["weights"], "weights"), str(obj.get("source", "")),
            str(obj.get("sign_convention", "")), subjects, float(shrinkage))
    except (ValueError, TypeError) as exc:
        if isinstance(exc, ParameterError):
            raise
        raise ParameterError(f"{what}: {exc}"[:300]) from None


def _matlab_matrix(text: str, name: str, what: str) -> np.ndarray:
    found = re.search(rf"(?m)^\s*{name}\s*=\s*\[([^\]]*)\]", text)
    if not found:
        raise ParameterError(f"{what} has no '{name}=[...]'")
    rows = [r for r in found.group(1).replace("\n", " ").split(";") if r.strip()]
    try:
        out = np.array([[float(v) for v in re.split(r"[,\s]+", r.strip()) if v]
                        for r in rows])
    except ValueError:
        raise ParameterError(f"{what}: '{name}' holds something other than numbers") \
            from None
    return out


def read_prtsinfo(path) -> LikenessReference:
    """COMTEST's reference (``Sv``, ``m`` and ``invSigma``) read from one's own copy of
    ``PRTSinfo.m`` (github.com/VittorioFreiburg/COMTEST, ANALYSIS/OCTAVE/src), for the 11
    bands of the 80-state PRTS (module notes)."""
    from .._files import read_text
    from .bands import PETERKA_BAND_FREQUENCIES

    what = f"PRTSinfo.m {str(path)!r}"
    text = read_text(path, "PRTSinfo.m", max_bytes=2**20, error=ParameterError)
    sv = _matlab_matrix(text, "Sv", what).ravel()
    m = _matlab_matrix(text, "m", what).ravel()
    inv = _matlab_matrix(text, "invSigma", what)
    B = sv.size
    if m.size != 2 * B or inv.shape != (2 * B, 2 * B):
        raise ParameterError(f"{what}: Sv has {B} values, m {m.size}, invSigma "
                             f"{inv.shape}; need B, 2B and 2B×2B")
    freq = np.array(PETERKA_BAND_FREQUENCIES) if B == len(PETERKA_BAND_FREQUENCIES) \
        else np.arange(1, B + 1, dtype=float)
    return LikenessReference(
        "PRTSinfo.m", freq, m[:B] + 1j * m[B:], inv, sv,
        f"read from {str(path)!r} (COMTEST's PRTSinfo.m: github.com/VittorioFreiburg/"
        "COMTEST, ANALYSIS/OCTAVE/src/PRTSinfo.m, GPL-3.0-or-later)",
        _COMTEST_SIGN)


#: How COMTEST's FRFs are taken (module notes).
_COMTEST_SIGN = ("COMTEST: recorded sway over an ideal PRTS of unit peak-to-peak, the sway "
                 "as recorded (following the surface reads phase near 0, as posturelab's "
                 "tilt FRF with response sign -1); score a posturelab FRF with scale = the "
                 "tilt's peak-to-peak amplitude in the sway's unit")


def build_likeness_reference(frfs, *, weights=None, shrinkage: float = 0.0,
                             name: str = "cohort") -> LikenessReference:
    """A reference from one's own cohort (module notes).

    Parameters
    ----------
    frfs : list of FRFs
        One per subject (FRFEstimate, FRFTable or B complex values), over the same bands.
    weights : array_like, shape (B,), optional
        s per band (default 1 each: the plain Mahalanobis distance). [-]
    shrinkage : float
        λ in [0, 1]: 0 (default) refuses a cohort of fewer than 2B + 1 subjects. [-]
    name : str

    Returns
    -------
    LikenessReference
    """
    from .._validation import float_in_range
    from .statistics import frf_matrix

    lam = float_in_range("shrinkage", shrinkage, 0.0, 1.0)
    freq, Z = frf_matrix(frfs, "cohort FRF")
    N, B = Z.shape
    X = np.concatenate([Z.real, Z.imag], axis=1)
    if lam == 0 and N < 2 * B + 1:
        raise ParameterError(f"{N} subjects give a singular covariance of the {2 * B} real "
                             f"and imaginary parts of {B} bands; give at least {2 * B + 1}, "
                             "or a shrinkage (--shrinkage 0.2, say) to regularise it")
    if N < 2:
        raise ParameterError(f"a reference needs at least 2 subjects, got {N}")
    cov = np.cov(X, rowvar=False)
    cov = (1 - lam) * cov + lam * np.diag(np.diag(cov))
    eig = np.linalg.eigvalsh(cov)
    if eig.min() <= 1e-12 * max(eig.max(), 1e-300):
        raise ParameterError("the cohort's covariance is singular (identical or collinear "
                             "FRFs); give more subjects or a larger shrinkage")
    inv = np.linalg.inv(cov)
    inv = (inv + inv.T) / 2
    s = np.ones(B) if weights is None else np.asarray(weights, dtype=float)
    if s.shape != (B,):
        raise ParameterError(f"weights must be {B} numbers (one per band), got {s.shape}")
    if np.any(np.isnan(freq)):
        freq = np.arange(1, B + 1, dtype=float)
    note = f"built from {N} FRFs" + (f", covariance shrunk towards its diagonal by "
                                     f"λ = {lam:g}" if lam else "")
    return LikenessReference(str(name), freq, Z.mean(axis=0), inv, s, note, "", N, lam)
