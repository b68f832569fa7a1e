"""Shared test helper: random but valid bodies (every caller passes a seeded generator)."""

from posturelab.model.body import Body


def random_body(rng, n, gravity=9.81):
    """A random N-link body; ``gravity=None`` draws g from [5, 15] m/s² too."""
    lengths = rng.uniform(0.2, 0.9, n)
    return Body.from_arrays(
        masses=rng.uniform(1.0, 40.0, n),
        lengths=lengths,
        com_distances=rng.uniform(0.0, 1.0, n) * lengths,
        inertias=rng.uniform(0.05, 3.0, n),
        gravity=rng.uniform(5.0, 15.0) if gravity is None else gravity,
    )
