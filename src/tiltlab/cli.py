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
import json
import os
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["main", "run"]

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
    from . import datasets, schema

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
    """A Recording from a data-source string, or from a CSV with a mapping.

    A refusal of the unit check names ``--no-check-units``."""
    from . import datasets, io
    from .quality import UnitCheckError

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
    """The content of a JSON file; a missing file or bad JSON is a :class:`UserError`."""
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
    """An argparse type: an integer >= 1, checked by :mod:`tiltlab._validate`."""
    from . import _validate

    def parse(text: str) -> int:
        try:
            return _validate.integer(text, option, minimum=1)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    return parse


# --------------------------------------------------------------------------- commands


def _cmd_fetch(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    from . import datasets

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
    """Collect the warnings of tiltlab (quality warnings and any other warning raised in
    the package) while the block runs, and hand each distinct message, in order, to
    ``emit`` when it ends — also when it ends by an error. Other warnings (libraries')
    are shown as usual."""
    package = str(Path(__file__).resolve().parent)
    lines: list[str] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield lines
    finally:
        from .quality import QualityWarning

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
    """What a file source looks like (:func:`tiltlab.io.detect`), None for names."""
    from . import io

    if not Path(source).is_file():
        return None
    try:
        return io.detect(source)
    except OSError:
        return None


def _cmd_info(args: argparse.Namespace) -> int:
    from . import schema

    what = None if args.mapping else _looks_like(args.source)
    with _quality_lines(lambda t: print(f"tiltlab: warning: {t}", file=sys.stderr)):
        rec = _load(args.source, args.mapping, cmd="info", check_units=args.check_units)
    if what is not None:
        print(f"{'file':>14}: {what}")
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
    from . import io, schema
    from .quality import UnitCheckError

    what = None
    if args.mapping is None and Path(args.source).suffix.lower() not in _CSV_SUFFIXES:
        what = _looks_like(args.source)
    if what is not None and not what.startswith(("tiltlab Recording", "BROAD")):
        # a file read by conversion is not a Recording file: say what it is
        raise io.NotRecordingError(args.source, what)
    # quality warnings are part of the report (stdout), one line each; they do not
    # change the exit status, errors do (one line on stderr, from main)
    with _quality_lines(lambda t: print(f"warning: {t}")) as lines:
        rec = _load(
            args.source, args.mapping, cmd="validate", check_units=args.check_units
        )
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
    from . import io, schema

    out = Path(args.out)
    if out.is_dir():
        raise UserError(f"--out {out} is a folder; give a file such as session.nc")
    if out.suffix.lower() not in (".nc", ".nc4", ".netcdf"):
        raise UserError(f"--out {out}: a Recording is written as NetCDF; end it in .nc")
    if out.exists() and not args.force:
        raise UserError(f"{out} exists; give another --out, or --force to replace it")
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


def _cmd_cohort_init(args: argparse.Namespace) -> int:
    from . import cohort

    folder = Path(args.folder)
    if not folder.is_dir():
        raise UserError(f"{folder}: no such folder")
    out = Path(args.out)
    if out.exists() and not args.force:
        raise UserError(f"{out} exists; give another --out, or --force to replace it")
    options = None
    if args.reader_options is not None:
        text = args.reader_options.strip()
        if text.startswith("{"):
            try:
                options = json.loads(text)
            except json.JSONDecodeError as exc:
                raise UserError(
                    f"--reader-options is not valid JSON (column {exc.colno}: {exc.msg})"
                ) from None
        else:
            options = _read_json(text, "reader options")
        if not isinstance(options, dict):
            raise UserError("--reader-options must be a JSON object")
    manifest = cohort.init_manifest(
        folder,
        args.pattern,
        reader=args.reader,
        group=args.group,
        reader_options=options,
        out=out,
    )
    table = manifest.table
    groups = ", ".join(
        f"{g} ({n})" for g, n in table["group"].value_counts(sort=False).items()
    )
    print(
        f"wrote {out}: {len(table)} session(s) of {table['subject'].nunique()} "
        f"subject(s); groups: {groups}"
    )
    return EXIT_OK


def _cohort_inputs(args: argparse.Namespace):
    """Manifest and feature configuration of ``cohort run``: a problem exits 2."""
    from . import cohort

    try:
        manifest = cohort.read_manifest(args.manifest)
        if args.config is None:
            config = cohort.FeatureConfig()
        else:
            raw = _read_json(args.config, "config")
            if not isinstance(raw, dict):
                raise UserError(
                    f"{args.config}: a config is a JSON object, got a JSON "
                    f"{type(raw).__name__}",
                    EXIT_REJECTED,
                )
            config = cohort.FeatureConfig.from_dict(raw)
    except UserError:
        raise
    except _user_errors() as exc:
        where = (
            f"{args.config}: " if args.config and "FeatureConfig" in str(exc) else ""
        )
        raise UserError(where + _message(exc), EXIT_REJECTED) from None
    return manifest, config


def _without_unit_check(manifest):
    """The manifest with ``"check_units": false`` in every row's reader_options."""
    import dataclasses

    table = manifest.table.copy()
    rows = []
    for text in table.get("reader_options", [""] * len(table)):
        opts = json.loads(text) if str(text or "").strip() else {}
        opts["check_units"] = False
        rows.append(json.dumps(opts, sort_keys=True))
    table["reader_options"] = rows
    return dataclasses.replace(manifest, table=table)


def _scheduler(text: str) -> str:
    """An argparse type for ``--scheduler``: ``dask``, ``processes`` or an address."""
    if text in ("dask", "processes") or "://" in text:
        return text
    raise argparse.ArgumentTypeError(
        f"expected 'dask', 'processes' or a scheduler address such as "
        f"tcp://host:8786, got {text!r}"
    )


def _cmd_cohort_run(args: argparse.Namespace) -> int:
    from . import cohort

    manifest, config = _cohort_inputs(args)
    if not args.check_units:
        manifest = _without_unit_check(manifest)
    out = Path(args.out)
    if out.is_dir():
        raise UserError(
            f"--out {out} is a folder; give a file such as features.nc", EXIT_REJECTED
        )
    # run_cohort prints the summary itself (on stderr) when it shows progress
    features = cohort.run_cohort(
        manifest,
        config,
        scheduler=args.scheduler,
        workers=args.workers,
        cache_dir=args.cache_dir,
        progress=not args.no_progress,
        out=out,
    )
    report = cohort.summary(features)
    print(report)
    print(f"features of {report.n_sessions} session(s) written to {out}")
    if report.n_failed:
        failed = list(report.failures)
        listed = ", ".join(failed[:10]) + (", ..." if len(failed) > 10 else "")
        print(
            f"tiltlab: {report.n_failed} of {report.n_sessions} session(s) failed: "
            f"{listed} (their errors are listed above; features are NaN)",
            file=sys.stderr,
        )
        return EXIT_ERROR
    return EXIT_OK


#: Features shown first by ``cohort show`` (Fayat et al. 2021's main outcomes).
MAIN_FEATURES = (
    "immobile_fraction",
    "visited_fraction",
    "tilt_immobile_sagittal_deg",
    "tilt_immobile_kappa",
    "circling_index",
    "angular_speed_moving_q50",
    "dba_mean",
    "tilted_fraction_20deg",
)


def _feature_table(features, max_features: int | None):
    """Sessions × (labels, status, main features) as a DataFrame; units of the shown
    features; names of the features left out."""
    import pandas as pd

    labels = [
        c
        for c in ("subject", "group", "timepoint")
        if c in features.variables and features[c].dims == ("session",)
    ]
    numeric = [
        str(v)
        for v in features.data_vars
        if features[v].dims == ("session",) and features[v].dtype.kind in "fiu"
    ]
    ordered = [v for v in MAIN_FEATURES if v in numeric] + [
        v for v in numeric if v not in MAIN_FEATURES
    ]
    shown = ordered if max_features is None else ordered[:max_features]
    table = pd.DataFrame(
        index=pd.Index(features["session"].values.astype(str), name="session")
    )
    for c in labels:
        table[c] = features[c].values.astype(str)
    if "status" in features:
        table["status"] = features["status"].values.astype(str)
    for v in shown:
        table[v] = features[v].values
    units = {v: features[v].attrs.get("units", "") for v in shown}
    return table, units, ordered[len(shown) :]


def _cmd_cohort_show(args: argparse.Namespace) -> int:
    from . import cohort

    path = Path(args.features)
    if not path.is_file():
        raise UserError(f"{path}: no such file")
    features = cohort.load_features(path)
    table, units, hidden = _feature_table(
        features, None if args.all else args.max_features
    )
    print(
        table.to_string(
            float_format=lambda x: f"{x:.4g}", na_rep="NaN", justify="right"
        )
    )
    with_units = [f"{v} [{u}]" for v, u in units.items() if u and u != "1"]
    if with_units:
        print(f"\nunits: {', '.join(with_units)} (others dimensionless)")
    if hidden:
        print(f"{len(hidden)} more feature(s), shown with --all: {', '.join(hidden)}")
    if "status" in features:
        print(f"\n{cohort.summary(features)}")
    config = _config_of(features)
    if config is not None:
        digest = features.attrs.get("config_hash", "")
        print(f"\nconfig{f' (hash {digest[:12]})' if digest else ''}:")
        width = max(len(k) for k in config)
        for k in sorted(config):
            print(f"  {k:<{width}} = {json.dumps(config[k])}")
    return EXIT_OK


def _config_of(features) -> dict | None:
    """The feature configuration stored in a feature table's attrs, if any."""
    for key in ("feature_config", "config"):
        value = features.attrs.get(key)
        if isinstance(value, str):
            try:
                return json.loads(value)
            except json.JSONDecodeError:
                return {key: value}
        if isinstance(value, dict):
            return value
    return None


# --------------------------------------------------------------------------- parser


def _add_check_units(p: argparse.ArgumentParser, where: str = "") -> None:
    p.add_argument(
        "--no-check-units",
        dest="check_units",
        action="store_false",
        help="accept the unit labels as they are, even where the values contradict "
        "them (the unit check refuses, e.g., m/s² values labelled g)" + where,
    )


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
    p_conv.add_argument("--out", required=True, help="Recording to write (.nc)")
    p_conv.add_argument(
        "--preset",
        metavar="NAME",
        help="device axes convention (android, ios, tagtools, animal ...), for sources "
        "whose axes are not in the sensor frame yet",
    )
    p_conv.add_argument(
        "--force", action="store_true", help="replace an existing --out file"
    )
    _add_check_units(p_conv)

    p_cohort = sub.add_parser("cohort", help="cohort manifests and features")
    csub = p_cohort.add_subparsers(dest="cohort_cmd", required=True, metavar="COMMAND")
    p_init = csub.add_parser(
        "init",
        help="write a manifest from the files of a folder",
        description="Write a cohort manifest (one row per session) from the files of "
        "FOLDER whose relative paths match PATTERN.",
    )
    p_init.add_argument("folder", metavar="FOLDER")
    p_init.add_argument(
        "--pattern",
        required=True,
        help='relative path with fields, e.g. "{group}/{subject}_{timepoint}.nc"',
    )
    p_init.add_argument("--reader", default="netcdf", help="reader (default netcdf)")
    p_init.add_argument(
        "--group", help="group of every session when the pattern has no {group}"
    )
    p_init.add_argument(
        "--out",
        default="manifest.csv",
        help="manifest to write (default manifest.csv); file paths in it are "
        "relative to its folder",
    )
    p_init.add_argument(
        "--reader-options",
        metavar="JSON|FILE.json",
        help="reader options for every session, as JSON text or a JSON file; for "
        "--reader csv, the column/unit mapping (see 'tiltlab info --help')",
    )
    p_init.add_argument(
        "--force", action="store_true", help="replace an existing manifest"
    )

    p_run = csub.add_parser(
        "run",
        help="compute the features of every session of a manifest",
        description="Compute per-session features for a manifest and write them. Exit "
        "status 0 if every session succeeded, 1 if any failed (listed on stderr), 2 if "
        "the manifest or config is rejected.",
    )
    p_run.add_argument("manifest", metavar="MANIFEST")
    p_run.add_argument("--out", required=True, help="feature file to write (.nc)")
    p_run.add_argument(
        "--workers",
        type=_positive_int("--workers"),
        help="worker processes (default: automatic)",
    )
    p_run.add_argument(
        "--scheduler",
        type=_scheduler,
        metavar="ADDRESS|dask|processes",
        help="'processes' (local pool), 'dask' (local dask.distributed cluster) or the "
        "address of a running dask scheduler (tcp://host:8786); default serial",
    )
    p_run.add_argument("--config", metavar="CONFIG.json", help="feature configuration")
    p_run.add_argument("--cache-dir", metavar="DIR", help="per-session feature cache")
    p_run.add_argument("--no-progress", action="store_true", help="no progress bar")
    _add_check_units(
        p_run,
        ' for every session (in a manifest row: reader_options {"check_units": false})',
    )

    p_show = csub.add_parser(
        "show",
        help="print a feature file as a table, with its config",
    )
    p_show.add_argument("features", metavar="FEATURES.nc")
    p_show.add_argument(
        "--max-features",
        type=_positive_int("--max-features"),
        default=len(MAIN_FEATURES),
        help=f"features shown as columns (default {len(MAIN_FEATURES)}: the main ones)",
    )
    p_show.add_argument("--all", action="store_true", help="every feature")
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
    try:
        if args.cmd == "fetch":
            return _cmd_fetch(args, parser)
        if args.cmd == "info":
            return _cmd_info(args)
        if args.cmd == "validate":
            return _cmd_validate(args)
        if args.cmd == "convert":
            return _cmd_convert(args)
        if args.cmd == "cohort":
            return {
                "init": _cmd_cohort_init,
                "run": _cmd_cohort_run,
                "show": _cmd_cohort_show,
            }[args.cohort_cmd](args)
    except UserError as exc:
        if debug:
            raise
        print(f"tiltlab: {exc}", file=sys.stderr)
        return exc.code
    except KeyboardInterrupt:
        print("tiltlab: interrupted", file=sys.stderr)
        return 130
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


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())


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
