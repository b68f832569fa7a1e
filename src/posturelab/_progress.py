"""Progress bars on standard error (private): the one bar every long command draws, by tqdm.

A :class:`Progress` is what the library's ``progress(done, total)`` callbacks expect
(:func:`posturelab.studies.sweep.run_sweep`, :func:`posturelab.linear.batch.stability_map`,
:func:`posturelab.paper.report.reproduce_paper`, ...): call it with the number of finished
items, or use :meth:`Progress.update` and :meth:`Progress.close`. One line, redrawn in place::

    stability-map [##########....................]  33% 330000/1000000 sets [00:01<00:02]

tqdm is imported when the first bar is made, so that importing this module costs nothing.
"""

from __future__ import annotations

import sys
from typing import IO

__all__ = ["Progress", "shown"]

#: The line of every bar: label, bar, percentage, done/total, unit, elapsed<left, note.
BAR_FORMAT = ("{desc}[{bar:%d}] {percentage:3.0f}%% {n_fmt}/{total_fmt} {unit} "
              "[{elapsed}<{remaining}]{postfix}")


def shown(forced: bool, stream: IO[str] | None = None) -> bool:
    """Whether to draw a bar: ``forced`` (a command's ``--progress``) or ``stream`` (standard
    error by default) is a terminal."""
    stream = sys.stderr if stream is None else stream
    if forced:
        return True
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # (a closed or file-less stream)
        return False


class Progress:
    """A one-line progress bar (tqdm) counting finished items of a known total.

    Parameters
    ----------
    total : int, optional
        Items to do; may be given or changed later by calling the bar. [-]
    label : str
        Text before the bar (the command's name).
    unit : str
        What is counted ("runs", "sets", "rows", "steps").
    stream : text stream, optional
        Where to draw; standard error by default.
    width : int
        Characters of the bar itself. [-]
    every_step : bool
        Redraw on every change (for a few long steps); otherwise at most ten times a second.
    """

    def __init__(self, total: int | None = None, *, label: str = "", unit: str = "runs",
                 stream: IO[str] | None = None, width: int = 30,
                 every_step: bool = False) -> None:
        self._options = dict(desc=label.rstrip() + " " if label else "", unit=unit,
                             file=sys.stderr if stream is None else stream,
                             bar_format=BAR_FORMAT % width, ascii=".#", leave=True,
                             mininterval=0.0 if every_step else 0.1, dynamic_ncols=False)
        self._tqdm = None
        self._closed = False
        if total is not None:  # (else drawn from the first call, which gives the total)
            self._start(total)

    def _start(self, total: int) -> None:
        from tqdm import tqdm

        self._tqdm = tqdm(total=max(int(total), 0), **self._options)

    @property
    def done(self) -> int:
        """Items finished so far. [-]"""
        return 0 if self._tqdm is None else int(self._tqdm.n)

    @property
    def total(self) -> int | None:
        """Items to do. [-]"""
        return None if self._tqdm is None else int(self._tqdm.total)

    def update(self, done: int, note: str | None = None) -> None:
        """Set the number of finished items (not an increment) and redraw if due; ``note``
        is shown after the bar (the step now running)."""
        bar = self._tqdm
        if bar is None:
            raise ValueError("a progress bar made without a total is started by calling it")
        if note is not None:
            bar.set_postfix_str(note, refresh=False)
        done = min(max(int(done), 0), int(bar.total))
        if done != bar.n:
            bar.update(done - bar.n)
        elif note is not None:
            bar.refresh()

    def __call__(self, done: int, total: int, note: str | None = None) -> None:
        """``progress(done, total)``, the library's callback: ``total`` [-] may change."""
        if self._tqdm is None:
            self._start(total)
        elif self._tqdm.total != total:
            self._tqdm.total = max(int(total), 0)
        self.update(done, note)

    def close(self) -> None:
        """Draw the last state and end the line (again: nothing)."""
        if not self._closed:
            self._closed = True
            if self._tqdm is not None:
                self._tqdm.close()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
