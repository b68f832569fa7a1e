"""``posturelab poles``: poles of the linearised paper model about upright."""

from __future__ import annotations

import argparse

from ._common import (
    add_muscle_arguments,
    body_from_args,
    feedback_options_from_args,
    muscles_from_args,
    print_json,
)

DESCRIPTION = """\
Poles [1/s] of the paper's three-link biped (Appendix A) linearised about upright
stance (Θ = 0, Θ̇ = 0), with the five muscle pairs acting as stiffness K [N·m/rad]
and viscosity L = R·K [N·m·s/rad]. The system is stable when every pole has a
negative real part.

With --feedback-delay the rightmost characteristic roots at that delay are printed too
('rightmost_roots' and 'stable_with_delay' in JSON).

A one-sided gastrocnemius (--gastrocnemius one-sided) has no derivative at upright,
where its stretch θ2 is exactly 0. It is linearised on both sides of its switch:
the side θ2 >= 0 where it acts (the poles printed, identical to two-sided) and the
side θ2 < 0 where it is slack (printed too; 'inactive_side_poles' in JSON). The
system is reported stable only if both sides are.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab poles``."""
    add_muscle_arguments(p)
    p.add_argument("--all", action="store_true",
                   help="Table II: every case as printed beside what we compute, errata flagged.")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of text.")


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

    body = body_from_args(args)
    muscles = muscles_from_args(args, body)
    active, inactive = analyse_both_sides(body, muscles)
    one_sided = args.gastrocnemius == "one-sided"
    stable = active.stable and inactive.stable
    delay = feedback_options_from_args(args).get("feedback_delay")
    delayed = None
    if delay is not None:
        from ..linear.delay import rightmost_roots

        delayed = rightmost_roots(body, muscles, delay, 2 * body.n_links)
    if args.json:
        out = {
            "stiffness": [float(x) for x in muscles.stiffnesses],
            "viscosity": [float(x) for x in muscles.viscosities],
            "stiffness_fraction_of_mgh": [float(x) for x in
                                          muscles.stiffnesses / body.load_stiffness],
            "viscosity_ratio": float(_ratio(args)),
            "poles": [{"re": float(z.real), "im": float(z.imag)} for z in active.poles],
            "stable": bool(stable),
        }
        if one_sided:
            out["gastrocnemius"] = "one-sided"
            out["inactive_side_poles"] = [
                {"re": float(z.real), "im": float(z.imag)} for z in inactive.poles
            ]
        if muscles.has_active_feedback:
            out["active_stiffness"] = [float(x) for x in muscles.active_stiffnesses]
            out["active_viscosity"] = [float(x) for x in muscles.active_viscosities]
        if args.controller is not None:
            out["viscosity_ratio"] = None  # (the preset gives every gain)
        if delayed is not None:
            out["feedback_delay"] = float(delay)
            out["rightmost_roots"] = [{"re": float(z.real), "im": float(z.imag)}
                                      for z in delayed]
            out["stable_with_delay"] = bool(delayed[0].real < 0)
        print_json(out)
        return 0
    label = f"case {args.case} (Table I)" if args.case else "custom stiffness"
    pairs = " ".join(f"{n}={k:g}" for n, k in zip(muscles.names, muscles.stiffnesses, strict=True))
    print(f"{label}: stiffness [N·m/rad] {pairs}; viscosity = {_ratio(args):g} × stiffness")
    head = "poles [1/s]" + (" (gastrocnemius acting, θ2 >= 0)" if one_sided else "")
    print(head + ":")
    for z in active.poles:
        print(f"  {_fmt_pole(z)}")
    if one_sided:
        print("poles [1/s] (gastrocnemius slack, θ2 < 0):")
        for z in inactive.poles:
            print(f"  {_fmt_pole(z)}")
    worst = max(active.max_real_part, inactive.max_real_part)
    print(f"stable: {'yes' if stable else 'no'} (largest real part {worst:.3f} 1/s)")
    if delayed is not None:
        print(f"with the feedback delay τ = {delay:g} s, rightmost roots [1/s]:")
        for z in delayed:
            print(f"  {_fmt_pole(z)}")
        print(f"stable with the delay: {'yes' if delayed[0].real < 0 else 'no'} "
              "(posturelab delay-margin gives the delay at which it changes)")
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
