"""Checks of a model's parts at the public API's edge (the generic checks of fields and values
are in :mod:`posturelab._validation`, which knows nothing of the model)."""

from __future__ import annotations

from typing import Any

from .._validation import expect_type
from ..errors import ParameterError
from .body import Body
from .muscles import MuscleSet

__all__ = ["check_model"]


def check_model(body: Any, muscles: Any = None) -> None:
    """The public API's first check: ``body`` is a Body, ``muscles`` (if given) a MuscleSet
    for as many links."""
    expect_type("body", body, Body)
    if muscles is not None:
        expect_type("muscles", muscles, MuscleSet)
        if muscles.n_links != body.n_links:
            raise ParameterError(f"muscle set is for {muscles.n_links} links but the body "
                                 f"has {body.n_links}")
