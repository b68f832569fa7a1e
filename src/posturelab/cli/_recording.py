"""The options that say how a recording is read (``frf``, ``fit-frf``, ``cohort``, ``fit``,
``likeness``, ``likeness-reference``, ``compare-frf``, ``convert``): resampling, declared
units, the cut to whole cycles, and ``com_angle`` from markers or a force plate (``--sway``,
computed as ``convert --sway`` computes it); and how what the reading did is said."""

from __future__ import annotations

import argparse

#: The sway methods (recordings.sway.SWAY_METHODS; here so that --help loads no numerical
#: module; tests/test_recordings_hostile.py compares them).
SWAY_CHOICES = ("segments", "two-marker", "cop")


def add_recording_arguments(p: argparse.ArgumentParser, *, sway: bool = True,
                            subject: bool = True) -> None:
    """--resample, --max-gap, --angle-unit, --length-unit, --time-unit, --start, and (with
    ``sway``) the --sway options (with ``subject`` their own --height and --mass; a command
    with a body model's --height and --mass passes False and those are used)."""
    g = p.add_argument_group("reading a recording (CSV or .c3d)")
    g.add_argument("--resample", type=float, metavar="HZ",
                   help="put an uneven time column (or short runs of missing samples) onto a "
                   "uniform grid at HZ by a cubic spline; a gap longer than --max-gap is "
                   "refused (default: a non-uniform time column is refused).")
    g.add_argument("--max-gap", type=float, metavar="SECONDS",
                   help="with --resample: the longest gap accepted [s] (default 3 median "
                   "steps of the time column).")
    g.add_argument("--angle-unit", choices=["rad", "deg"], default="rad",
                   help="the unit of angle columns whose header declares no unit "
                   "(default rad; deg is converted); a unit a header declares, e.g. "
                   "tilt [deg], is always honoured and converted, whatever this says.")
    g.add_argument("--length-unit", choices=["m", "mm"], default="m",
                   help="the unit of length columns (and a CSV's marker columns) whose "
                   "header declares no unit (default m; mm is converted); a unit a header "
                   "declares, e.g. x [mm], is always honoured and converted.")
    g.add_argument("--time-unit", choices=["s", "ms"], default="s",
                   help="the unit of a CSV's time column (default s; ms is converted; a "
                   "header [ms] needs it).")
    g.add_argument("--start", type=float, metavar="SECONDS",
                   help="drop the samples before this time (where the stimulus's first "
                   "cycle starts) [s].")
    if sway:
        add_sway_arguments(p, response=True, subject=subject)


def add_sway_arguments(p: argparse.ArgumentParser, *, response: bool = False,
                       subject: bool = True) -> None:
    """--sway, --markers, --ankle-marker … --shoulder-marker, --plate, --forward, --up, and
    (with ``subject``) --height and --mass."""
    g = p.add_argument_group("com_angle from markers or a force plate (--sway)")
    g.add_argument("--sway", choices=SWAY_CHOICES,
                   help="compute com_angle [rad] by this method, as posturelab convert does: "
                   "segments (ankle, knee, hip, shoulder markers; Winter 2009 Table 4.1), "
                   "two-marker (hip and shoulder; posturelab's reduction of that table), cop "
                   "(a force plate; Caron et al. 1997; needs --height and --mass)"
                   + ("; then --response com_angle." if response else "."))
    g.add_argument("--markers", default="", metavar="LANDMARK=LABEL,...",
                   help="ankle=, knee=, hip=, shoulder= marker labels (or CSV columns).")
    for landmark in ("ankle", "knee", "hip", "shoulder"):
        g.add_argument(f"--{landmark}-marker", metavar="LABEL",
                       help=f"the {landmark} marker (as --markers {landmark}=LABEL).")
    g.add_argument("--plate", type=int, default=1, metavar="K",
                   help="the force plate --sway cop uses (default 1).")
    g.add_argument("--forward", default="x", metavar="AXIS",
                   help="the lab axis pointing forward: x, y, z, -x, -y, -z (default x).")
    g.add_argument("--up", default="z", metavar="AXIS",
                   help="the lab axis pointing up (default z).")
    if subject:
        g.add_argument("--height", type=float, metavar="M",
                       help="the subject's height [m] (--sway cop; two-marker on forward "
                       "positions only).")
        g.add_argument("--mass", type=float, metavar="KG",
                       help="the subject's mass [kg] (--sway cop).")


def add_cycle_trim_argument(p: argparse.ArgumentParser) -> None:
    """--drop-partial (for the commands that cut a trial into stimulus cycles)."""
    p.add_argument("--drop-partial", action="store_true",
                   help="drop a partial cycle at the end of the recording (said on "
                   "standard error, or as \"trimming\" in --json; default: a recording must "
                   "hold whole cycles).")


def marker_mapping(args: argparse.Namespace) -> dict[str, str]:
    """Landmark → marker label from --markers and --LANDMARK-marker (one of them each)."""
    from ..errors import ParameterError

    out: dict[str, str] = {}
    for item in [i.strip() for i in str(getattr(args, "markers", "") or "").split(",")
                 if i.strip()]:
        key, eq, value = item.partition("=")
        if not eq or not value.strip():
            raise ParameterError(f"--markers must be LANDMARK=LABEL,..., got {item!r}")
        out[key.strip().lower()] = value.strip()
    for landmark in ("ankle", "knee", "hip", "shoulder"):
        label = getattr(args, f"{landmark}_marker", None)
        if label:
            if landmark in out and out[landmark].lower() != label.strip().lower():
                raise ParameterError(f"the {landmark} marker is given twice: --markers "
                                     f"{landmark}={out[landmark]} and --{landmark}-marker "
                                     f"{label}")
            out[landmark] = label.strip()
    return out


def sway_spec(args: argparse.Namespace):
    """The :class:`~posturelab.recordings.sway.SwaySpec` of --sway (None without it)."""
    method = getattr(args, "sway", None)
    markers = marker_mapping(args)
    if method is None:
        if markers:
            from . import UsageError

            raise UsageError("marker labels were given without --sway METHOD")
        return None
    from ..errors import ParameterError
    from ..recordings.sway import SwaySpec

    def number(name: str) -> float | None:  # (fit-frf's --height is text: a body's)
        value = getattr(args, name, None)
        try:
            return None if value is None else float(value)
        except ValueError:
            raise ParameterError(f"--{name} must be a number for --sway, got {value!r}"
                                 ) from None

    return SwaySpec(method, tuple((k, v.lower()) for k, v in markers.items()),
                    plate=args.plate, forward=args.forward.strip().lower(),
                    up=args.up.strip().lower(), height=number("height"),
                    mass=number("mass"))


def recording_options(args: argparse.Namespace) -> dict:
    """:func:`posturelab.recordings.table.read_recording`'s reading options."""
    given = {"resample": None, "max_gap": None, "angle_unit": "rad", "length_unit": "m",
             "start": None}  # a command without these options reads as before
    out = {k: getattr(args, k, default) for k, default in given.items()}
    if getattr(args, "time_unit", "s") != "s":
        out["time_unit"] = args.time_unit
    if getattr(args, "drop_partial", False):
        out["drop_partial"] = True
    spec = sway_spec(args)
    if spec is not None:
        out["sway"] = spec
    return out


def check_sway_response(args: argparse.Namespace, response: str | None) -> None:
    """--sway writes com_angle: refuse another --response with it."""
    if getattr(args, "sway", None) and response is not None \
            and response.strip().lower() != "com_angle":
        from . import UsageError

        raise UsageError(f"--sway computes com_angle; give --response com_angle (got "
                         f"{response!r})")


def print_reading(recording, data: str | None = None) -> None:
    """Say what reading a recording did, one line each on standard error (so --json stays
    one object)."""
    if recording is None:
        return
    import sys

    where = f"{data}: " if data else ""
    for line in recording.report_lines():
        print(f"posturelab: note: {where}{line}", file=sys.stderr)


def print_resampling(report) -> None:
    """Say what the resampling did (on standard error, so --json stays one object)."""
    if report is not None:
        import sys

        print(f"posturelab: note: {report.text()}", file=sys.stderr)


def refuse_repeated_files(paths: list[str], option: str = "--data") -> None:
    """Refuse one file given twice among the FRFs (it would count as two independent
    measurements and narrow every interval by about √2), as ``cohort`` refuses it
    (:func:`posturelab.frequency.cohort._refuse_repeated_files`, here naming ``option``)."""
    from pathlib import Path

    from ..errors import ParameterError

    seen: dict[Path, str] = {}
    for p in paths:
        key = Path(p).resolve()
        if key in seen:
            raise ParameterError(f"{option} names the same file twice ({seen[key]!r} and "
                                 f"{str(p)!r}); each FRF is one measurement, given once")
        seen[key] = str(p)
