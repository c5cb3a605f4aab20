"""``tiltlab cohort init``, ``run`` and ``show``, and their parser (:func:`_add_cohort`).

What these commands print goes through :func:`_emit`: once the reader of a pipe has
gone (``tiltlab cohort show FEATURES.nc | head -1``) the rest of the output is dropped
quietly, with no ``BrokenPipeError``, and the command still does its work (an
``--export`` file is written).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import sys
from pathlib import Path

from ._common import (
    EXIT_ERROR,
    EXIT_OK,
    EXIT_REJECTED,
    UserError,
    _add_check_units,
    _add_out_force,
    _message,
    _positive_int,
    _read_json,
    _user_errors,
    _writable,
)


# --------------------------------------------------------------------------- output


def _drop_stdout() -> None:
    """Send the rest of stdout to the null device (its reader has gone)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(devnull, sys.stdout.fileno())
        finally:
            os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout is not a file descriptor
        sys.stdout = open(os.devnull, "w", encoding="utf-8")


def _emit(*lines: str) -> None:
    """Print ``lines`` on stdout; quiet once the reader of a pipe has gone."""
    try:
        for line in lines:
            print(line)
    except BrokenPipeError:
        _drop_stdout()


def _flush() -> None:
    """Flush stdout at the end of a command (a closed pipe is not an error)."""
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _drop_stdout()


#: the first line of :class:`tiltlab.cohort.CohortSummary`
_SUMMARY_HEAD = re.compile(r"\d+ sessions: \d+ ok, \d+ failed")


class _WithoutRunSummary:
    """Pass stderr through during a cohort run, except the run's own summary.

    stderr during :func:`tiltlab.cohort.run_cohort`: everything passes (the progress
    bar, warnings) except the summary the run prints at its end, which ``cohort run``
    prints itself, once, on stdout.
    """

    def __init__(self, stream):
        self._stream = stream
        self._dropped = False

    def write(self, text: str) -> int:
        if _SUMMARY_HEAD.match(text):
            self._dropped = True
            return len(text)
        if self._dropped and text == "\n":
            self._dropped = False
            return len(text)
        self._dropped = False
        return self._stream.write(text)

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def _name_list(option: str):
    """Make an argparse type: comma-separated names (``A,B``), none empty."""

    def parse(text: str) -> list[str]:
        names = [n.strip() for n in text.split(",")]
        if not names or any(not n for n in names):
            raise argparse.ArgumentTypeError(
                f"{option} {text!r}: give comma-separated names, none empty (e.g. "
                f"{'A,B' if option == '--groups' else 'd0,d7'})"
            )
        return names

    return parse


def _counts(values) -> str:
    """Count each value, in order of appearance: ``"a (2), b (1)"``."""
    import pandas as pd

    counts = pd.Series(list(values), dtype=object).astype(str).value_counts(sort=False)
    return ", ".join(f"{v or '(none)'} ({n})" for v, n in counts.items())


# --------------------------------------------------------------------------- commands


def _cmd_cohort_init(args: argparse.Namespace) -> int:
    from .. import cohort

    folder = Path(args.folder)
    if not folder.is_dir():
        raise UserError(f"{folder}: no such folder")
    out = _writable(Path(args.out), args.force)
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
        getattr(args, "pattern", None),
        regex=getattr(args, "regex", None),
        reader=args.reader,
        group=args.group,
        nested_subjects=getattr(args, "nested_subjects", False),
        declared=cohort.StudyLabels(
            groups=getattr(args, "groups", None),
            timepoints=getattr(args, "timepoints", None),
        ),
        reader_options=options,
        out=out,
    )
    table = manifest.table
    _emit(
        f"wrote {out}: {len(table)} session(s) of {table['subject'].nunique()} "
        f"subject(s); groups: {_counts(table['group'])}",
        f"time points: {_counts(table['timepoint'])}; reader"
        f"{'' if args.reader else 's chosen from the files'}: "
        f"{_counts(table['reader'])}",
    )
    _flush()
    return EXIT_OK


def _cohort_inputs(args: argparse.Namespace):
    """Manifest and feature configuration of ``cohort run``: a problem exits 2."""
    from .. import cohort

    try:
        manifest = cohort.read_manifest(
            args.manifest,
            groups=getattr(args, "groups", None),
            timepoints=getattr(args, "timepoints", None),
        )
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
    """Copy the manifest with ``"check_units": false`` in every row's reader_options."""
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
    """Parse ``--scheduler``: ``dask``, ``processes`` or an address."""
    if text in ("dask", "processes") or "://" in text:
        return text
    raise argparse.ArgumentTypeError(
        f"expected 'dask', 'processes' or a scheduler address such as "
        f"tcp://host:8786, got {text!r}"
    )


def _cmd_cohort_run(args: argparse.Namespace) -> int:
    from .. import cohort
    from ..cohort.tables import TABLE_SUFFIXES

    out = Path(args.out)
    if out.suffix.lower() in TABLE_SUFFIXES:
        raise UserError(
            f"--out {out} names the NetCDF feature file: give a file such as "
            "features.nc (the .csv and .parquet tables are written beside it)",
            EXIT_REJECTED,
        )
    manifest, config = _cohort_inputs(args)
    if not args.check_units:
        manifest = _without_unit_check(manifest)
    if out.is_dir():
        raise UserError(
            f"--out {out} is a folder; give a file such as features.nc", EXIT_REJECTED
        )
    progress = not args.no_progress
    # run_cohort prints the summary on stderr when it shows progress; printed here
    # once, on stdout, whatever the progress switch
    quiet = (
        contextlib.redirect_stderr(_WithoutRunSummary(sys.stderr))
        if progress
        else contextlib.nullcontext()
    )
    with quiet:
        features = cohort.run_cohort(
            manifest,
            config,
            scheduler=args.scheduler,
            workers=args.workers,
            cache_dir=args.cache_dir,
            progress=progress,
            out=out,
        )
    report = cohort.summary(features)
    _emit(str(report), f"features of {report.n_sessions} session(s) written to {out}")
    csv, parquet = _save_tables(features, out)
    _emit(
        f"the same table for R, Excel and pandas: {csv} (units and long names in "
        f"{cohort.sidecar_path(csv)}) and {parquet}"
    )
    _flush()
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


def _save_tables(features, out: Path) -> tuple[Path, Path]:
    """Write the CSV and Parquet tables beside the NetCDF feature file.

    Write ``<out stem>.csv`` (with its ``.columns.csv``) and ``.parquet`` beside
    the NetCDF feature file.
    """
    from .. import cohort

    table = cohort.to_table(features)
    return (
        _export(table, out.with_suffix(".csv")),
        _export(table, out.with_suffix(".parquet")),
    )


def _export(table, path: Path) -> Path:
    """:func:`tiltlab.cohort.save_table`, a missing pyarrow reported as a user error."""
    from .. import cohort

    try:
        return cohort.save_table(table, path)
    except ImportError as exc:
        raise UserError(f"{path}: {exc}") from None


def _export_path(text: str) -> Path:
    """Check the ``--export`` file of ``cohort show`` before any work (exit 2)."""
    from ..cohort.tables import TABLE_SUFFIXES

    path = Path(text)
    if path.suffix.lower() not in TABLE_SUFFIXES:
        raise UserError(
            f"--export {text}: unknown table format "
            f"{path.suffix or '(no suffix)'!r}; give a .csv file (units in "
            "<stem>.columns.csv beside it) or a .parquet file",
            EXIT_REJECTED,
        )
    if path.is_dir():
        raise UserError(f"--export {text} is a folder; give a file", EXIT_REJECTED)
    return path


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
    """Tabulate sessions with their labels, status and main features.

    Sessions × (labels, status, main features) as a DataFrame; units of the shown
    features; names of the features left out.
    """
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
    from .. import cohort

    path = Path(args.features)
    export = None if args.export is None else _export_path(args.export)
    if not path.is_file():
        raise UserError(f"{path}: no such file")
    features = cohort.load_features(path)
    table, units, hidden = _feature_table(
        features, None if args.all else args.max_features
    )
    _emit(
        table.to_string(
            float_format=lambda x: f"{x:.4g}", na_rep="NaN", justify="right"
        )
    )
    with_units = [f"{v} [{u}]" for v, u in units.items() if u and u != "1"]
    if with_units:
        _emit(f"\nunits: {', '.join(with_units)} (others dimensionless)")
    if hidden:
        _emit(f"{len(hidden)} more feature(s), shown with --all: {', '.join(hidden)}")
    if "status" in features:
        _emit(f"\n{cohort.summary(features)}")
    config = _config_of(features)
    if config is not None:
        digest = features.attrs.get("config_hash", "")
        _emit(f"\nconfig{f' (hash {digest[:12]})' if digest else ''}:")
        width = max(len(k) for k in config)
        _emit(*(f"  {k:<{width}} = {json.dumps(config[k])}" for k in sorted(config)))
    if export is not None:
        table = cohort.to_table(features)
        _export(table, export)
        n_rows, n_cols = table.shape
        where = (
            f" (units and long names in {cohort.sidecar_path(export)})"
            if export.suffix.lower() == ".csv"
            else ""
        )
        _emit(f"\nwrote {export}: {n_rows} session(s) x {n_cols} column(s){where}")
    _flush()
    return EXIT_OK


def _config_of(features) -> dict | None:
    """Read the feature configuration stored in a feature table's attrs, if any."""
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


#: :data:`tiltlab.cohort.READERS`' names, here so that ``--help`` imports nothing heavy
_READER_NAMES = (
    "netcdf",
    "fayat_csv",
    "fayat_tumble",
    "broad",
    "csv",
    "tagtools",
    "auto",
)

#: The pattern grammar (:data:`tiltlab.cohort.initialize.PATTERN_HELP`) as options say it.
_PATTERN_EPILOG = (
    "Patterns: a pattern is a file's path relative to FOLDER, with '/' between "
    "folders, in which {name} fields stand for parts of the path. A field matches one "
    "or more characters other than '/'; fields are read from left to right, each "
    "taking as much as it can, so where a separator (such as '_') stands between two "
    "fields the path is split at the separator's LAST occurrence: with --pattern "
    "'{group}/{subject}_{timepoint}.nc', 'A/rat_01_d0.nc' is subject 'rat_01' at time "
    "point 'd0'. Only the last field of a path segment must therefore be free of the "
    "separator before it (time points such as d0, 7d, baseline). Two fields must be "
    "separated by some text, and a field named twice must match the same text both "
    "times. Fields session, subject, group and timepoint fill those columns; any "
    "other field is a covariate. Where the rule does not fit (time points such as "
    "'day_7'), give --regex with named groups instead."
)


def _add_cohort(sub) -> None:
    """Add the ``cohort`` command's parser (``init``, ``run``, ``show``)."""
    p_cohort = sub.add_parser("cohort", help="cohort manifests and features")
    csub = p_cohort.add_subparsers(dest="cohort_cmd", required=True, metavar="COMMAND")
    p_init = csub.add_parser(
        "init",
        help="write a manifest from the files of a folder",
        description="Write a cohort manifest (one row per session) from the files of "
        "FOLDER whose relative paths match --pattern (or --regex). Prints the "
        "sessions, subjects, groups, time points and readers found: check them.",
        epilog=_PATTERN_EPILOG,
    )
    p_init.add_argument("folder", metavar="FOLDER")
    how = p_init.add_mutually_exclusive_group(required=True)
    how.add_argument(
        "--pattern",
        help='relative path with fields, e.g. "{group}/{subject}_{timepoint}.nc"; a '
        "field matches no '/', and a separator between two fields splits at its last "
        "occurrence (A/rat_01_d0.nc: subject rat_01, time point d0); see below",
    )
    how.add_argument(
        "--regex",
        metavar="REGEX",
        help="instead of --pattern: a regular expression with named groups matched "
        "against the whole relative path, e.g. "
        r"'(?P<group>[^/]+)/(?P<subject>[^/]+)_(?P<timepoint>day_\d+)\.nc'",
    )
    p_init.add_argument(
        "--reader",
        choices=_READER_NAMES,
        metavar="READER",
        help="reader of every file: "
        + ", ".join(_READER_NAMES)
        + " (auto: chosen when "
        "each session is read). Default: chosen for each file from its content "
        "(netcdf for a tiltlab Recording, tagtools for a tag-tools NetCDF, broad for "
        "a BROAD trial); any other file is refused: give --reader",
    )
    p_init.add_argument(
        "--group", help="group of every session when the pattern has no {group}"
    )
    p_init.add_argument(
        "--nested-subjects",
        action="store_true",
        help="subject ids restart in each group (A/rat1 and B/rat1 are two animals): "
        "name the subjects <group>-<subject> (A-rat1); without it a subject in two "
        "groups is refused",
    )
    _add_declared(p_init)
    _add_out_force(
        p_init,
        "manifest",
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

    p_run = csub.add_parser(
        "run",
        help="compute the features of every session of a manifest",
        description="Compute per-session features for a manifest and write them: "
        "the NetCDF feature file --out (FEATURES.nc) and, beside it, the same table "
        "for R, Excel and pandas as FEATURES.csv (UTF-8, one row per session; units "
        "and long names in FEATURES.columns.csv) and FEATURES.parquet (units in its "
        "field metadata). Prints the run's summary once, on stdout. Exit status 0 if "
        "every session succeeded, 1 if any failed (listed on stderr; the failed "
        "sessions are rows with their error), 2 if the manifest or config is "
        "rejected.",
    )
    p_run.add_argument("manifest", metavar="MANIFEST")
    p_run.add_argument(
        "--out",
        required=True,
        metavar="FEATURES.nc",
        help="feature file to write (.nc); FEATURES.csv, FEATURES.columns.csv and "
        "FEATURES.parquet are written beside it",
    )
    p_run.add_argument(
        "--workers",
        type=_positive_int("--workers"),
        help="worker processes. Without --scheduler: 1 (the default) runs the "
        "sessions one after the other in this process, N > 1 in a local pool of N "
        "processes; with --scheduler processes or dask the default is one per CPU core",
    )
    p_run.add_argument(
        "--scheduler",
        type=_scheduler,
        metavar="ADDRESS|dask|processes",
        help="'processes' (local pool), 'dask' (local dask.distributed cluster) or the "
        "address of a running dask scheduler (tcp://host:8786); default: none (see "
        "--workers)",
    )
    _add_declared(p_run)
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
        description="Print a feature file (FEATURES.nc, from 'cohort run') as a table, "
        "with its summary and config; --export also writes it as CSV or Parquet.",
    )
    p_show.add_argument("features", metavar="FEATURES.nc")
    p_show.add_argument(
        "--export",
        metavar="TABLE.csv|TABLE.parquet",
        help="also write the whole feature table, one row per session, as CSV "
        "(UTF-8; units and long names in TABLE.columns.csv) or Parquet (units in its "
        "field metadata), for R, Excel and pandas",
    )
    p_show.add_argument(
        "--max-features",
        type=_positive_int("--max-features"),
        default=len(MAIN_FEATURES),
        help=f"features shown as columns (default {len(MAIN_FEATURES)}: the main ones)",
    )
    p_show.add_argument("--all", action="store_true", help="every feature")


def _add_declared(p: argparse.ArgumentParser) -> None:
    """Add ``--groups`` and ``--timepoints``: the study's declared names."""
    p.add_argument(
        "--groups",
        type=_name_list("--groups"),
        metavar="A,B",
        help="the study's groups; a session in another group (a typo) is refused, "
        "naming it",
    )
    p.add_argument(
        "--timepoints",
        type=_name_list("--timepoints"),
        metavar="d0,d7",
        help="the study's time points; a session at another time point (a typo) is "
        "refused, naming it",
    )
