import numpy as np
import pytest

from posturelab.model.body import paper_body


@pytest.fixture
def body():
    """The paper's three-link body (Appendix A)."""
    return paper_body()


@pytest.fixture
def rng():
    """A seeded generator: every random test is repeatable."""
    return np.random.default_rng(20261122)


@pytest.fixture(scope="module")
def prts_trial():
    """Peterka 2002's one-link controller on a PRTS tilt, 3 cycles of 20 s at 1 kHz: time
    [s], tilt [rad], com_angle [rad] (the recordings tests' reference trial)."""
    import posturelab as pl
    from posturelab.model.controllers import get_controller
    from posturelab.model.tilt import PRTSTilt

    body = pl.get_body("paper-1link")
    preset = get_controller("peterka-2002")
    r = pl.simulate(body, preset.muscles(body), None, 60.0,
                    tilt=PRTSTilt.named("posturelab-80", 0.035), engine="compiled",
                    sample_rate=1000.0, rtol=1e-9, atol=1e-11, **preset.run_options())
    return r.time, r.tilt, r.com_angle
