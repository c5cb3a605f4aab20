r"""Per-session head-tilt features (Fayat et al. 2021, §2.5–2.10, §3.3–3.4).

:func:`session_features` is one plain pipeline,

.. code-block:: text

    Recording ─calibration─▶ corrected ─filters.estimate─▶ q ─filters.gravity─▶ g_s
        └──────────── angular speed, immobility ───────────┴──▶ features

1. **Calibration** (§2.5, App. A.1): the accelerometer offsets (or ellipsoid) of the
   subject's tumble test, then the session's own gyroscope offset :math:`b` from its
   quietest windows, :math:`\omega \leftarrow \omega - b`.
2. **Orientation** with any registered method and **tilt**
   :math:`g_s = R(q)^\top e_z`.
3. **Features** (all scalars), with the angular speed
   :math:`s = \lVert\omega\rVert` in °/s:

   * immobility (§2.9): the fraction of samples in still periods,
     :math:`s < 12` °/s, gaps :math:`< 0.1` s merged, periods :math:`< 0.5` s dropped,
     and the same with the threshold at the valley of the :math:`\log_{10} s`
     histogram;
   * fraction of the sphere visited (§2.7, area-based):
     :math:`\sum_{f\,\text{visited}} A_f / 4\pi` on the Fibonacci mesh, all samples and
     while moving;
   * mean tilt during immobility (§2.8): the vMF maximum-likelihood direction
     :math:`\hat\mu = \sum g_i / \lVert\sum g_i\rVert`, its concentration
     :math:`\hat\kappa` (:math:`A_3(\hat\kappa) = \bar R`) and the signed angle to the
     sagittal plane :math:`\alpha = \arcsin(-s_\mathrm{side}\,\hat\mu_y)`, positive
     toward the lesion side;
   * circling index (§2.10): :math:`\overline{\omega\cdot\hat g_s}` over moving samples
     in circles per minute, counter-clockwise (seen from above) positive;
   * quantiles of :math:`s` while moving; mean DBA :math:`\lVert a - \bar a\rVert` and
     ODBA :math:`\sum_j |a_j - \bar a_j|` in g;
   * the fraction of time with the head tilted beyond :math:`\theta`:
     :math:`\arccos(g_{s,z}) > \theta`.

Sessions without a gyroscope (bio-logging tags: accelerometer, maybe magnetometer) are
first-class: the tilt comes from ``config.no_gyro_method`` (the static-acceleration
low-pass by default), immobility from the accelerometer rule
(:func:`tiltlab.behavior.acc_immobility`, VeDBA below ``config.acc_threshold_g``), and
the features that need the angular velocity (gyroscope offset, angular-speed quantiles,
the valley threshold, circling) are NaN with the reason in the result's attrs. The
same holds for a session with no immobile or no moving sample: the features over the
empty set are NaN, with the reason, never an error.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
.. [2] S. Benhamou, arXiv:2310.05820, 2023. doi:10.48550/arXiv.2310.05820
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .. import __version__, _deprecate
from .. import behavior as _behavior
from .. import calibration as _calibration
from .. import filters as _filters
from .. import schema as _schema
from .. import sphere as _sphere
from .. import units as _units
from .._validate import RecordingError
from .config import FeatureConfig

__all__ = ["feature_specs", "session_features", "empty_features", "session_tilt"]

#: the reason given for the features that need the angular velocity
NO_GYRO = "needs a gyroscope; the Recording has no 'gyr'"


def _tag(x: float) -> str:
    return f"{x:g}".replace(".", "p").replace("-", "m")


def _axis_keys(prefix: str) -> list[str]:
    """Name the features of one quantity per axis: ``<prefix>_x``, ``_y``, ``_z``."""
    return [f"{prefix}_{a}" for a in "xyz"]


def _per_axis(prefix: str, units: str, text: str) -> dict[str, tuple[str, str]]:
    """Specs of a per-axis feature, ``text`` formatted with the axis name."""
    return {k: (units, text.format(a)) for k, a in zip(_axis_keys(prefix), "xyz")}


def feature_specs(config: FeatureConfig | None = None) -> dict[str, tuple[str, str]]:
    """Feature names → (units, long_name), in output order, for a configuration.

    Parameters
    ----------
    config : FeatureConfig, optional
        Feature configuration (thresholds, quantiles, mesh size ...); default
        ``FeatureConfig()``.

    Returns
    -------
    dict
        Feature name -> ``(units, long_name)``, both str, in output order.
    """
    c = config or FeatureConfig()
    thr = f"{c.threshold_deg_s:g} deg/s"
    what = "area" if c.visited_by == "area" else "facets"
    spec = {
        "n_samples": ("1", "number of samples analysed (samples in gaps left out)"),
        "duration_s": ("s", "duration of the recording"),
        **_per_axis(
            "gyr_offset", "deg/s", "gyroscope offset removed, {} (session estimate)"
        ),
        "immobile_fraction": (
            "1",
            f"fraction of time immobile (angular speed < {thr}, or without a "
            f"gyroscope VeDBA < {c.acc_threshold_g:g} g; gaps < {c.merge_gap_s:g} s "
            f"merged, periods < {c.min_duration_s:g} s dropped)",
        ),
        "immobile_fraction_auto": (
            "1",
            "fraction of time immobile with the threshold at the valley of the "
            "log angular-speed histogram",
        ),
        "immobility_threshold_auto": (
            "deg/s",
            "angular-speed threshold at the valley of the log-speed histogram",
        ),
        "visited_fraction": (
            "1",
            f"fraction of the sphere's {what} visited by the tilt (mesh of "
            f"{c.mesh_n} vertices), all samples",
        ),
        "visited_fraction_moving": (
            "1",
            f"fraction of the sphere's {what} visited by the tilt while moving",
        ),
        **_per_axis(
            "tilt_immobile", "1", "vMF mean tilt during immobility, sensor {} axis"
        ),
        "tilt_immobile_kappa": ("1", "vMF concentration of the tilt during immobility"),
        "tilt_immobile_sagittal_deg": (
            "deg",
            "angular distance of the mean immobile tilt to the sagittal plane"
            if c.sagittal == "unsigned"
            else f"angle of the mean immobile tilt to the sagittal plane, positive "
            f"toward the {c.lesion_side} (lesion) side",
        ),
        "circling_index": (
            "1/min",
            "mean rotation about gravity while moving (circles per minute, "
            "counter-clockwise seen from above positive)",
        ),
    }
    for q in c.speed_quantiles:
        spec[f"angular_speed_moving_q{_tag(100 * q)}"] = (
            "deg/s",
            f"{100 * q:g}th percentile of the angular speed while moving",
        )
    spec["dba_mean"] = (
        "g",
        f"mean dynamic body acceleration (VeDBA, {c.dba_window_s:g} s window)",
    )
    spec["odba_mean"] = (
        "g",
        f"mean overall dynamic body acceleration ({c.dba_window_s:g} s window)",
    )
    for t in c.tilt_thresholds_deg:
        spec[f"tilted_fraction_{_tag(t)}deg"] = (
            "1",
            f"fraction of time with the tilt more than {t:g} deg from +z",
        )
    return spec


def _dataset(
    values: dict[str, float],
    config: FeatureConfig,
    attrs=None,
    reasons: dict[str, str] | None = None,
) -> xr.Dataset:
    spec = feature_specs(config)
    reasons = dict(reasons or {})
    data = {}
    for k, (u, ln) in spec.items():
        v = np.float64(values.get(k, np.nan))
        a = {"units": u, "long_name": ln}
        if np.isnan(v) and k in reasons:
            a["reason"] = reasons[k]
        data[k] = ((), v, a)
    a = {
        "feature_config": config.to_json(),
        "config_hash": config.hash(),
        "tiltlab_version": __version__,
        **dict(attrs or {}),
    }
    if reasons:
        a["reasons"] = reasons
        by_reason: dict[str, list[str]] = {}
        for k, r in reasons.items():
            by_reason.setdefault(r, []).append(k)
        a["notes"] = "; ".join(f"{', '.join(ks)}: {r}" for r, ks in by_reason.items())
    return xr.Dataset(data, attrs=a)


def empty_features(config: FeatureConfig | None = None) -> xr.Dataset:
    """Make the feature Dataset of a failed session: every value NaN.

    Parameters
    ----------
    config : FeatureConfig, optional
        Feature configuration; default ``FeatureConfig()``.

    Returns
    -------
    xarray.Dataset
        One NaN variable per feature of :func:`feature_specs`, with its units and
        long name.
    """
    return _dataset({}, config or FeatureConfig())


def _tumble(cal, config: FeatureConfig):
    """Make a Calibration from a tumble-test Recording (or take a Calibration as is)."""
    if isinstance(cal, _calibration.Calibration):
        return cal
    if not isinstance(cal, xr.Dataset):
        raise TypeError(
            "calibration must be a tumble-test Recording or a "
            f"tiltlab.calibration.Calibration, got {type(cal).__name__}"
        )
    fit = _calibration.tumble_calibration(
        cal, model=config.calibration_model
    ).calibration
    return _calibration.Calibration(
        name="tumble test",
        acc_offset=fit.acc_offset,
        acc_matrix=fit.acc_matrix,
        gyr_offset=fit.gyr_offset if config.calibration_gyro else None,
        info=fit.info,
    )


def _corrected(rec: xr.Dataset, config: FeatureConfig, calibration, notes=None):
    """Calibrate a Recording and remove the session's gyroscope offset.

    Calibrated Recording and the session gyro offset removed (°/s; NaN when it
    could not be estimated, e.g. sustained rotation throughout: then nothing is
    removed and ``notes`` gets the reason).
    """
    stacked = False
    if calibration is not None:
        cal = _tumble(calibration, config)
        rec = _calibration.calibrate(rec, cal)
        stacked = "gyr_offset" in cal.corrects()
    off = np.zeros(3)
    if config.gyr_offset == "auto" and "gyr" in rec:
        try:
            # sustained rotation is never removed as an offset: the reason is kept
            raw = np.asarray(
                _calibration.robust_gyro_offset(rec, on_rotation="raise"), float
            )
        except _calibration.CalibrationError as exc:
            if notes is not None:
                notes.append(f"gyroscope offset not removed: {exc}")
            return rec, np.full(3, np.nan)
        off = raw * _units.conversion_factor(rec["gyr"].attrs["units"], "deg/s")
        rec = _calibration.calibrate(
            rec,
            _calibration.Calibration(name="session gyro offset", gyr_offset=off),
            allow_stacking=stacked,
        )
    return rec, off


@_deprecate.renamed(recording="rec")
def session_tilt(
    rec: xr.Dataset,
    config: FeatureConfig | None = None,
    *,
    calibration=None,
) -> tuple[xr.Dataset, xr.DataArray]:
    """Correct one session and find its tilt, as the feature pipeline sees them.

    The first steps of :func:`session_features`, for figures that need the per-sample data
    (tilt maps, angular velocity in a gravity-aligned frame): the tumble-test calibration
    (when given), the session's gyroscope offset (``config.gyr_offset``), then the
    orientation method of ``config`` and the gravity-up direction.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording; not modified.
    config : FeatureConfig, optional
        Default :class:`FeatureConfig()`.
    calibration : xarray.Dataset or tiltlab.calibration.Calibration, optional
        The subject's tumble test (see :func:`session_features`).

    Returns
    -------
    rec : xarray.Dataset
        The corrected Recording.
    tilt : xarray.DataArray
        Gravity-up direction in the sensor frame (time, axis), with ``fs`` and the method.
    """
    config = config or FeatureConfig()
    corrected, _ = _corrected(rec, config, calibration)
    return corrected, _tilt(corrected, config)


def _tilt_method(rec: xr.Dataset, config: FeatureConfig) -> tuple[str, dict, bool]:
    """Choose the tilt method, its parameters and ``use_mag`` for this Recording.

    The method, parameters and ``use_mag`` for this Recording: ``config.method``
    when the Recording has what it needs, else ``config.no_gyro_method``.
    """
    have = {v for v in _filters.SENSORS if v in rec}
    if set(_filters.get_method(config.method).needs) <= have:
        return config.method, config.method_params, config.use_mag
    return config.no_gyro_method, config.no_gyro_method_params, False


def _tilt(rec: xr.Dataset, config: FeatureConfig) -> xr.DataArray:
    """Estimate the gravity-up direction of a corrected Recording.

    Gravity-up direction of a corrected Recording with the configured method (or,
    without the sensors it needs, ``config.no_gyro_method``).
    """
    method, params, use_mag = _tilt_method(rec, config)
    with warnings.catch_warnings():  # the features record the gaps themselves
        warnings.filterwarnings("ignore", r"estimate\(.*gaps='segments'")
        q = _filters.estimate(rec, method, use_mag=use_mag, gaps="segments", **params)
    return _filters.gravity(q)


def _immobile(speed, config: FeatureConfig, threshold: float) -> np.ndarray:
    return np.asarray(
        _behavior.detect_immobility(
            speed,
            threshold_deg_s=threshold,
            merge_gap_s=config.merge_gap_s,
            min_duration_s=config.min_duration_s,
        ),
        dtype=bool,
    )


@_deprecate.renamed(recording="rec")
def session_features(
    rec: xr.Dataset,
    config: FeatureConfig | None = None,
    *,
    calibration=None,
    check_units: bool = True,
    validate: bool = True,
) -> xr.Dataset:
    r"""Head-tilt features of one session, as a Dataset of labelled scalars.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording (``acc``, ``gyr`` with units; ``fs``); not modified.
    config : FeatureConfig, optional
        Every choice of the pipeline (default :class:`FeatureConfig()`).
    calibration : xarray.Dataset or tiltlab.calibration.Calibration, optional
        The subject's tumble-test Recording (its accelerometer offsets, or ellipsoid,
        are fitted with :func:`tiltlab.calibration.tumble_calibration` and applied),
        or a ready :class:`~tiltlab.calibration.Calibration`.
    check_units : bool
        Check the values against their unit labels when re-validating the Recording
        (:func:`tiltlab.schema.validate`); ``False`` accepts the labels as they are.
    validate : bool
        Validate ``rec`` first (default). ``False`` is for a Recording that its reader
        has just validated (the cohort pipeline reads every session through one), so
        that each session is validated once.

    Returns
    -------
    xarray.Dataset
        0-d variables named by :func:`feature_specs`, each with ``units`` and a
        one-line ``long_name``; attrs ``feature_config`` (the configuration's JSON),
        ``config_hash``, ``tiltlab_version``, ``source``, ``sensors`` (the Recording's
        sensor variables), ``tilt_method`` (the orientation method used) and
        ``immobility_rule`` (gyroscope or accelerometer, with its threshold and
        units). A feature that is undefined for this session (no gyroscope, no
        immobility, no movement, a unimodal speed distribution) is NaN, with the
        reason in its own ``reason`` attribute, in ``attrs["reasons"]`` (feature →
        reason) and in ``attrs["notes"]`` (one line).

    Examples
    --------
    >>> from tiltlab import cohort
    >>> from tiltlab.simulate import simulate_session
    >>> rec = simulate_session(20.0, 100.0, seed=1, keep_true=False).drop_vars("gyr")
    >>> f = cohort.session_features(rec, cohort.FeatureConfig(mesh_n=500))
    >>> f.attrs["tilt_method"], f.attrs["immobility_rule"].split(":")[0]
    ('lowpass', 'accelerometer')
    >>> bool(f["circling_index"].isnull()), f["circling_index"].attrs["reason"]
    (True, "needs a gyroscope; the Recording has no 'gyr'")

    Raises
    ------
    tiltlab._validate.RecordingError
        A recording that breaks the Recording contract (non-finite sensor samples,
        inconsistent ``fs`` …) or is too short for the pipeline.

    Notes
    -----
    Immobility (Fayat §2.9) on the offset-corrected angular speed
    :math:`s = \lVert\omega - b\rVert`: :math:`s < s_0` (:math:`s_0` = 12 °/s), periods
    separated by less than 0.1 s merged, periods shorter than 0.5 s discarded. The mean
    tilt during immobility (§2.8) is the vMF estimate over the immobile samples,
    :math:`\hat\mu = S/\lVert S\rVert`, :math:`S = \sum_{i\,\text{immobile}} g_i`, and
    :math:`\hat\kappa` solves :math:`\coth\kappa - 1/\kappa = \lVert S\rVert / n`;
    its angle to the sagittal (xz) plane is :math:`\arcsin(-s\,\hat\mu_y)` with
    :math:`s = +1` for a left lesion (the up direction moves to :math:`-y` when the
    left ear goes down, §3.3). The circling index (§2.10) is
    :math:`\frac{60}{360}\,\overline{\omega\cdot\hat g_s}` over moving samples
    (circles/min, CCW positive). The visited fraction (§2.7) sums the exact spherical
    areas of the facets holding at least ``visited_min_count`` samples, over
    :math:`4\pi`.

    References
    ----------
    .. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
    """
    config = _checked(rec, config, check_units, validate)
    acc = _Features(feature_specs(config))
    has_gyr = "gyr" in rec
    offset_notes: list[str] = []
    corrected, off = _corrected(rec, config, calibration, offset_notes)
    _offset_features(acc, has_gyr, offset_notes, off)
    _check_length(corrected)
    s = _samples(corrected, _tilt(corrected, config))
    _immobility(acc, s, config)
    _visited_features(acc, s, config)
    _tilt_immobile_features(acc, s, config)
    _motion_features(acc, s, config)
    _acceleration_features(acc, s, config)
    method, _, _ = _tilt_method(corrected, config)
    attrs = {
        "source": str(rec.attrs.get("source", "")),
        "sensors": ", ".join(v for v in _filters.SENSORS if v in rec),
        "tilt_method": method,
        "immobility_rule": s.rule,
        **s.gaps,
    }
    return _dataset(acc.out, config, attrs, acc.reasons)


def _checked(
    rec, config: FeatureConfig | None, check_units: bool, validate: bool = True
) -> FeatureConfig:
    """Check both inputs and return the configuration (default ``FeatureConfig()``)."""
    config = config or FeatureConfig()
    if not isinstance(config, FeatureConfig):
        raise TypeError(f"config must be a FeatureConfig, got {type(config).__name__}")
    if not isinstance(rec, xr.Dataset):
        raise TypeError(
            f"rec must be a Recording (xarray.Dataset), got {type(rec).__name__}"
        )
    if validate:
        _schema.validate(rec, allow_nan=True, check_units=check_units)
    return config


class _Features:
    """The feature values found so far, and the reasons of those left undefined."""

    def __init__(self, spec: dict[str, tuple[str, str]]):
        self.spec = spec
        self.out: dict[str, float] = {}
        self.reasons: dict[str, str] = {}

    def undefined(self, keys, reason: str) -> None:
        """Record why the features ``keys`` are NaN (the first reason given wins)."""
        for k in keys:
            self.reasons.setdefault(k, reason)

    def speed_keys(self) -> list[str]:
        """List the names of the angular-speed quantile features."""
        return [k for k in self.spec if k.startswith("angular_speed_moving_q")]


@dataclass
class _Samples:
    """The corrected session, its tilt and the samples the features are computed on."""

    rec: xr.Dataset  # corrected Recording
    g: xr.DataArray  # gravity-up direction, every sample
    valid: np.ndarray  # samples outside gaps
    n: int
    gaps: dict[str, str]
    speed: xr.DataArray | None = None  # angular speed (°/s, gaps at 1e9)
    imm: np.ndarray | None = None  # immobile, valid samples only
    rule: str = ""

    @property
    def has_gyr(self) -> bool:
        """Whether the session has a gyroscope."""
        return "gyr" in self.rec

    @property
    def n_valid(self) -> int:
        """Number of samples outside gaps."""
        return int(self.valid.sum())

    @property
    def gv(self) -> np.ndarray:
        """Tilt of the valid samples, (n_valid, 3)."""
        return self.g.values[self.valid]

    @property
    def moving(self) -> np.ndarray:
        """Moving valid samples."""
        return ~self.imm


def _check_length(rec: xr.Dataset) -> None:
    """Refuse a session shorter than 2 s."""
    fs = float(rec.attrs["fs"])
    n = rec.sizes["time"]
    if n < 2 * fs:
        raise RecordingError(
            f"the recording is too short for the features ({n} samples, {n / fs:.2f} s;"
            " at least 2 s needed)"
        )


def _samples(rec: xr.Dataset, g: xr.DataArray) -> _Samples:
    """Find the samples outside gaps, refusing a session with less than 2 s of them.

    Samples in gaps (non-finite sensor values, hence no tilt) are left out of every
    feature; the immobility rules count them as neither still nor moving.
    """
    fs = float(rec.attrs["fs"])
    n = rec.sizes["time"]
    valid = np.isfinite(g.values).all(axis=1)
    for v in ("acc", "gyr"):
        if v in rec:
            valid &= np.isfinite(rec[v].values).all(axis=1)
    n_valid = int(valid.sum())
    if n_valid < 2 * fs:
        raise RecordingError(
            f"the recording has too few samples outside its gaps ({n_valid} of {n}; at "
            "least 2 s needed)"
        )
    gaps = (
        {}
        if n_valid == n
        else {"gaps": f"{n - n_valid} of {n} samples in gaps left out"}
    )
    return _Samples(rec=rec, g=g, valid=valid, n=n, gaps=gaps)


def _offset_features(acc: _Features, has_gyr: bool, notes: list[str], off) -> None:
    """Duration and the session's gyroscope offset (or why it is undefined)."""
    keys = _axis_keys("gyr_offset")
    if not has_gyr:
        acc.undefined(keys, NO_GYRO)
    elif notes:
        acc.undefined(keys, notes[0])
    else:
        acc.out.update({k: float(o) for k, o in zip(keys, off)})


def _immobility(acc: _Features, s: _Samples, config: FeatureConfig) -> None:
    """Immobility by the gyroscope or accelerometer rule, and its valley threshold."""
    fs = float(s.rec.attrs["fs"])
    acc.out["duration_s"] = s.n / fs
    acc.out["n_samples"] = s.n_valid
    if s.has_gyr:
        # a gap is never still: a speed above any threshold there (left out below)
        s.speed = _behavior.angular_speed(s.rec).fillna(1e9)
        s.imm = _immobile(s.speed, config, config.threshold_deg_s)[s.valid]
        s.rule = (
            f"gyroscope: angular speed < {config.threshold_deg_s:g} deg/s, gaps < "
            f"{config.merge_gap_s:g} s merged, periods < {config.min_duration_s:g} s "
            "dropped"
        )
    else:
        still = _behavior.acc_immobility(
            s.rec,
            threshold_g=config.acc_threshold_g,
            window_s=config.acc_window_s,
            smooth_s=config.acc_smooth_s,
            merge_gap_s=config.merge_gap_s,
            min_duration_s=config.min_duration_s,
        )
        s.imm = np.asarray(still, dtype=bool)[s.valid]
        s.rule = f"accelerometer: {still.attrs['rule_description']}"
    acc.out["immobile_fraction"] = float(s.imm.mean())
    auto_keys = ["immobility_threshold_auto", "immobile_fraction_auto"]
    if not config.auto_threshold:
        acc.undefined(auto_keys, "not computed (config.auto_threshold is False)")
    elif not s.has_gyr:
        acc.undefined(auto_keys, NO_GYRO + " (valley of the angular-speed histogram)")
    else:
        try:
            thr = _behavior.valley_threshold(s.speed[s.valid])
        except ValueError as exc:
            acc.undefined(auto_keys, str(exc))
        else:
            acc.out["immobility_threshold_auto"] = float(thr)
            acc.out["immobile_fraction_auto"] = float(
                _immobile(s.speed, config, thr)[s.valid].mean()
            )


def _visited_features(acc: _Features, s: _Samples, config: FeatureConfig) -> None:
    """Fraction of the sphere's area visited, all samples and while moving."""
    mesh = _sphere.sphere_mesh(config.mesh_n)
    moving = s.moving
    for key, mask in (("visited_fraction", None), ("visited_fraction_moving", moving)):
        if mask is not None and not mask.any():
            acc.undefined([key], "no moving samples")
            continue
        tmap = _sphere.tilt_map(s.g[s.valid], mesh=mesh, mask=mask)
        acc.out[key] = _sphere.visited_fraction(
            tmap, mesh, min_count=config.visited_min_count, by=config.visited_by
        )


def _tilt_immobile_features(acc: _Features, s: _Samples, config: FeatureConfig) -> None:
    """Fit the vMF mean tilt during immobility, its concentration and sagittal angle."""
    keys = _axis_keys("tilt_immobile")
    keys += ["tilt_immobile_kappa", "tilt_immobile_sagittal_deg"]
    if s.imm.sum() < 2:
        acc.undefined(keys, f"fewer than 2 immobile samples ({int(s.imm.sum())})")
        return
    if config.tilt_mean == "map":  # Fayat §2.8: facet centroids weighted by counts
        tmap = _sphere.tilt_map(s.gv[s.imm], mesh=_sphere.sphere_mesh(config.mesh_n))
        fit = _sphere.vmf_fit(tmap["centroid"].values, weights=tmap["count"].values)
    else:
        fit = _sphere.vmf_fit(s.gv[s.imm])
    acc.out.update({k: float(m) for k, m in zip(keys, fit.mu)})
    acc.out["tilt_immobile_kappa"] = float(fit.kappa)
    angle = np.degrees(_sphere.sagittal_angle(fit.mu, config.lesion_side))
    unsigned = config.sagittal == "unsigned"
    acc.out["tilt_immobile_sagittal_deg"] = float(abs(angle) if unsigned else angle)


def _motion_features(acc: _Features, s: _Samples, config: FeatureConfig) -> None:
    """Circling index and angular-speed quantiles while moving (gyroscope only)."""
    keys = ["circling_index", *acc.speed_keys()]
    moving = s.moving
    if not s.has_gyr:
        acc.undefined(keys, NO_GYRO)
        return
    if not moving.any():
        acc.undefined(keys, "no moving samples")
        return
    whole = s.n_valid == s.n
    acc.out["circling_index"] = _behavior.circling_index(
        s.rec if whole else s.rec.isel(time=s.valid),
        s.g if whole else s.g[s.valid],
        moving=moving,
    )
    sp = np.asarray(s.speed, float)[s.valid]
    for q in config.speed_quantiles:
        key = f"angular_speed_moving_q{_tag(100 * q)}"
        acc.out[key] = float(np.quantile(sp[moving], q))


def _acceleration_features(acc: _Features, s: _Samples, config: FeatureConfig) -> None:
    """Mean DBA and ODBA (g), and the fractions of time tilted beyond thresholds."""
    to_g = _units.conversion_factor(s.rec["acc"].attrs["units"], "g")
    # DBA is NaN where its window touches a gap
    acc.out["dba_mean"] = float(
        np.nanmean(_behavior.dba(s.rec, window_s=config.dba_window_s)) * to_g
    )
    acc.out["odba_mean"] = float(
        np.nanmean(_behavior.odba(s.rec, window_s=config.dba_window_s)) * to_g
    )
    gv = s.gv
    gz = np.clip(gv[:, 2] / np.linalg.norm(gv, axis=1), -1.0, 1.0)
    tilt_deg = np.degrees(np.arccos(gz))
    for t in config.tilt_thresholds_deg:
        acc.out[f"tilted_fraction_{_tag(t)}deg"] = float(np.mean(tilt_deg > t))
