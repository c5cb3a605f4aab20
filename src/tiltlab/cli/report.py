"""``tiltlab report``: chosen chapters of the book, executed on your data, as HTML."""

from __future__ import annotations

import argparse
import json
import re
from typing import Any

from ._common import EXIT_ERROR, EXIT_OK, UserError

_DESCRIPTION = """\
Execute chapters of the book on SOURCE, a recording (a NetCDF Recording written by
'tiltlab convert', a BROAD-layout .hdf5/.mat file, or broad:N, fayat:example) or a cohort
manifest (.csv, see 'tiltlab cohort init'), and render them as HTML in --out with the
book's look: open OUT/index.html. The index page lists, per chapter, whether it ran, how
long it took and what it skipped and why; a chapter that fails shows its error and the
others still run. Exit status 0 if no chapter failed, 1 if any did (or the pages could not
be rendered), 2 on a usage error."""

_EPILOG = """\
Which parameter receives SOURCE: a recording goes to SOURCE (chapters 1, 2, 3, 5, 6, 7;
also HEADING_SOURCE in 6 and HEAD_SOURCE in 7) and RAT_SOURCE (chapter 4); a manifest
goes to COHORT_MANIFEST (chapter 8). A chapter given the other kind is listed as not run,
with the reason; with a manifest, --recording FILE runs the recording chapters too.

Shrink a run with -p (each chapter's parameters cell lists its names), e.g.
  tiltlab report tag.nc --chapters 6 --out report -p N_LATTICE=2000 -p N_BOOT=100
  tiltlab report manifest.csv --chapters 8 --out report -p N_SIM_POWER=100 \\
      -p 'POWER_N=[3, 4, 6]' -p MAP_ANIMALS=2
Chapters run in their own folder: relative paths to existing files in -p values are
made absolute; give other paths absolute.

The chapters are the notebooks/ folder of a tiltlab checkout: --book DIR, else
TILTLAB_BOOK_DIR, else the checkout this package was installed from (pip install -e)."""


def _param(text: str) -> tuple[str, Any]:
    """Parse ``NAME=VALUE`` (an argparse type), the value as JSON, else a string."""
    name, sep, raw = text.partition("=")
    name = name.strip()
    if not sep or not re.fullmatch(r"[A-Za-z_]\w*", name):
        raise argparse.ArgumentTypeError(
            f"{text!r}: give NAME=VALUE, e.g. N_BOOT=100 or 'POWER_N=[3, 4]'"
        )
    try:
        value = json.loads(raw)
    except json.JSONDecodeError:
        value = raw  # a plain string: broad:3, left ...
    return name, value


def _add_report(sub) -> None:
    """Add the ``report`` subcommand's parser."""
    p = sub.add_parser(
        "report",
        help="run chapters of the book on your recording or cohort, as HTML",
        description=_DESCRIPTION,
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "source",
        metavar="SOURCE_OR_MANIFEST",
        help="a recording (.nc, .hdf5, .mat, broad:N ...) or a cohort manifest (.csv)",
    )
    p.add_argument(
        "--chapters",
        default="all",
        help="chapter numbers, e.g. 4,6,8 or 6-8 (default: all)",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="folder of the report")
    p.add_argument(
        "-p",
        "--param",
        dest="params",
        action="append",
        type=_param,
        default=[],
        metavar="NAME=VALUE",
        help="a chapter parameter (value parsed as JSON), for every chosen chapter "
        "that has it; repeatable",
    )
    p.add_argument(
        "--recording",
        metavar="FILE",
        help="with a manifest: a recording for the chapters that analyse one",
    )
    p.add_argument(
        "--book",
        metavar="DIR",
        help="the chapters' folder (a checkout's notebooks/; default TILTLAB_BOOK_DIR, "
        "else the checkout tiltlab was installed from)",
    )
    p.add_argument(
        "--no-render",
        action="store_true",
        help="only execute the chapters (notebooks and index.md, no HTML)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bars")


def _cmd_report(args: argparse.Namespace) -> int:
    from ..report import ReportError, run_report

    try:
        result = run_report(
            args.source,
            args.chapters,
            args.out,
            params=dict(args.params),
            book_dir=args.book,
            recording_path=args.recording,
            render=not args.no_render,
            progress=not args.no_progress,
        )
    except ReportError as exc:
        raise UserError(str(exc)) from None
    width = max(len(c.name) for c in result.chapters)
    for c in result.chapters:
        if c.status == "not run":
            line = f"not run: {c.reason}"
        else:
            line = f"{c.status} in {c.seconds:.0f} s"
            if c.skipped:
                line += f", {len(c.skipped)} skipped line(s)"
            if c.status == "failed":
                line += f": {c.reason}"
        print(f"{c.name:<{width}}  {line}")
    where = result.index if result.index is not None else result.out / "index.md"
    print(f"wrote {where}")
    return EXIT_ERROR if result.failed else EXIT_OK
