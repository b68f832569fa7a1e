"""The compiled engine's default tolerances, in a module of their own so that what states
them (the sweep's defaults, ``--help``) does not load the engine
(:mod:`posturelab.simulation.compiled` re-exports them)."""

#: Default relative tolerance of the compiled engine. [-]
DEFAULT_RTOL = 1e-6
#: Default absolute tolerance [rad, rad/s]. With rtol = 1e-6 the angle error of the paper's
#: scenarios and of random-gain sweeps stays below 1e-6 rad against a DOP853 rtol = 1e-10
#: reference (measured by benchmarks/bench_simulate.py; tested in tests/test_fast.py).
DEFAULT_ATOL = 1e-9
