r"""Cohorts: from a lab's folder of sessions to one feature table (layer 7).

* :mod:`~tiltlab.cohort.manifest` — the cohort manifest (one CSV row per session:
  ``session, subject, group, timepoint, file, reader, reader_options, calibration`` and
  covariates), :func:`read_manifest` (rejects a malformed manifest before any work,
  naming the row);
* :mod:`~tiltlab.cohort.sessions` — :data:`READERS`, :func:`load_session` and
  :func:`load_calibration`: a session's recording and tumble test, as a row names them;
* :mod:`~tiltlab.cohort.initialize` — :func:`init_manifest` (from files matching a
  pattern such as ``"{group}/{subject}_{timepoint}.nc"``);
* :mod:`~tiltlab.cohort.config` — :class:`FeatureConfig`, every choice of the
  pipeline, frozen, validated, serialisable and hashed;
* :mod:`~tiltlab.cohort.features` — :func:`session_features`: calibration →
  orientation → tilt → features (immobility, visited sphere, vMF mean tilt and its
  sagittal angle, circling, angular speed, DBA, time tilted) of one session (Fayat et
  al. 2021, §2.7–2.10, §3.3–3.4);
* :mod:`~tiltlab.cohort.labels` — :func:`feature_name`, :func:`feature_units` and
  :func:`feature_label`: a feature's short name and units for tables and axes;
* :mod:`~tiltlab.cohort.lookup` — :func:`session_row` (a subject's session at a time
  point) and :func:`load_session_tilt` (its corrected Recording and tilt, as the
  pipeline computes them);
* :mod:`~tiltlab.cohort.run` — :func:`run_cohort` (serial, local processes or
  ``dask.distributed``, one code path; a per-session disk cache; failed sessions
  recorded, never lost), :func:`summary`, :func:`save_features`,
  :func:`load_features`;
* :mod:`~tiltlab.cohort.maps` — :func:`group_tilt_maps` (Figs 3c–d: tilt maps averaged
  per group and time point), :func:`circling_example`, :func:`gravity_frame_velocity`
  and :func:`velocity_quantiles` (Fig. A5: angular velocity in the head and the
  gravity-aligned frames);
* :mod:`~tiltlab.cohort.archive` — :func:`read_feature_archive` (saved feature tables
  of several configurations, each checked against its SHA-256);
* :mod:`~tiltlab.cohort.trajectories` — :func:`tilt_trajectories` (Fig. 3e: each
  animal's mean-tilt trajectory with its baseline at the pole, group mean directions);
* :mod:`~tiltlab.cohort.tables` — the same feature table for R, Excel and pandas:
  :func:`to_table` (a tidy DataFrame, one row per session, ids as strings, units in
  ``df.attrs``), :func:`save_table` (``.csv`` with its units in the sidecar
  ``<stem>.columns.csv``, or ``.parquet`` with units in the field metadata) and
  :func:`load_table`.

Example
-------
>>> from tiltlab import cohort                                   # doctest: +SKIP
>>> m = cohort.read_manifest("study/manifest.csv")               # doctest: +SKIP
>>> feats = cohort.run_cohort(m, cohort.FeatureConfig(), workers=4)  # doctest: +SKIP
>>> print(cohort.summary(feats))                                 # doctest: +SKIP
>>> cohort.save_table(feats, "features.csv")                     # doctest: +SKIP

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from .config import FeatureConfig
from .features import empty_features, feature_specs, session_features, session_tilt
from .initialize import init_manifest
from .labels import (
    FEATURE_NAMES,
    UNIT_TEXT,
    feature_label,
    feature_name,
    feature_units,
)
from .lookup import load_session_tilt, session_row
from .maps import (
    circling_example,
    circling_examples,
    gravity_frame_velocity,
    group_tilt_maps,
    velocity_quantiles,
)
from .manifest import (
    OPTIONAL_COLUMNS,
    READERS,
    REQUIRED_COLUMNS,
    Manifest,
    ManifestError,
    ManifestWarning,
    StudyLabels,
    load_calibration,
    load_session,
    read_manifest,
    session_path,
)
from .run import (
    CohortSummary,
    cache_key,
    compute_session,
    load_features,
    run_cohort,
    save_features,
    summary,
)
from .tables import TABLE_SUFFIXES, load_table, save_table, sidecar_path, to_table
from .trajectories import pole_rotation, tilt_trajectories
from .archive import FeatureArchive, read_feature_archive

__all__ = [
    "FeatureConfig",
    "feature_specs",
    "empty_features",
    "session_features",
    "session_tilt",
    "FEATURE_NAMES",
    "UNIT_TEXT",
    "feature_name",
    "feature_units",
    "feature_label",
    "session_row",
    "load_session_tilt",
    "group_tilt_maps",
    "circling_example",
    "circling_examples",
    "gravity_frame_velocity",
    "velocity_quantiles",
    "REQUIRED_COLUMNS",
    "OPTIONAL_COLUMNS",
    "READERS",
    "Manifest",
    "ManifestError",
    "ManifestWarning",
    "StudyLabels",
    "read_manifest",
    "init_manifest",
    "load_session",
    "load_calibration",
    "session_path",
    "CohortSummary",
    "cache_key",
    "compute_session",
    "run_cohort",
    "summary",
    "save_features",
    "load_features",
    "pole_rotation",
    "FeatureArchive",
    "read_feature_archive",
    "tilt_trajectories",
    "TABLE_SUFFIXES",
    "to_table",
    "save_table",
    "load_table",
    "sidecar_path",
]
