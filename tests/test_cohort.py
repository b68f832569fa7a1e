"""Cohort fits (posturelab.frequency.cohort, posturelab cohort): every subject's FRF fitted
with one model, in worker processes; one row per subject and parameter; a failed subject is a
row saying why; the summary's median and quartiles; nothing written when interrupted.

The synthetic cohort: seeded virtual subjects whose gains, delay and W are drawn about a
published controller (icm-pmc5664365), each measured as the model's exact FRF at the 11
bands plus complex noise of a stated standard error; written as the three kinds of FRF file
(frf with frf_se, gain and phase with their standard errors, and a trial CSV).
"""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import posturelab as pl
from _cli import cli, one_line_exit_2
from posturelab.errors import ParameterError
from posturelab.frequency import FRFTable, model_frf
from posturelab.frequency.bands import PETERKA_BAND_FREQUENCIES
from posturelab.frequency.cohort import fit_cohort
from posturelab.model.controllers import get_controller
from posturelab.model.tilt import PRTSTilt

BODY = pl.get_body("paper-1link")
PRESET = get_controller("icm-pmc5664365")
BASE = PRESET.muscles(BODY)
FREQ = np.asarray(PETERKA_BAND_FREQUENCIES)
FREE = ["active_stiffness:ankle", "active_viscosity:ankle", "feedback_delay",
        "proprioceptive_weight"]
START = {"feedback_delay": 0.1, "proprioceptive_weight": 0.7}
CONTROLLER = ["--body", "paper-1link", "--controller", "icm-pmc5664365", "--feedback-delay",
              "0.1", "--proprioceptive-weight", "0.7"]


def subject_truth(rng) -> dict:
    """A virtual subject: each parameter drawn uniformly within ±20 % of the preset's (W in
    0.5 … 0.9)."""
    return {"active_stiffness:ankle": BASE.active_stiffnesses[0] * rng.uniform(0.8, 1.2),
            "active_viscosity:ankle": BASE.active_viscosities[0] * rng.uniform(0.8, 1.2),
            "feedback_delay": PRESET.feedback_delay * rng.uniform(0.8, 1.2),
            "proprioceptive_weight": rng.uniform(0.5, 0.9)}


def subject_frf(truth: dict, frequency=FREQ):
    muscles = BASE.with_active_feedback([truth["active_stiffness:ankle"]],
                                        [truth["active_viscosity:ankle"]])
    return model_frf(BODY, muscles, frequency, feedback_delay=truth["feedback_delay"],
                     proprioceptive_weight=truth["proprioceptive_weight"])


def measured(truth: dict, rng, relative_se: float = 0.05) -> FRFTable:
    H = subject_frf(truth)
    se = relative_se * np.abs(H)
    noise = se / np.sqrt(2) * (rng.normal(size=H.size) + 1j * rng.normal(size=H.size))
    return FRFTable(FREQ, H + noise, frf_se=se)


@pytest.fixture(scope="module")
def cohort_files(tmp_path_factory):
    """Six subjects: two FRF JSONs with frf_se, two gain-and-phase-only tables with their
    standard errors, one trial CSV (three 20 s cycles of a 0.035 rad PRTS, white noise on
    the sway), one file that is no FRF; their truths by file stem."""
    rng = np.random.default_rng(20261202)
    folder = tmp_path_factory.mktemp("cohort")
    truths, paths = {}, []
    for k in range(4):
        name = f"s{k + 1:02d}"
        truths[name] = truth = subject_truth(rng)
        table = measured(truth, rng)
        if k < 2:
            obj = {"frequency": FREQ.tolist(),
                   "frf": [{"re": z.real, "im": z.imag} for z in table.frf],
                   "frf_se": table.frf_se.tolist()}
        else:  # gain and phase only, their standard errors to first order
            obj = {"frequency": FREQ.tolist(), "gain": table.gain.tolist(),
                   "phase_deg": table.phase_deg.tolist(),
                   "gain_se": (table.frf_se / np.sqrt(2)).tolist(),
                   "phase_se_deg": np.degrees(table.frf_se / np.sqrt(2)
                                              / table.gain).tolist()}
        path = folder / f"{name}.json"
        path.write_text(json.dumps(obj))
        paths.append(str(path))
    truths["s05"] = truth = subject_truth(rng)
    L, T = 1000, 20.0
    x = PRTSTilt.named("posturelab-80", 0.035).angle(np.arange(L) * T / L)
    X = np.fft.rfft(x)
    H = np.zeros(X.size, complex)
    H[1:] = subject_frf(truth, np.arange(1, X.size) / T)
    sway = -np.fft.irfft(H * X, L)  # the recorded angle: H = −y/α
    y = np.tile(sway, 3) + rng.normal(0.0, 0.001, 3 * L)
    with open(folder / "s05.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["t", "tilt", "com_angle"])
        for i, (a, b) in enumerate(zip(np.tile(x, 3), y, strict=True)):
            w.writerow([i * T / L, a, b])
    paths.append(str(folder / "s05.csv"))
    (folder / "s06.json").write_text('{"frequency": [0.1], "colour": "blue"}')
    paths.append(str(folder / "s06.json"))
    return paths, truths


READER = {"stimulus": "tilt", "response": "com_angle", "cycle_length": 20.0,
          "response_sign": -1}


def test_each_subject_is_fitted_and_a_bad_file_is_a_row_saying_why(cohort_files):
    paths, truths = cohort_files
    cohort = fit_cohort(BODY, BASE, paths, FREE, workers=1, reader=READER, **START)
    assert cohort.parameters == tuple(FREE)
    assert [s.subject for s in cohort.subjects] == ["s01", "s02", "s03", "s04", "s05", "s06"]
    assert cohort.failed == ("s06",)
    bad = cohort.subjects[-1]
    assert "needs frf, or gain and phase_deg" in bad.reason and "s06.json" in bad.reason
    assert np.isnan(bad.estimates).all()
    inside = total = 0
    for s in cohort.subjects[:-1]:
        assert not s.failed and s.determined.all(), s
        truth = np.array([truths[s.subject][n] for n in FREE])
        # within 5 standard errors every time, inside the 95 % interval nearly every time
        assert np.all(np.abs(s.estimates - truth) <= 5 * s.standard_errors), s.subject
        inside += int(np.sum((s.confidence_intervals[:, 0] <= truth)
                             & (truth <= s.confidence_intervals[:, 1])))
        total += truth.size
    assert inside >= total - 2, (inside, total)
    assert [s.weighting for s in cohort.subjects[:5]] == ["variance", "variance",
                                                         "gain-phase", "gain-phase",
                                                         "variance"]


def test_the_same_table_from_worker_processes(cohort_files):
    """Two worker processes give the table one process gives, in the subjects' order."""
    paths, _ = cohort_files
    one = fit_cohort(BODY, BASE, paths[:4], FREE, workers=1, **START)
    two = fit_cohort(BODY, BASE, paths[:4], FREE, workers=2, **START)
    for a, b in zip(one.subjects, two.subjects, strict=True):
        assert a.subject == b.subject
        np.testing.assert_array_equal(a.estimates, b.estimates)
        np.testing.assert_array_equal(a.confidence_intervals, b.confidence_intervals)


def test_the_summary_gives_the_median_and_quartiles():
    rng = np.random.default_rng(7)
    truths = [subject_truth(rng) for _ in range(7)]
    cohort = fit_cohort(BODY, BASE, [measured(t, rng, 0.02) for t in truths], FREE,
                        workers=1, **START)
    summary = cohort.summary()
    assert summary["subjects"] == 7 and summary["failed"] == []
    for name in FREE:
        v = cohort.values(name)
        row = summary["parameters"][name]
        assert row["subjects"] == 7
        assert row["median"] == pytest.approx(np.median(v))
        assert [row["q1"], row["q3"]] == pytest.approx(np.percentile(v, [25, 75]))
    columns = dict(cohort.columns())
    assert len(columns["subject"]) == 7 * len(FREE)
    assert list(columns["parameter"][:4]) == FREE and not columns["failed"].any()


@pytest.mark.parametrize("kwargs, needle", [
    ({"subjects": []}, "needs 1"),
    ({"workers": 0}, "--workers must be an integer"),
    ({"free": ["stiffnes"]}, "stiffnes"),
    ({"per_condition": ["proprioceptive_weight"]}, "no per-condition"),
    ({"names": ["a"]}, "names must name each"),
])
def test_bad_cohort_requests_are_refused(kwargs, needle):
    rng = np.random.default_rng(3)
    call = {"subjects": [measured(subject_truth(rng), rng) for _ in range(2)], "free": FREE,
            **kwargs}
    with pytest.raises(ParameterError, match=needle):
        fit_cohort(BODY, BASE, call.pop("subjects"), call.pop("free"), **call)


def test_the_cohort_command_writes_the_table_summary_and_figure(cohort_files, tmp_path):
    paths, truths = cohort_files
    data = [a for p in paths for a in ("--data", p)]
    out = tmp_path / "cohort.csv"
    p = cli("cohort", *data, *CONTROLLER, "--free", ",".join(FREE), "--stimulus", "tilt",
            "--response", "com_angle", "--cycle-length", "20", "--out", str(out),
            "--summary", str(tmp_path / "summary.json"), "--plot", str(tmp_path / "c.png"),
            "--workers", "2", "--json")
    assert p.returncode == 0, p.stderr
    printed = json.loads(p.stdout)
    assert printed["summary"]["failed"][0]["subject"] == "s06"
    assert json.loads((tmp_path / "summary.json").read_text()) == printed["summary"]
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["subject", "parameter", "unit", "value", "standard_error",
                             "ci95_low", "ci95_high", "determined", "fit_error",
                             "variance_accounted_for", "converged", "stable", "describes_data",
                             "weighting", "failed", "reason"]
    assert len(rows) == 6 * len(FREE)
    s05 = {r["parameter"]: r for r in rows if r["subject"] == "s05"}
    w = s05["proprioceptive_weight"]
    assert w["failed"] == "false" and w["unit"] == "-"
    assert float(w["ci95_low"]) <= truths["s05"]["proprioceptive_weight"] <= float(
        w["ci95_high"])
    assert all(None not in r for r in rows)  # (a reason's commas stay in its cell)
    assert w["stable"] == "true" and w["describes_data"] == "true"
    assert all(r["failed"] == "true" and r["value"] == "" and r["stable"] == ""
               and r["reason"].endswith("needs frf, or gain and phase_deg")
               for r in rows if r["subject"] == "s06")
    assert (tmp_path / "c.png").read_bytes()[:4] == b"\x89PNG"
    # several files after one --data (as a shell pattern gives them)
    p = cli("cohort", "--data", *paths[:4], *CONTROLLER, "--free", ",".join(FREE), "--out",
            str(tmp_path / "plain.csv"), "--workers", "1")
    assert p.returncode == 0, p.stderr
    assert "to 4 subject(s); 0 left out of the summary" in p.stdout and "quartiles" in p.stdout
    assert len((tmp_path / "plain.csv").read_text().splitlines()) == 1 + 4 * len(FREE)


def test_the_cohort_command_refuses_before_any_fit(cohort_files, tmp_path):
    paths, _ = cohort_files
    base = ["cohort", "--data", paths[0], *CONTROLLER, "--free", ",".join(FREE)]
    one_line_exit_2(cli(*base, "--out", str(tmp_path / "x.txt")), "must end in .csv")
    one_line_exit_2(cli(*base, "--out", str(tmp_path / "missing" / "x.csv")),
                    "does not exist")
    one_line_exit_2(cli(*base, "--out", str(tmp_path / "x.csv"), "--workers", "999"),
                    "--workers must be an integer")
    one_line_exit_2(cli(*base, "--data", paths[4], "--out", paths[4]),
                    "an output never overwrites an input")


def test_an_interrupted_cohort_writes_nothing(cohort_files, tmp_path, monkeypatch):
    """Ctrl-C during the fits: exit 130, no table, no summary, no temporary left."""
    import posturelab.frequency.cohort as cohort_module
    from posturelab.cli import main

    def interrupted(*args, **kwargs):
        kwargs["progress"](1, 4)
        raise KeyboardInterrupt

    monkeypatch.setattr(cohort_module, "fit_cohort", interrupted)
    paths, _ = cohort_files
    code = main(["cohort", *[a for p in paths[:4] for a in ("--data", p)], *CONTROLLER,
                 "--free", ",".join(FREE), "--out", str(tmp_path / "c.csv"), "--summary",
                 str(tmp_path / "s.json"), "--progress"])
    assert code == 130
    assert list(tmp_path.iterdir()) == []


def test_the_table_as_parquet_keeps_the_rows(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    rng = np.random.default_rng(11)
    subjects = [measured(subject_truth(rng), rng) for _ in range(3)]
    cohort = fit_cohort(BODY, BASE, subjects, FREE, workers=1, **START)
    cohort.write(tmp_path / "c.parquet")
    table = pq.read_table(tmp_path / "c.parquet").to_pydict()
    assert table["subject"] == [f"subject {k}" for k in (1, 2, 3) for _ in FREE]
    np.testing.assert_array_equal(table["value"], dict(cohort.columns())["value"])
    assert table["failed"] == [False] * 12
