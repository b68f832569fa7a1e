"""Exceptions raised by posturelab.

Every error a user can cause by bad input derives from :class:`PostureLabError`;
the command line turns these into one line on standard error and exit code 2.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TypeVar

_T = TypeVar("_T")


class PostureLabError(Exception):
    """Base class of all errors that posturelab raises on purpose."""


class ParameterError(PostureLabError, ValueError):
    """A parameter is missing, of the wrong shape, or outside its allowed range.

    The message names the field, the value given and the allowed range.
    """


class UnknownNameError(PostureLabError, KeyError):
    """A preset, case or pair name is not in its registry; the message lists the known ones."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class ScenarioError(PostureLabError, ValueError):
    """A scenario file is malformed or has an unknown key."""


class DataFileError(PostureLabError, ValueError):
    """A data file (platform profile, measurement) cannot be read or fails validation."""


class UnknownParameterError(UnknownNameError, ParameterError):
    """A parameter name that is not in the parameter table (:mod:`posturelab.parameters`),
    or names a pair or joint the body lacks; the message lists the known ones."""


def lookup(registry: Mapping[str, _T], name: object, what: str, known: str = "known") -> _T:
    """``registry[name]`` (the name trimmed and lower-cased): a named preset. An unknown
    name raises :class:`UnknownNameError` "unknown {what} 'x'; {known}: a, b, …", listing the
    registry's names in order."""
    try:
        return registry[str(name).strip().lower()]
    except KeyError:
        raise UnknownNameError(f"unknown {what} {name!r}; {known}: "
                               f"{', '.join(registry)}") from None
