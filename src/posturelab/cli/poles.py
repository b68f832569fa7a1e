"""``posturelab poles``: poles of the linearised paper model about upright."""

from __future__ import annotations

import argparse

from ._common import (
    add_muscle_arguments,
    feedback_given,
    model_from_args,
    print_json,
)
from ._flags import add_flags

DESCRIPTION = """\
Poles [1/s] of the paper's three-link biped (Appendix A; or any --body, --height/--mass)
linearised about upright stance (Θ = 0, Θ̇ = 0), with the muscle pairs acting as
stiffness K [N·m/rad] and viscosity L = R·K [N·m·s/rad]. The system is stable when every
pole has a negative real part. --controller NAME: a one-link controller preset after a
published model (--help of simulate says which of its numbers come from the source) on the
paper's body as one link, or on --height/--mass lumped to one link.

With --feedback-delay (or a --controller's delay) the rightmost characteristic roots at
that delay are printed too ('rightmost_roots' and 'stable_without_delay' in JSON).

The verdict (the last lines; 'stable' and 'linear_stability' in JSON) is the one that
posturelab simulate, sweep, the explorer and the report give (posturelab.upright_verdict):
with a feedback delay (given, or a --controller's) it is that of the delay equation's
roots.

A one-sided gastrocnemius (--gastrocnemius one-sided or pull-only) has no derivative at
upright: upright is exactly its switching point (stretch θ2 = 0). It is linearised on both
sides of its switch: the side θ2 >= 0 where it acts (the poles printed first, identical to
two-sided) and the side θ2 < 0 where it is slack (printed too; 'inactive_side_poles' in
JSON). Both sides stable: stable; both unstable: unstable; otherwise the verdict is
"depends on the side" (a switched system whose stability about upright the linear model
cannot settle), and 'stable' is false.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab poles``."""
    add_muscle_arguments(p)
    p.add_argument("--all", action="store_true",
                   help="Table II: every case as printed beside what we compute, errata flagged.")
    add_flags(p, "--json")


def _ratio(args: argparse.Namespace) -> float:
    """--viscosity-ratio, 0.25 (the paper's) when not given. [s]"""
    return 0.25 if args.viscosity_ratio is None else args.viscosity_ratio


def _fmt_pole(z: complex) -> str:
    if abs(z.imag) < 1e-12:
        return f"{z.real:.3f}"
    return f"{z.real:.3f} {'+' if z.imag >= 0 else '-'} {abs(z.imag):.3f}j"


def run(args: argparse.Namespace) -> int:
    if args.all:
        if args.case is not None or args.stiffness is not None:
            from . import UsageError

            raise UsageError("poles: --all takes no --case or --stiffness")
        return _run_all(args)
    from ..linear.analysis import analyse_both_sides
    from ..linear.verdict import upright_verdict

    model = model_from_args(args)
    body, muscles = model.body, model.muscles
    active, inactive = analyse_both_sides(body, muscles)
    one_sided = muscles.one_sided_mask.any()
    delay = model.options.feedback_delay if feedback_given(args) else None
    verdict = upright_verdict(body, muscles, delay or 0.0)
    if args.json:
        out = {
            "stiffness": [float(x) for x in muscles.stiffnesses],
            "viscosity": [float(x) for x in muscles.viscosities],
            "stiffness_fraction_of_mgh": [float(x) for x in
                                          muscles.stiffnesses / body.load_stiffness],
            "viscosity_ratio": float(_ratio(args)),
            "poles": [{"re": float(z.real), "im": float(z.imag)} for z in active.poles],
            "stable": verdict.stable,
            "linear_stability": verdict.to_dict(),
        }
        if one_sided:
            out["gastrocnemius"] = args.gastrocnemius
            out["inactive_side_poles"] = [
                {"re": float(z.real), "im": float(z.imag)} for z in inactive.poles
            ]
        if muscles.has_active_feedback:
            out["active_stiffness"] = [float(x) for x in muscles.active_stiffnesses]
            out["active_viscosity"] = [float(x) for x in muscles.active_viscosities]
        if args.controller is not None:
            out["viscosity_ratio"] = None  # (the preset gives every gain)
            out["controller"] = args.controller
            out["body"] = body.name
        if delay is not None:
            out["feedback_delay"] = float(delay)
            out["stable_without_delay"] = bool(active.stable and inactive.stable)
            out["rightmost_roots"] = [{"re": float(z.real), "im": float(z.imag)}
                                      for z in verdict.side(engaged=True).roots]
        print_json(out)
        return 0
    pairs = " ".join(f"{n}={k:g}" for n, k in zip(muscles.names, muscles.stiffnesses, strict=True))
    if args.controller is not None:
        active_pairs = " ".join(f"{n}={k:.4g}" for n, k in
                                zip(muscles.names, muscles.active_stiffnesses, strict=True))
        print(f"controller {args.controller} on body {body.name}: intrinsic stiffness "
              f"[N·m/rad] {pairs}; active stiffness [N·m/rad] {active_pairs}")
    else:
        label = f"case {args.case} (Table I)" if args.case else "custom stiffness"
        side = f"; {args.gastrocnemius} gastrocnemius" if body.n_links == 3 else ""
        where = f" on body {body.name}" if body.name != "paper" else ""
        print(f"{label}{where}: stiffness [N·m/rad] {pairs}; viscosity = {_ratio(args):g} × "
              f"stiffness{side}")
    head = "poles [1/s] at τ = 0" + (" (gastrocnemius engaged, θ2 >= 0)" if one_sided else "")
    print(head + ":")
    for z in active.poles:
        print(f"  {_fmt_pole(z)}")
    if one_sided:
        print("poles [1/s] at τ = 0 (gastrocnemius slack, θ2 < 0):")
        for z in inactive.poles:
            print(f"  {_fmt_pole(z)}")
    if delay is not None:
        for s in verdict.sides:
            which = f" ({s.label()})" if s.label() else ""
            print(f"rightmost roots [1/s] with the feedback delay τ = {delay:g} s{which}:")
            for z in s.roots:
                print(f"  {_fmt_pole(z)}")
    worst = verdict.rightmost_root.real
    words = {"stable": "yes", "unstable": "no", "marginal": "no (marginal)",
             "depends on the side": "depends on the side"}[verdict.status]
    print(f"stable: {words} (largest real part {worst:.3f} 1/s)")
    print(f"verdict: {verdict.describe()}")
    if delay is not None:
        print("(posturelab delay-margin gives the delay at which stability changes)")
    return 0


def _run_all(args: argparse.Namespace) -> int:
    from ..paper.compare import erratum, table2_comparison

    rows = table2_comparison(viscosity_ratio=_ratio(args))
    if args.json:
        print_json({"table2": [
            {"case": r.case, "stiffness": list(r.stiffness), "stable": r.stable,
             "poles": [{"printed": p.printed, "re": p.computed.real, "im": p.computed.imag,
                        "agrees": p.agrees, "erratum": p.erratum} for p in r.poles]}
            for r in rows]})
        return 0
    print("Table II: poles [1/s] of the linearised system, printed | computed "
          f"(viscosity = {_ratio(args):g} × stiffness)")
    print("  '!' marks a printed pole that disagrees beyond its printed digits; "
          "[n] is the erratum.")
    flagged: set[int] = set()
    for r in rows:
        cells = []
        for p in r.poles:
            mark = "" if p.agrees else (f" ![{p.erratum}]" if p.erratum else " !")
            if p.erratum and not p.agrees:
                flagged.add(p.erratum)
            cells.append(f"{p.printed:>12} | {_fmt_pole(p.computed):<18}{mark}")
        print(f"case {r.case:<3} {'stable' if r.stable else 'UNSTABLE'}")
        for c in cells:
            print(f"    {c}")
    if flagged:
        print("Disagreements:")
        for n in sorted(flagged):
            e = erratum(n)
            print(f"  [{n}] {e.where}: printed {e.printed}, computed {e.derived}. {e.explanation}")
    return 0
