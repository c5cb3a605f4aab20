"""``tiltlab fetch``, ``info``, ``validate`` and ``convert``: files in and out."""

from __future__ import annotations

import argparse
import contextlib
import sys
import warnings
from pathlib import Path
from typing import Any

from ._common import (
    EXIT_OK,
    UserError,
    _CSV_SUFFIXES,
    _load,
    _writable,
)


def _cmd_fetch(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    from .. import datasets

    names = list(datasets.registry()) if args.all else args.names
    if not names:
        parser.error("give file names or --all")
    from tqdm import tqdm

    known = datasets.registry()
    unknown = [n for n in names if n not in known]
    if unknown:
        raise datasets.DataError(f"{unknown[0]!r} is not in the tiltlab data registry")
    for name in tqdm(names, desc="fetching", unit="file"):
        datasets.fetch(name)
    print(f"{len(names)} file(s) present and verified")
    return EXIT_OK


@contextlib.contextmanager
def _quality_lines(emit):
    """Collect tiltlab's warnings while the block runs and emit each once at its end.

    Collect the warnings of tiltlab (quality warnings and any other warning raised in
    the package) while the block runs, and hand each distinct message, in order, to
    ``emit`` when it ends — also when it ends by an error. Other warnings (libraries')
    are shown as usual.
    """
    package = str(Path(__file__).resolve().parent)
    lines: list[str] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield lines
    finally:
        from ..quality import QualityWarning

        for w in caught:
            mine = issubclass(w.category, QualityWarning) or str(
                Path(w.filename).resolve()
            ).startswith(package)
            if not mine:
                warnings.showwarning(w.message, w.category, w.filename, w.lineno)
                continue
            text = " ".join(str(w.message).split())
            if text not in lines:
                lines.append(text)
        for text in lines:
            emit(text)


def _looks_like(source: str) -> str | None:
    """Say what a file source looks like (:func:`tiltlab.io.detect`), None for names."""
    from .. import io

    if not Path(source).is_file():
        return None
    try:
        return io.detect(source)
    except OSError:
        return None


_NO_CHECKSUM = (
    "{source}: no checksum stored (written before tiltlab stored checksums, or by "
    "another tool): its values cannot be checked for corruption; 'tiltlab convert "
    "{source} --out NEW.nc' writes a copy with checksums"
)


def _checksums(source: str, what: str | None) -> str | None:
    """Say what a tiltlab NetCDF Recording's checksums say, None for other sources.

    For a tiltlab NetCDF Recording, what its checksums say: ``"verified (…)"`` or
    ``"none stored"``; None for any other source.

    Called once the file has loaded, which verified the checksums it holds (a
    mismatch has been raised as an :class:`~tiltlab.io.IntegrityError`).
    """
    from .. import io

    if what is None or not what.startswith("tiltlab Recording"):
        return None
    sums = io.netcdf_checksums(source)
    if sums is None:
        return "none stored"
    return f"verified (sha256 of {len(sums['variables'])} variables and the attributes)"


def _cmd_info(args: argparse.Namespace) -> int:
    from .. import schema

    what = None if args.mapping else _looks_like(args.source)
    with _quality_lines(lambda t: print(f"tiltlab: warning: {t}", file=sys.stderr)):
        rec = _load(args.source, args.mapping, cmd="info", check_units=args.check_units)
    if what is not None:
        print(f"{'file':>14}: {what}")
    sums = _checksums(args.source, what)
    if sums is not None:
        print(f"{'checksums':>14}: {sums}")
    for k, v in schema.describe(rec).items():
        print(f"{k:>14}: {float(f'{v:.7g}') if isinstance(v, float) else v}")
    if "fs_source" in rec.attrs:
        print(f"{'fs_source':>14}: {rec.attrs['fs_source']}")
    if what is not None and not what.startswith("tiltlab Recording"):
        print(
            f"{'convert':>14}: tiltlab convert {args.source} --out session.nc"
            + (" --no-check-units" if not args.check_units else "")
        )
    return EXIT_OK


def _cmd_validate(args: argparse.Namespace) -> int:
    from .. import io, schema
    from ..quality import UnitCheckError

    what = None
    if args.mapping is None and Path(args.source).suffix.lower() not in _CSV_SUFFIXES:
        what = _looks_like(args.source)
    if what is not None and not what.startswith(("tiltlab Recording", "BROAD")):
        # a file read by conversion is not a Recording file: say what it is
        raise io.NotRecordingError(args.source, what)
    # quality warnings are part of the report (stdout), one line each; they do not
    # change the exit status, errors do (one line on stderr, from main). A saved
    # Recording's checksums are verified as it loads: a mismatch is an error naming
    # the variable; a file without checksums (written before tiltlab stored them)
    # is valid, with a warning saying so.
    with _quality_lines(lambda t: print(f"warning: {t}")) as lines:
        rec = _load(
            args.source, args.mapping, cmd="validate", check_units=args.check_units
        )
        if _checksums(args.source, what) == "none stored":
            warnings.warn(_NO_CHECKSUM.format(source=args.source), stacklevel=1)
        try:
            schema.validate(rec, allow_nan=True, check_units=args.check_units)
        except UnitCheckError as err:
            raise err.for_switch("cli") from None
    n = len(lines)
    print(
        f"{args.source}: valid Recording"
        + (f" ({n} warning{'s' if n > 1 else ''})" if n else "")
    )
    return EXIT_OK


def _cmd_convert(args: argparse.Namespace) -> int:
    from .. import io, schema

    out = Path(args.out)
    if out.is_dir():
        raise UserError(f"--out {out} is a folder; give a file such as session.nc")
    if out.suffix.lower() not in (".nc", ".nc4", ".netcdf"):
        raise UserError(f"--out {out}: a Recording is written as NetCDF; end it in .nc")
    _writable(out, args.force)
    src = Path(args.source)
    if src.resolve() == out.resolve():
        raise UserError(f"--out {out} is the source itself; give another file")
    what = None if args.mapping else _looks_like(args.source)
    options: dict[str, Any] = {}
    if args.preset is not None:
        options["preset"] = args.preset
    with _quality_lines(lambda t: print(f"warning: {t}")):
        rec = _load(
            args.source,
            args.mapping,
            cmd="convert",
            check_units=args.check_units,
            **options,
        )
    io.save_netcdf(rec, out)
    d = schema.describe(rec)
    variables = ", ".join(str(v) for v in rec.data_vars)
    print(
        f"wrote {out}: {rec.sizes['time']} samples at {rec.attrs['fs']:g} Hz "
        f"({d['duration_s']:g} s; {variables})" + (f" from a {what}" if what else "")
    )
    return EXIT_OK
