"""``tiltlab`` command line: inspect, validate, convert and fetch data; run cohorts.

Examples
--------
::

    tiltlab fetch --all                # download (or verify in the mirror) every registered file
    tiltlab info broad:2               # summary of BROAD trial 2
    tiltlab info deployment.nc         # what a file looks like (tag-tools NetCDF …) and its summary
    tiltlab validate session.nc        # check a saved Recording against the contract
    tiltlab info my_session.csv --mapping mapping.json   # your own CSV, with a column mapping
    tiltlab convert deployment.nc --out session.nc       # tag-tools NetCDF → Recording
    tiltlab convert my_session.csv --mapping mapping.json --out session.nc
    tiltlab convert board/ --mapping files.json --out session.nc  # one file per sensor
    tiltlab cohort init data/ --pattern "{group}/{subject}_{timepoint}.nc" --out manifest.csv
    tiltlab cohort run manifest.csv --out features.nc --workers 2
    tiltlab cohort show features.nc

Every user error (missing file, bad JSON, bad mapping, a Recording that breaks the
contract) is reported as one line ``tiltlab: ...`` on stderr with a non-zero exit
status, never as a traceback (set ``TILTLAB_DEBUG=1`` to see one). A file that is not
a tiltlab Recording (a tag-tools NetCDF, a MATLAB file …) is named for what it looks
like, with the command that converts it. Values that decisively contradict their unit
labels are refused; ``--no-check-units`` (on ``info``, ``validate``, ``convert`` and
``cohort run``) accepts the labels as they are — in a cohort manifest the same switch
is ``reader_options {"check_units": false}``. Quality warnings (clipped samples,
values doubtful for their units: :mod:`tiltlab.quality`) are printed by ``tiltlab
validate`` and ``tiltlab convert`` as lines ``warning: ...``, and leave the exit status 0.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Sequence

from ._common import (
    EXIT_ERROR,
    EXIT_REJECTED,
    UserError,
    _MAPPING_HELP,
    _add_check_units,
    _add_out_force,
    _message,
    _user_errors,
)
from .files import (
    _cmd_convert,
    _cmd_fetch,
    _cmd_info,
    _cmd_validate,
)
from .cohort import (
    _add_cohort,
    _cmd_cohort_init,
    _cmd_cohort_run,
    _cmd_cohort_show,
)
from .report import _add_report, _cmd_report

__all__ = ["main", "run"]


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tiltlab",
        description=__doc__.splitlines()[0],
        epilog="Set TILTLAB_DEBUG=1 to see tracebacks.",
    )
    sub = parser.add_subparsers(dest="cmd", required=True, metavar="COMMAND")
    p_fetch = sub.add_parser(
        "fetch", help="fetch registered data files (checksums verified)"
    )
    p_fetch.add_argument(
        "names",
        nargs="*",
        help="registry names, e.g. broad/02_undisturbed_slow_rotation_B.hdf5",
    )
    p_fetch.add_argument("--all", action="store_true", help="every registered file")
    for name, help_ in (
        ("info", "summarise a recording"),
        ("validate", "validate a recording against the contract"),
    ):
        p = sub.add_parser(
            name,
            help=help_,
            description=f"{help_[0].upper()}{help_[1:]}: broad:N, fayat:example, "
            "fayat:tumble, a .nc / .hdf5 / .mat file, or your own CSV with --mapping.",
            epilog=_MAPPING_HELP,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        p.add_argument("source", help="data source or file")
        p.add_argument(
            "--mapping",
            metavar="MAPPING.json",
            help="column/unit mapping (JSON) for a generic CSV file, or a multi-file "
            'mapping with "files"',
        )
        _add_check_units(p)
    p_conv = sub.add_parser(
        "convert",
        help="convert a file into a NetCDF Recording",
        description="Convert SOURCE into a validated NetCDF Recording (tiltlab.io.read "
        "then tiltlab.io.save_netcdf): a tag-tools NetCDF archive, a BROAD trial, a "
        "tiltlab NetCDF, your own CSV with --mapping, or one file per sensor with a "
        'mapping that has "files" (SOURCE is then the folder of those files). Prints '
        "one summary line, after any quality warnings ('warning: ...').",
        epilog=_MAPPING_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p_conv.add_argument("source", metavar="SOURCE", help="file (or folder) to convert")
    p_conv.add_argument(
        "--mapping", metavar="MAPPING.json", help="column/unit or multi-file mapping"
    )
    _add_out_force(p_conv, "--out file", required=True, help="Recording to write (.nc)")
    p_conv.add_argument(
        "--preset",
        metavar="NAME",
        help="device axes convention (android, ios, tagtools, animal ...), for sources "
        "whose axes are not in the sensor frame yet",
    )
    _add_check_units(p_conv)

    _add_cohort(sub)
    _add_report(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``tiltlab`` command.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0 success, 1 an error or a failed session, 2 a rejected input
        (usage, cohort manifest or config).
    """
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # usage errors and --help: argparse has printed them
        return exc.code if isinstance(exc.code, int) else EXIT_REJECTED
    debug = os.environ.get("TILTLAB_DEBUG", "") not in ("", "0")
    commands = {
        "fetch": lambda: _cmd_fetch(args, parser),
        "info": lambda: _cmd_info(args),
        "validate": lambda: _cmd_validate(args),
        "convert": lambda: _cmd_convert(args),
        "cohort": lambda: {
            "init": _cmd_cohort_init,
            "run": _cmd_cohort_run,
            "show": _cmd_cohort_show,
        }[args.cohort_cmd](args),
        "report": lambda: _cmd_report(args),
    }
    try:
        if args.cmd in commands:
            status = commands[args.cmd]()
            sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
            return status
    except UserError as exc:
        if debug:
            raise
        print(f"tiltlab: {exc}", file=sys.stderr)
        return exc.code
    except KeyboardInterrupt:
        print("tiltlab: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader closed the pipe (`tiltlab cohort show f.nc | head`): stop quietly,
        # and keep Python from complaining when it flushes stdout at exit
        with contextlib.suppress(OSError, ValueError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except Exception as exc:
        if debug:
            raise
        if isinstance(exc, _user_errors()):
            print(f"tiltlab: {_message(exc)}", file=sys.stderr)
        else:  # not expected: still one line, the traceback on request
            print(
                f"tiltlab: unexpected error ({type(exc).__name__}: {_message(exc)}); "
                "set TILTLAB_DEBUG=1 to see the traceback",
                file=sys.stderr,
            )
        return EXIT_ERROR
    parser.error(f"unknown command {args.cmd!r}")  # pragma: no cover
    return EXIT_REJECTED  # pragma: no cover


def run(command: str) -> int:
    """Run one ``tiltlab`` command line from Python (a notebook), as a shell would.

    The line is echoed as ``$ tiltlab ...``; what the command writes to stderr (its
    one-line errors and ``warning:`` lines) is shown with its output.

    Parameters
    ----------
    command : str
        The arguments, e.g. ``"convert tag.csv --mapping tag.json --out tag.nc"``.

    Returns
    -------
    int
        The exit status (see :func:`main`).

    Examples
    --------
    >>> from tiltlab import cli
    >>> cli.run("info broad:2 --help")  # doctest: +SKIP
    """
    import shlex

    print(f"$ tiltlab {command}")
    with contextlib.redirect_stderr(sys.stdout):
        status = main(shlex.split(command))
    if status:
        print(f"(exit status {status})")
    return status
