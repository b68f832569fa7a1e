"""The ankle-strategy paper: its printed numbers, captions and errata (:mod:`.printed`), the
comparison of printed and computed values (:mod:`.compare`) and the reproduction report,
imported on first use: its runs (:mod:`.runs`), checks and findings as data
(:mod:`posturelab.paper.checks`, :mod:`.findings`), figures (:mod:`.figures`) and the page
rendered from
``templates/report.html.j2`` (:mod:`.report`)."""

from .._lazy import submodule_getattr  # noqa: E402
from .printed import (
    BACKWARD_INITIAL_STATE,
    BACKWARD_INITIAL_STATE_SOURCE,
    ERRATA,
    SENSITIVITY_PRINTED,
    SENSITIVITY_SOURCE,
    TABLE_II_PRINTED,
    TABLE_II_SOURCE,
    Erratum,
    match_printed_poles,
    printed_decimals,
    printed_tolerance,
)

__getattr__ = submodule_getattr(__name__, __path__)
