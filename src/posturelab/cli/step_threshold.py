"""``posturelab step-threshold``: the largest platform translation withstood without a step."""

from __future__ import annotations

import argparse

from ._common import print_json
from ._flags import add_flag, add_flags, add_options

DESCRIPTION = """\
The largest platform translation a subject withstands with the feet in place: a one-link
body scaled from --height and --mass (Winter's table), an ankle controller with the
population's gains, feedback delay and ankle strength. The foot is the population's
functional base of support (King, Judge & Wolfson 1994: 0.60 of the foot's length under 60
years, 0.42 at 60 and over, 66 % of it in front of the quiet-standing centre of pressure) on
a foot of 0.152 × height; --foot anatomical takes the whole foot from the ankle. The ankle
moment is limited to what that foot carries each way (plantarflexion also by the strength
left after the quiet stance's tonic moment; --symmetric-ankle-cap: the plantarflexion cap
both ways). A run needs a step when the extrapolated centre of mass x + v/ω0 (Hof, Gazendam
& Sinke 2005, J Biomech 38:1–8; ω0 = √(g/l)) leaves the foot once the platform's remaining
path is counted (--criterion platform-path, the default: the subject stands the whole move;
platform-velocity: judged as if the platform kept its current velocity), or when the body
falls. The platform moves are ramp-and-holds over 0.5 s (posturelab's assumption),
increased in 1 cm steps and then bisected to 1 mm. Compared with Koushyar et al. 2019
(PLoS ONE 14:e0210049, PMC6338353): backward, 16.2 ± 2.6 cm (young), 11.8 ± 2.1 cm (older).
Where each number of a population comes from: --sources. An upright that is unstable at the
feedback delay (it topples without a platform move) is refused: there is no threshold. When
no translation up to the search's ceiling needs a step, the output says so
("reached_search_limit": true, "largest_translation": null, "largest_searched" [m]) and
nothing is compared.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab step-threshold``."""
    add_options(p, {"--height": ("M", "standing height [m] (0.5–2.5)."),
                    "--mass": ("KG", "body mass [kg] (10–300).")}, type=float, required=True)
    p.add_argument("--population", default="young", metavar="NAME",
                   help="young or older (default young): the controller, delay and ankle "
                   "strength.")
    add_flag(p, "--translation", " (default backward)", former=("--direction",),
             default="backward", choices=None, metavar="WAY")
    add_options(p, {  # each in place of the population's (or the protocol's) value
        "--feedback-delay": ("SECONDS", "feedback delay τ [s] in place of the population's."),
        "--ankle-strength": ("N·m", "plantarflexion strength of both ankles [N·m] in place "
                             "of the population's."),
        "--move-duration": ("SECONDS", "duration T [s] of each platform move in place of "
                            "the protocol's 0.5 s (posturelab's assumption)."),
    }, type=float, default=None)
    add_options(p, {
        "--cop-criterion": "also count a step when the centre of pressure leaves the foot "
                           "(the heel would rise or the toes lift).",
        "--symmetric-ankle-cap": "cap dorsiflexion at the plantarflexion cap (the same both "
                                 "ways, as before issue 22) instead of at m g |x_heel|, the "
                                 "foot's: the centre of pressure may then pass the heel.",
        "--sources": "also print where each number of the population comes from.",
    }, action="store_true")
    p.add_argument("--foot", choices=("functional", "anatomical"), default="functional",
                   help="functional (default): the population's functional base of support "
                   "from the quiet-standing centre of pressure; anatomical: the whole foot "
                   "from the ankle.")
    p.add_argument("--criterion", choices=("platform-path", "platform-velocity"),
                   default="platform-path",
                   help="platform-path (default): the XCoM with the platform's remaining path "
                   "counted; platform-velocity: as if the platform kept its current velocity.")
    add_flags(p, "--json")


def run(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from .._validation import float_in_range
    from ..errors import UnknownNameError
    from ..studies.stepping import (
        COP_TOLERANCE,
        DIRECTIONS,
        PROTOCOL,
        UNITS,
        get_population,
        step_threshold,
    )

    if args.translation not in DIRECTIONS:
        raise UnknownNameError(f"--translation {args.translation!r} is not known; known: "
                               f"{', '.join(DIRECTIONS)}")
    population = get_population(args.population)
    protocol = PROTOCOL if args.move_duration is None else replace(
        PROTOCOL, move_duration=float_in_range("--move-duration [s]", args.move_duration,
                                               0.05, 10.0, unit="s"))
    result = step_threshold(args.height, args.mass, population, args.translation,
                            protocol=protocol, feedback_delay=args.feedback_delay,
                            ankle_strength=args.ankle_strength,
                            cop_criterion=args.cop_criterion,
                            heel_limit=not args.symmetric_ankle_cap, foot=args.foot,
                            criterion=args.criterion)
    out = result.to_dict()
    if args.json:
        out["units"] = UNITS
        out["protocol"] = protocol.citation
        if args.sources:
            out["sources"] = population.provenance_text()
        print_json(out)
        return 0
    cm = 100.0
    print(f"{result.population}, {result.direction}, H = {result.height:g} m, "
          f"M = {result.mass:g} kg")
    if result.reached_search_limit:
        print("no step needed up to the largest translation searched "
              f"({result.largest_searched * cm:.1f} cm): no threshold found")
    else:
        low, high = result.largest_translation * cm, result.smallest_stepping * cm
        digits = 1 if f"{low:.1f}" != f"{high:.1f}" else 2  # the bracket, never "9.6 … 9.6"
        print(f"largest translation without a step: {low:.{digits}f} cm "
              f"(a step at {high:.{digits}f} cm: {result.reason})")
    print(f"  platform move over {result.move_duration:g} s: peak {result.peak_velocity:.2f} "
          f"m/s, {result.peak_acceleration:.2f} m/s² at "
          + ("the largest searched" if result.reached_search_limit else "the threshold"))
    print(f"  τ = {result.feedback_delay * 1000:.0f} ms, ankle strength "
          f"{result.ankle_strength:.0f} N·m (caps: plantarflexion "
          f"{result.ankle_moment_cap:.0f} N·m, dorsiflexion {result.dorsiflexion_cap:.0f} "
          f"N·m), {result.foot} foot "
          f"{result.heel * cm:.1f} … {result.toe * cm:.1f} cm, ω0 = {result.omega0:.2f} 1/s, "
          f"criterion {result.criterion}")
    if result.cop_overrun > COP_TOLERANCE:
        print(f"  the centre of pressure went {result.cop_overrun * cm:.1f} cm beyond the foot "
              "at the threshold (see the guide)")
    if result.reached_search_limit:
        print("published: not compared (no threshold within the search)")
    elif result.published_mean is not None:
        verdict = "within" if result.within_two_sd else "outside"
        print(f"published: {result.published_mean * cm:.1f} ± {result.published_sd * cm:.1f} "
              f"cm ({verdict} two SD); {result.published_source}")
    else:
        print("published: no figure for this population and direction")
    if args.sources:
        print(f"sources: {population.provenance_text()}")
    return 0
