"""``tiltlab cohort init``, ``run`` and ``show``."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ._common import (
    EXIT_ERROR,
    EXIT_OK,
    EXIT_REJECTED,
    UserError,
    _message,
    _read_json,
    _user_errors,
)


def _cmd_cohort_init(args: argparse.Namespace) -> int:
    from .. import cohort

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
    from .. import cohort

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
    csv, parquet = _save_tables(features, out)
    print(
        f"the same table for R, Excel and pandas: {csv} (units and long names in "
        f"{cohort.sidecar_path(csv)}) and {parquet}"
    )
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
    """Write ``<out stem>.csv`` (with its ``.columns.csv``) and ``.parquet`` beside
    the NetCDF feature file."""
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
    """The ``--export`` file of ``cohort show``, checked before any work (exit 2)."""
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
    from .. import cohort

    path = Path(args.features)
    export = None if args.export is None else _export_path(args.export)
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
    if export is not None:
        table = cohort.to_table(features)
        _export(table, export)
        n_rows, n_cols = table.shape
        where = (
            f" (units and long names in {cohort.sidecar_path(export)})"
            if export.suffix.lower() == ".csv"
            else ""
        )
        print(f"\nwrote {export}: {n_rows} session(s) x {n_cols} column(s){where}")
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
