"""The help texts and the README say the same thing, and what they say holds.

Checked against: every fit-frf option has a help text and --free lists the parameter names;
the fit-frf example uses the full names the README uses; the README writes the --tilt forms
as simulate's --help does; the README calls --controller a preset after a published model
and says to_dataframe has time as its index (as the test of to_dataframe asserts); the
README's reason for the band bounds of a noise-free simulated trial: each band's
coherence is exactly what the FRF's change across its harmonics gives, while the cycles'
scatter, what fit-frf weighs by, is tiny.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def posturelab_cli(*args):
    return subprocess.run([sys.executable, "-m", "posturelab", *args], capture_output=True,
                          text=True, timeout=300)


def _words(text: str) -> str:
    return " ".join(text.split())


def test_every_fit_frf_option_has_help_and_free_lists_the_names():
    from posturelab.cli import build_parser

    parser = build_parser("fit-frf")
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    options = [a for a in sub.choices["fit-frf"]._actions if a.option_strings]
    undocumented = [a.option_strings[0] for a in options if not a.help]
    assert undocumented == []
    p = posturelab_cli("fit-frf", "--help")
    assert p.returncode == 0, p.stderr
    text = _words(p.stdout)
    listed = text[text.index("options:"):]
    free = listed[listed.index("--free NAMES "):listed.index("--per-condition NAMES ")]
    for name in ("stiffness:PAIR", "viscosity:PAIR", "active_stiffness:PAIR",
                 "active_viscosity:PAIR", "feedback_delay", "proprioceptive_weight"):
        assert name in free
    example = text[text.index("Example: posturelab fit-frf"):]
    used = re.search(r"--free (\S+)", example).group(1).split(",")
    assert used == ["active_stiffness:ankle", "active_viscosity:ankle", "feedback_delay"]
    assert "--free active_stiffness:ankle,feedback_delay" in _words(README.read_text())


def test_the_readme_writes_the_tilt_forms_as_the_help_does():
    help_text = _words(posturelab_cli("simulate", "--help").stdout).replace(", ", ",")
    readme = README.read_text()
    forms = re.findall(r"`((?:sine|raised-cosine|prts):[A-Z_:\[\]]+)`", readme)
    assert sorted(f.split(":")[0] for f in forms) == ["prts", "raised-cosine", "sine"]
    for form in forms:
        assert form in help_text, form
    assert "prts:A[:SEQUENCE]" not in readme


def test_the_readme_says_what_a_controller_preset_and_to_dataframe_are():
    readme = _words(README.read_text())
    assert "published one-link controller" not in readme
    assert "a one-link controller preset after a published model" in readme
    assert "the CSV's columns, time t as the index" in readme


def test_a_noise_free_trial_band_bounds_come_from_the_change_across_harmonics():
    import posturelab as pl
    from posturelab.frequency import estimate_frf
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import PRTSTilt

    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    tilt = PRTSTilt.named("posturelab-80", 0.035)
    run = pl.simulate(body, preset.muscles(body), None, 60.0, tilt=tilt, engine="compiled",
                      sample_rate=100.0, **preset.run_options())
    stimulus, response = run.tilt[:-1], run.com_angle[:-1]  # three whole 20 s cycles
    bands = estimate_frf(stimulus, response, 100.0, 20.0, discard_cycles=1,
                         response_sign=-1.0)
    each = estimate_frf(stimulus, response, 100.0, 20.0, discard_cycles=1,
                        bands="harmonics", response_sign=-1.0)
    used = sorted({j for b in bands.bands for j in b})  # the bands' harmonics, to 2.2 Hz
    h_of = {b[0]: h for b, h in zip(each.bands, each.frf, strict=True)}
    gamma_of = {b[0]: g for b, g in zip(each.bands, each.coherence, strict=True)}
    assert min(gamma_of[j] for j in used) > 0.9999  # one harmonic per band: bounds closed
    wide = [i for i, b in enumerate(bands.bands) if len(b) > 1]
    assert wide and bands.coherence[wide].max() < 0.999
    for i in wide:
        w = bands.harmonic_weight[i]
        h = np.array([h_of[j] for j in bands.bands[i]])
        # a noise-free band's coherence from H's change across its harmonics alone
        spread = abs(np.sum(w * h)) ** 2 / (np.sum(w) * np.sum(w * abs(h) ** 2))
        np.testing.assert_allclose(bands.coherence[i], spread, rtol=1e-6)
    # the cycles' scatter (fit-frf's weights) is far below that spread
    assert np.sqrt(bands.variance).max() < 1e-3 * np.abs(bands.frf).min()
