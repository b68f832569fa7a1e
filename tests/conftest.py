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
