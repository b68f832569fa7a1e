"""``posturelab cohort``: the same model fitted to every subject's FRF; a table of parameters
per subject, a summary and a figure of their distributions."""

from __future__ import annotations

import argparse

from ..errors import ParameterError
from ._common import (
    add_muscle_arguments,
    model_from_args,
    print_json,
)
from ._flags import add_data_files, add_flag, add_flags
from .fit_frf import _bounds, _names, add_fit_arguments, reader_options

DESCRIPTION = """\
Fit the same model to every subject's FRF: each --data FILE is one subject (a trial CSV, read as
posturelab fit-frf reads one with --stimulus, --response, --cycle-length, or an FRF JSON:
what posturelab frf --json writes, or a table of gain and phase with or without standard
errors); the body, the starting gains and --free, --bounds are as for posturelab fit-frf,
and every subject starts from them. The fits run in --workers processes (default one per
CPU, at most four per CPU; each subject is one task, so the results do not depend on it).

--out TABLE.csv|.parquet gets one row per subject and parameter: subject (the file's name
without its suffix), parameter, unit, value, standard_error, ci95_low, ci95_high (95 %),
determined, fit_error (√(χ²/dof), about 1 when the model explains the data),
variance_accounted_for, converged, stable, describes_data (true/false, empty without a
fit), weighting, failed and reason. A subject whose file cannot be read or whose fit fails
gets rows saying why and never stops the others; a fit that is no success (not converged,
an unstable fitted loop, or VAF below 50 %: the model does not describe the data) keeps its
values, marked failed, and is left out of the summary, which says how many and why.
Prints a summary per parameter: subjects fitted, median and quartiles (--json: one
object, "summary" with the failed subjects and "left_out", and "readings": what reading
each resampled or cut trial did); --summary FILE.json writes it, --plot FIG.png
draws every subject's estimate with its interval over a box of the quartiles. Outputs are
written only when every fit is done, each atomically (Ctrl-C leaves none half-written).
Why a command and not fit-frf --each: fit-frf's --data are one subject's conditions; here
each --data is a subject, and the output is a table.

Example: posturelab cohort --data s01.json s02.json s03.json \\
             --controller peterka-2002 --free active_stiffness:ankle,feedback_delay,\\
proprioceptive_weight --out cohort.csv --plot cohort.png
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``posturelab cohort``."""
    add_data_files(p, "subjects, one file each: trial.csv or frf.json")
    add_fit_arguments(p, per_condition=False)
    p.add_argument("--out", required=True, metavar="TABLE.csv|TABLE.parquet",
                   help="the table: one row per subject and parameter (.csv or .parquet).")
    p.add_argument("--summary", metavar="SUMMARY.json",
                   help="write the summary (median, quartiles per parameter) as JSON.")
    add_flag(p, "--plot", "each parameter's distribution over the subjects")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="worker processes (default: one per CPU; at most four per CPU).")
    add_flags(p, "--progress", "--json")
    add_muscle_arguments(p)


def run(args: argparse.Namespace) -> int:
    from .._files import refuse_input_as_output
    from .._progress import Progress, shown
    from ..frequency.cohort import fit_cohort, max_cohort_workers
    from ..frequency.fit import check_fit_request
    from ..studies.sweep import table_format
    from ._common import check_writable
    from .frf import FIGURE_SUFFIXES

    refuse_input_as_output({"--data": args.data}, {"--out": args.out, "--plot": args.plot,
                                                   "--summary": args.summary})
    table_format(args.out)
    outputs = [p for p in (args.out, args.summary, args.plot) if p]
    check_writable(outputs, {args.out: (".csv", ".parquet", ".pq"),  # before the fits
                             **({args.summary: (".json",)} if args.summary else {}),
                             **({args.plot: FIGURE_SUFFIXES} if args.plot else {})})
    limit = max_cohort_workers()
    if args.workers is not None and not 1 <= args.workers <= limit:
        raise ParameterError(f"--workers must be an integer in 1 … {limit} (4 × the CPUs), "
                             f"got {args.workers}")
    model = model_from_args(args)
    body, muscles, options = model.body, model.muscles, model.options
    from ._recording import check_sway_response

    check_sway_response(args, args.response)
    free = _names(args.free)
    check_fit_request(muscles, free, (), _bounds(args.bounds))  # before any file is read
    bar = (Progress(len(args.data), label="cohort", unit="subjects")
           if shown(args.progress) else None)
    try:
        cohort = fit_cohort(body, muscles, args.data, free, workers=args.workers,
                            progress=bar, reader=reader_options(args), input=args.input,
                            output=args.output.strip().lower(),
                            feedback_delay=options.feedback_delay,
                            proprioceptive_weight=options.proprioceptive_weight,
                            bounds=_bounds(args.bounds))
    finally:
        if bar is not None:
            bar.close()
    summary = cohort.summary()
    _write(cohort, summary, args)
    readings = [{"subject": s.subject, "reading": list(s.reading)} for s in cohort.subjects
                if s.reading]
    if args.json:
        print_json({"out": args.out, "summary": summary,
                    "parameters": list(cohort.parameters),
                    **({"readings": readings} if readings else {})})
        return 0
    import sys

    for item in readings:
        for line in item["reading"]:
            print(f"posturelab: note: {item['subject']}: {line}", file=sys.stderr)
    failed = summary["failed"]
    left = summary["left_out"]
    why = ", ".join(f"{n} {r}" for r, n in left["by_reason"].items())
    print(f"fitted {len(cohort.parameters)} parameter(s) to {len(cohort.subjects)} "
          f"subject(s); {left['count']} left out of the summary" + (f" ({why})" if why
                                                                    else ""))
    for name, row in summary["parameters"].items():
        def num(v):
            return "-" if v is None else f"{v:.4g}"

        print(f"  {name:<24} median {num(row['median'])} (quartiles {num(row['q1'])} … "
              f"{num(row['q3'])}) {row['unit']}; {row['subjects']} fitted, "
              f"{row['determined']} determined")
    for item in failed:
        print(f"left out: {item['subject']}: {item['reason']}")
    for path in (args.out, args.summary, args.plot):
        if path:
            print(f"wrote {path}")
    return 0


def _write(cohort, summary: dict, args: argparse.Namespace) -> None:
    """The table, the summary and the figure, each atomically."""
    import json

    from .._files import atomic_write_text

    cohort.write(args.out)
    if args.summary:
        atomic_write_text(args.summary, json.dumps(summary, indent=2, ensure_ascii=False)
                          + "\n")
    if args.plot:
        from ..viz.plots import plot_cohort, save_figure

        save_figure(plot_cohort(cohort), args.plot)
