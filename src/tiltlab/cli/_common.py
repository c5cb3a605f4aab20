"""Share the command line's exit statuses, user error, source loading and options.

Shared pieces of the command line: exit statuses, the one-line user error, loading a
source and reading options.
"""

from __future__ import annotations

import argparse
import contextlib
import json
from pathlib import Path
from typing import Any

#: Exit statuses.
EXIT_OK, EXIT_ERROR, EXIT_REJECTED = 0, 1, 2

_CSV_SUFFIXES = (".csv", ".tsv", ".txt")

_MAPPING_HELP = """\
A mapping is a JSON file telling tiltlab which columns hold what, in which units:

  {
    "columns": {"acc": ["AccX", "AccY", "AccZ"], "gyr": ["GyrX", "GyrY", "GyrZ"],
                "temp": "T"},
    "units": {"acc": "g", "gyr": "deg/s", "temp": "degC"},
    "time_column": "t_ms", "time_units": "ms",
    "preset": "android",
    "sep": ";"
  }

"columns" and "units" are required; "acc" is the only required variable ("gyr",
"mag", "temp", "q_ref" are optional: accelerometer-only tags are fine). Give "fs" (Hz)
or a "time_column" (its unit "s", "ms" or "us" in "time_units"; "clock": "resample"
puts an irregular clock on a regular grid). "axes" (e.g. ["x", "-y", "z"], or per
variable) or "preset" (android, ios, tagtools, animal ...) map the device's axes into
the sensor frame; "check_units": false accepts the unit labels as they are (the same as
--no-check-units). With "files" instead of "columns", each sensor comes from its own
file (one file per sensor, e.g. MATLAB .mat matrices), read by tiltlab.io.read_multi;
their paths are relative to the mapping's folder. Any other key is a pandas.read_csv
option (sep, decimal, skiprows, comment, encoding ...).

Files tiltlab reads without a mapping: NetCDF Recordings, tag-tools (animaltags)
NetCDF archives (NetCDF-4 or -3), BROAD trials (.hdf5, .mat)."""

_NO_MAPPING = (
    "don't know how to read {source!r} without a column mapping: give "
    "--mapping mapping.json, a JSON file such as "
    '{{"columns": {{"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]}}, '
    '"units": {{"acc": "g", "gyr": "deg/s"}}, "fs": 100}} '
    "(see 'tiltlab {cmd} --help')"
)


class UserError(Exception):
    """An error to report as one line, with the exit status to return."""

    def __init__(self, message: str, code: int = EXIT_ERROR):
        super().__init__(message)
        self.code = code


# --------------------------------------------------------------------------- helpers


def _user_errors() -> tuple[type[BaseException], ...]:
    """Exception types that are the user's to fix (reported, not raised)."""
    from .. import datasets, schema

    return (
        datasets.DataError,
        schema.RecordingError,
        ValueError,  # includes UnitsError, json.JSONDecodeError and validation errors
        OSError,  # includes io.ReadError, FileNotFoundError, PermissionError
        KeyError,
        TypeError,
    )


def _message(exc: BaseException) -> str:
    """One line for an exception: its message, or its type when it has none."""
    text = str(exc.args[0]) if isinstance(exc, KeyError) and exc.args else str(exc)
    text = " ".join(text.split())
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        text = f"{exc.filename}: {exc.strerror}"
    if isinstance(exc, (KeyError, TypeError)) or not text:
        text = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
    return text


def _load(
    source: str,
    mapping: str | None = None,
    *,
    cmd: str = "info",
    check_units: bool = True,
    **options: Any,
):
    """Load a Recording from a data-source string, or from a CSV with a mapping.

    A refusal of the unit check names ``--no-check-units``.
    """
    from .. import datasets, io
    from ..quality import UnitCheckError

    opts = dict(options)
    if not check_units:
        opts["check_units"] = False
    try:
        if mapping is not None:
            if not Path(mapping).is_file():
                raise UserError(f"{mapping}: no such mapping file")
            return io.read(source, mapping=mapping, **opts)
        if Path(source).suffix.lower() in _CSV_SUFFIXES:
            raise UserError(_NO_MAPPING.format(source=source, cmd=cmd))
        try:
            return datasets.load(source, **opts)
        except datasets.DataError as exc:
            if str(exc).startswith("don't know how to read"):
                what = ""
                if Path(source).is_file():
                    with contextlib.suppress(OSError):
                        what = f" (it looks like: {io.detect(source)})"
                raise UserError(
                    f"{exc}{what}; for your own CSV give --mapping mapping.json "
                    f"(see 'tiltlab {cmd} --help')"
                ) from None
            raise
    except UnitCheckError as err:
        raise err.for_switch("cli") from None


def _read_json(path: str, what: str) -> Any:
    """Read a JSON file; a missing file or bad JSON is a :class:`UserError`."""
    p = Path(path)
    if not p.is_file():
        raise UserError(f"{path}: no such {what} file", EXIT_REJECTED)
    try:
        return json.loads(p.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        where = (
            f"line {exc.lineno}, column {exc.colno}: {exc.msg}"
            if isinstance(exc, json.JSONDecodeError)
            else str(exc)
        )
        raise UserError(
            f"{path}: {what} is not valid JSON ({where})", EXIT_REJECTED
        ) from None


def _positive_int(option: str):
    """Parse an integer >= 1 (an argparse type), checked by :mod:`tiltlab._validate`."""
    from .. import _validate

    def parse(text: str) -> int:
        try:
            return _validate.integer(text, option, minimum=1)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    return parse


# --------------------------------------------------------------------------- commands


def _add_check_units(p: argparse.ArgumentParser, where: str = "") -> None:
    p.add_argument(
        "--no-check-units",
        dest="check_units",
        action="store_false",
        help="accept the unit labels as they are, even where the values contradict "
        "them (the unit check refuses, e.g., m/s² values labelled g)" + where,
    )


def _add_out_force(p: argparse.ArgumentParser, what: str, **out: Any) -> None:
    """Add ``--out`` (with the keyword arguments ``out``) and ``--force``.

    ``--force`` replaces an existing ``what`` (see :func:`_writable`).
    """
    p.add_argument("--out", **out)
    p.add_argument("--force", action="store_true", help=f"replace an existing {what}")


def _writable(out: Path, force: bool) -> Path:
    """Return ``out``, refusing to replace an existing file without ``--force``."""
    if out.exists() and not force:
        raise UserError(f"{out} exists; give another --out, or --force to replace it")
    return out
