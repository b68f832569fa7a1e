"""Reading input files safely and writing outputs atomically (private): one reader for every
text and CSV input, one writer for every output.

Every input file is checked the same way before a byte is parsed:

* it must be a regular file (a directory, a device such as ``/dev/zero``, a FIFO or a
  socket gets one line, never a hang);
* at most :data:`MAX_INPUT_BYTES` (a scenario at most :data:`MAX_SCENARIO_BYTES`);
* UTF-8, with or without a byte-order mark; another encoding is named by the offset of its
  first bad byte;
* a CSV has at most :data:`MAX_DATA_ROWS` data rows and no field longer than the csv
  module's limit (:data:`MAX_FIELD_CHARS` characters); errors name the line.

Messages never quote the file's content back.

Every output goes through :func:`atomic_outputs` (or :func:`atomic_write_files`,
:func:`atomic_write_bytes`, :func:`atomic_write_text` built on it): each file is written to a
temporary file beside it, with the mode a new file gets, and renamed into place only when all
are written; a failure or Ctrl-C leaves none of them. A device, FIFO or socket is never
replaced.
"""

from __future__ import annotations

import contextlib
import csv
import io
import os
import stat
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path

from .errors import DataFileError, ParameterError, PostureLabError

__all__ = ["MAX_INPUT_BYTES", "MAX_SCENARIO_BYTES", "MAX_DATA_ROWS", "MAX_FIELD_CHARS",
           "read_text", "csv_rows", "refuse_non_regular", "refuse_input_as_output",
           "new_file_mode", "atomic_outputs", "atomic_write_files", "atomic_write_bytes",
           "atomic_write_text", "atomic_write_csv", "check_output_rows"]

#: Largest data file read. [bytes]
MAX_INPUT_BYTES = 512 * 2**20
#: Largest scenario file read. [bytes]
MAX_SCENARIO_BYTES = 2**20
#: Most data rows a CSV may have (33 min at 1 kHz, 5.6 h at 100 Hz). [-]
MAX_DATA_ROWS = 2_000_000
#: Longest CSV field. [characters]
MAX_FIELD_CHARS = 131_072


def read_text(path: str | Path, what: str, *, max_bytes: int = MAX_INPUT_BYTES,
              error: type[PostureLabError] = DataFileError) -> str:
    """The text of a regular UTF-8 file (a byte-order mark dropped), or ``error`` in one
    line naming ``what`` and the file."""
    path = Path(path)
    name = f"{what} {str(path)!r}"
    try:
        info = os.stat(path)
    except OSError as exc:
        raise error(f"cannot read {name}: {exc.strerror or exc}") from None
    if stat.S_ISDIR(info.st_mode):
        raise error(f"cannot read {name}: it is a directory")
    if not stat.S_ISREG(info.st_mode):
        raise error(f"cannot read {name}: not a regular file (a device, FIFO or socket)")
    if info.st_size > max_bytes:
        raise error(f"{name} is {info.st_size:,} bytes; at most {max_bytes:,} are read")
    try:
        with open(path, "rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise error(f"cannot read {name}: {exc.strerror or exc}") from None
    if len(data) > max_bytes:
        raise error(f"{name} is more than {max_bytes:,} bytes; at most {max_bytes:,} are read")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise error(f"{name} is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
                    f"{exc.start})") from None


def csv_rows(text: str, what: str, *, max_rows: int = MAX_DATA_ROWS
             ) -> Iterator[tuple[int, list[str]]]:
    """(line number, cells) of each non-blank CSV row of ``text``, the header first; a
    DataFileError in one line for a malformed row, a row with more fields than the header
    (empty trailing fields aside), a field over :data:`MAX_FIELD_CHARS` characters or more
    than ``max_rows`` data rows."""
    # Counted before any parsing, so that an oversized table is refused at once rather than
    # after seconds of parsing (a quoted field with a line break can only over-count).
    if text.count("\n") > max_rows + 1:
        lines = sum(1 for line in text.splitlines() if line.strip())
        if lines > max_rows + 1:
            raise DataFileError(f"{what} has more than {max_rows:,} data rows; at most "
                                f"{max_rows:,} are read")
    reader = csv.reader(io.StringIO(text, newline=""))
    count = 0
    width = 0
    while True:
        try:
            row = next(reader)
        except StopIteration:
            return
        except csv.Error as exc:
            line = reader.line_num
            if "field larger than field limit" in str(exc):
                raise DataFileError(f"{what} line {line}: a field longer than "
                                    f"{MAX_FIELD_CHARS:,} characters") from None
            raise DataFileError(f"{what} line {line} is not valid CSV: {exc}") from None
        if not row or not any(cell.strip() for cell in row):
            continue
        count += 1
        if count == 1:
            width = len(row)
        elif len(row) > width and any(cell.strip() for cell in row[width:]):
            fields = max(k for k, cell in enumerate(row) if cell.strip()) + 1
            raise DataFileError(f"{what} line {reader.line_num} has {fields} fields; the "
                                f"header has {width}")
        if count > max_rows + 1:
            raise DataFileError(f"{what} has more than {max_rows:,} data rows; at most "
                                f"{max_rows:,} are read")
        yield reader.line_num, row


def header_words(cells: list[str]) -> str:
    """The header's column names for a message, or words saying it is not a header: names
    are listed only when there are at least two, each at most 32 characters (a line of text
    or data is not quoted back)."""
    names = [c.strip() for c in cells]
    if len(names) >= 2 and all(0 < len(c) <= 32 for c in names):
        return "found " + ", ".join(names)
    return "its first line is not a header of column names"


def refuse_non_regular(path: str | Path, error: type[PostureLabError]) -> None:
    """Raise ``error`` unless ``path`` is missing or a regular file: an output never
    replaces a device, FIFO or socket."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return
    if not stat.S_ISREG(mode):
        raise error(f"cannot write {str(path)!r}: it exists and is not a regular file (a "
                    "device, FIFO or socket is never replaced)")


def _named_paths(options: dict[str, str | Path | list | tuple | None]
                 ) -> list[tuple[str, str]]:
    """(option, path) of every path given, lists flattened, None left out."""
    out = []
    for option, value in options.items():
        values = value if isinstance(value, list | tuple) else [value]
        out.extend((option, str(v)) for v in values if v)
    return out


def refuse_input_as_output(inputs: dict[str, str | Path | list | tuple | None],
                           outputs: dict[str, str | Path | list | tuple | None]) -> None:
    """Raise ParameterError in one line, before any work, when an output would overwrite an
    input: the same file by any path (a symbolic or hard link, ``./x`` for ``x``).

    ``inputs`` and ``outputs`` map each option as the user typed it (``"--data"``,
    ``"RUN.csv"`` for a positional argument) to its path, a list of paths or None (not
    given). Every command that reads a file and writes one calls this once."""
    given = _named_paths(inputs)
    for out_option, out_path in _named_paths(outputs):
        if not os.path.exists(out_path):
            continue  # a file not there yet is no input
        for in_option, in_path in given:
            try:
                same = os.path.samefile(out_path, in_path)
            except OSError:
                same = False
            if same:
                raise ParameterError(f"{out_option} {out_path!r} is the input {in_option} "
                                     f"{in_path!r}; an output never overwrites an input")


#: Other spellings of the units posturelab reads, by their lower-case form.
UNIT_SPELLINGS = {"°": "deg", "degree": "deg", "degrees": "deg", "radian": "rad",
                  "radians": "rad", "°/s": "deg/s", "degrees/s": "deg/s", "rad/sec": "rad/s",
                  "sec": "s", "second": "s", "seconds": "s", "msec": "ms",
                  "millisecond": "ms", "milliseconds": "ms", "meter": "m", "meters": "m",
                  "metre": "m", "metres": "m", "millimeter": "mm", "millimeters": "mm",
                  "millimetre": "mm", "millimetres": "mm"}


def column_unit(header: str) -> str:
    """The unit a header cell declares in brackets (``"stim [deg]"`` → ``"deg"``; other
    spellings of a unit, ``[°]``, ``[degrees]``, ``[sec]``, as :data:`UNIT_SPELLINGS`), or
    ``""``."""
    if "[" not in header:
        return ""
    unit = header.split("[", 1)[1].split("]", 1)[0].strip()
    return UNIT_SPELLINGS.get(unit.lower(), unit)


def check_column_unit(what: str, header: str, accepted: tuple[str, ...],
                      reads: str | None = None) -> None:
    """Refuse a column whose header declares a unit (``name [unit]``) other than ``accepted``
    (none declared is read in posturelab's units): a unit is never ignored nor rescaled.
    ``reads`` says what posturelab reads in which unit (default: angles, translations, time).

    Raises
    ------
    DataFileError
        One line naming the file, the column, its unit and the units posturelab reads.
    """
    unit = column_unit(header)
    if unit == "" or unit in accepted or unit.lower() in {a.lower() for a in accepted}:
        return
    if reads is None:
        reads = ("time in s" if accepted == ("s",)
                 else "angles in rad, translations in m and time in s")
    raise DataFileError(f"{what}: column {header.strip()!r} is in {unit}; posturelab reads "
                        f"{reads}: convert the column (expected "
                        f"{' or '.join(f'[{a}]' for a in accepted)} or no unit)")


# ---- writing ----------------------------------------------------------------


def new_file_mode() -> int:
    """Permission bits a newly created file gets under the current umask (0o644 for 022).

    ``tempfile.mkstemp`` creates 0600 files; the atomic writers set this mode before renaming.
    """
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _unlink_quietly(path: str | Path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


@contextlib.contextmanager
def atomic_outputs(paths: Sequence[str | Path], *, suffix: str = ".tmp", what: str = "",
                   error: type[PostureLabError] = PostureLabError) -> Iterator[list[Path]]:
    """Write several files all or none: a temporary file beside each of ``paths``.

    The temporaries are created on entry, so that an unwritable place fails before any work,
    with the mode a new file gets; the block writes them (by path); on a normal exit each is
    renamed over its path in turn; on any exception (Ctrl-C too) all are removed.

    Parameters
    ----------
    paths : sequence of path
        The outputs.
    suffix : str
        The temporaries' suffix (a writer that looks at it, such as matplotlib's or Pillow's,
        gets the right format).
    what : str
        Words before the path in a message (``"--out "``).
    error : type
        The PostureLabError raised, in one line naming the file.

    Yields
    ------
    list of Path
        The temporary files, in the order of ``paths``.
    """
    temporaries: list[tuple[Path, Path]] = []

    def fail(path: Path, exc: OSError) -> PostureLabError:
        return error(f"cannot write {what}{str(path)!r}: {exc.strerror or exc}")

    try:
        for given in paths:
            if str(given).endswith(tuple(filter(None, ("/", os.sep, os.altsep)))):
                raise error(f"cannot write {what}{str(given)!r}: a file name cannot end in "
                            f"{str(given)[-1]!r} (a directory's separator)")
        for path in map(Path, paths):
            refuse_non_regular(path, error)
            directory = path.parent if str(path.parent) else Path(".")
            if not directory.is_dir():
                raise error(f"cannot write {what}{str(path)!r}: directory {str(directory)!r} "
                            "does not exist")
            try:
                fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix,
                                            dir=directory)
            except OSError as exc:
                raise fail(path, exc) from None
            temporaries.append((Path(name), path))
            try:
                os.fchmod(fd, new_file_mode())
            finally:
                os.close(fd)
        yield [tmp for tmp, _ in temporaries]
        while temporaries:
            tmp, path = temporaries[0]
            try:
                os.replace(tmp, path)
            except OSError as exc:
                raise fail(path, exc) from None
            temporaries.pop(0)
    except OSError as exc:  # (raised by the block while writing a temporary)
        where = next((path for tmp, path in temporaries if exc.filename in (str(tmp), tmp)),
                     temporaries[0][1] if temporaries else Path(paths[0]))
        raise fail(where, exc) from None
    finally:
        for tmp, _ in temporaries:
            _unlink_quietly(tmp)


def atomic_write_files(contents: Mapping[str | Path, bytes]) -> None:
    """Write several files so that a failure leaves none of them written: each goes to a
    temporary file beside it, and only when all are written are they renamed in turn."""
    with atomic_outputs(list(contents)) as temporaries:
        for tmp, data in zip(temporaries, contents.values(), strict=True):
            with open(tmp, "wb") as fh:
                fh.write(data)


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and a rename."""
    atomic_write_files({path: data})


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` through a temporary file and a rename."""
    atomic_write_files({path: text.encode("utf-8")})


#: Rows a table is written in, at a time (bounds the text held in memory). [-]
CSV_CHUNK_ROWS = 20_000


def check_output_rows(rows: int, what: str, fix: str) -> None:
    """Refuse a table of more than :data:`MAX_DATA_ROWS` rows (posturelab could not read it
    back), in one line naming ``what`` and the ``fix``."""
    if rows > MAX_DATA_ROWS:
        raise ParameterError(f"{what} would be {rows:,} rows; at most {MAX_DATA_ROWS:,} are "
                             f"written (the most posturelab reads back): {fix}")


def atomic_write_csv(path: str | Path, header: Sequence[str], columns: Sequence,
                     cell=None, *, fix: str = "write fewer rows") -> None:
    """Write a table as CSV, atomically, a block of :data:`CSV_CHUNK_ROWS` rows at a time
    (memory bounded by the columns, not by their text), refusing a file posturelab could not
    read back: more than :data:`MAX_DATA_ROWS` rows or :data:`MAX_INPUT_BYTES` bytes.

    Parameters
    ----------
    path : path
    header : sequence of str
        The column names (with their units, if any).
    columns : sequence of numpy.ndarray, shape (S,)
        The values, one array per column (numbers, or booleans written true/false).
    cell : callable, optional
        A number to its text (default: 17 significant digits, exact; NaN an empty cell).
    fix : str
        What to do instead, in the refusal.

    Raises
    ------
    ParameterError
        Too many rows or bytes (nothing written).
    """
    import numpy as np

    if cell is None:
        def cell(v: float) -> str:
            return "" if v != v else repr(v)
    arrays = [np.asarray(c) for c in columns]
    rows = len(arrays[0]) if arrays else 0
    check_output_rows(rows, f"--out {str(path)!r}", fix)
    written = 0
    with atomic_outputs([path], what="--out ", error=ParameterError) as (tmp,):
        with open(tmp, "wb") as fh:
            head = (",".join(header) + "\n").encode("utf-8")
            fh.write(head)
            written += len(head)
            for a in range(0, rows, CSV_CHUNK_ROWS):
                texts = []
                for c in arrays:
                    block = c[a:a + CSV_CHUNK_ROWS]
                    if block.dtype == bool:
                        texts.append(["true" if v else "false" for v in block.tolist()])
                    else:
                        texts.append([cell(v) for v in block.astype(float).tolist()])
                data = "".join(",".join(r) + "\n" for r in zip(*texts, strict=True)
                               ).encode("utf-8")
                written += len(data)
                if written > MAX_INPUT_BYTES:
                    raise ParameterError(
                        f"--out {str(path)!r} would be more than {MAX_INPUT_BYTES // 2**20} MiB "
                        f"({rows:,} rows × {len(arrays)} columns; the most posturelab reads "
                        f"back): {fix}")
                fh.write(data)
