"""The small synthetic C3D file posturelab ships, and how it was made.

``data/lab/prts_trial.c3d`` (:data:`EXAMPLE_C3D`): Peterka's (2002) one-link controller
(``peterka-2002`` on ``paper-1link``) standing on a 0.035 rad PRTS tilt (the 80-state
sequence, three 20 s cycles), simulated with the compiled engine and recorded as a
motion-capture lab would: four markers ``ank``, ``kne``, ``hip``, ``sho`` on the body's
line at the heights of Winter's (2009) Fig. 4.1 for a 1.75 m subject (lateral malleolus
0.039 H, knee 0.285 H, greater trochanter 0.530 H, shoulder 0.818 H), in millimetres at
50 Hz with 0.3 mm of (seeded) noise; the platform's tilt as an analog channel ``tilt`` in
degrees at 100 Hz. The lab's axes: x forward, y to the left, z up; the ankle joint at
x = 0, on the tilt axis.

On a one-link body every marker lies on the link, so the segment model's centre-of-mass
angle is the link angle, posturelab's ``com_angle``, up to the markers' noise.

``python -m posturelab.recordings.example OUT.c3d`` copies the shipped file;
``python -m posturelab.recordings.example OUT.csv`` writes a lab-style CSV made from it
(:func:`make_lab_csv`); ``--regenerate`` simulates and writes the shipped file again.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["EXAMPLE_C3D", "make_example_recording", "make_lab_csv", "EXAMPLE_HEIGHT"]

#: The shipped file.
EXAMPLE_C3D = Path(__file__).resolve().parents[1] / "data" / "lab" / "prts_trial.c3d"
#: The subject's height the markers are placed for. [m]
EXAMPLE_HEIGHT = 1.75
#: Marker noise (standard deviation). [m]
MARKER_NOISE = 3e-4


def make_example_recording(path: str | Path, seed: int = 20261204) -> None:
    """Simulate the trial and write it as a C3D file (see the module's docstring)."""
    import posturelab as pl
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import PRTSTilt

    from .c3d import write_c3d
    from .sway import LANDMARK_HEIGHTS

    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    run = pl.simulate(body, preset.muscles(body), None, 60.0,
                      tilt=PRTSTilt.named("posturelab-80", 0.035), engine="compiled",
                      sample_rate=100.0, **preset.run_options())
    rng = np.random.default_rng(seed)
    theta = run.theta[:-1:2, 0]  # 50 Hz, the end point left out: 3 whole cycles
    markers = {}
    for label, landmark in (("ank", "ankle"), ("kne", "knee"), ("hip", "hip"),
                            ("sho", "shoulder")):
        r = (LANDMARK_HEIGHTS[landmark] - LANDMARK_HEIGHTS["ankle"]) * EXAMPLE_HEIGHT
        ankle_z = LANDMARK_HEIGHTS["ankle"] * EXAMPLE_HEIGHT
        xyz = np.column_stack([r * np.sin(theta), np.full(theta.size, 0.1),
                               ankle_z + r * np.cos(theta)])
        markers[label] = xyz + rng.normal(0.0, MARKER_NOISE, xyz.shape)
    write_c3d(path, markers, 50.0, analogs={"tilt": np.degrees(run.tilt[:-1])},
              analog_rate=100.0, analog_units={"tilt": "deg"}, point_units="mm")


def make_lab_csv(path: str | Path, seed: int = 21) -> None:
    """A CSV as a lab's acquisition software writes one, from the shipped C3D file: a time
    column [s] stepping unevenly (0.0107–0.0117 s, as a motion-capture clock), the platform
    angle ``stim_pitch`` in degrees, and the forward positions of the hip and shoulder
    markers ``hip_xpos``, ``shld_xpos`` in millimetres, without units in the header (the
    values by a cubic spline through the C3D's samples)."""
    from scipy.interpolate import CubicSpline

    from .._files import atomic_write_text
    from .c3d import read_c3d

    rec = read_c3d(EXAMPLE_C3D)
    rng = np.random.default_rng(seed)
    steps = rng.uniform(0.0107, 0.0117, int(rec.time[-1] / 0.0107) + 2)
    t = np.concatenate([[0.0], np.cumsum(steps)])
    t = t[t < rec.time.size / rec.rate]  # the C3D's record: 3 whole cycles, 0 … 60 s
    cols = [t, CubicSpline(rec.time, rec.columns["tilt"])(t),  # ANALOG:UNITS deg
            1000 * CubicSpline(rec.time, rec.columns["hip_x"])(t),
            1000 * CubicSpline(rec.time, rec.columns["sho_x"])(t)]
    rows = "".join(",".join(f"{v:.6f}" for v in row) + "\n" for row in zip(*cols, strict=True))
    atomic_write_text(path, "time,stim_pitch,hip_xpos,shld_xpos\n" + rows)


if __name__ == "__main__":
    import shutil
    import sys

    out = sys.argv[1] if len(sys.argv) > 1 else "prts_trial.c3d"
    if out == "--regenerate":
        make_example_recording(EXAMPLE_C3D)
    elif out.lower().endswith(".csv"):
        make_lab_csv(out)
    else:
        shutil.copyfile(EXAMPLE_C3D, out)
