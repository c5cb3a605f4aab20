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

import numpy as np
import xarray as xr

from .. import __version__
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
    spec = {
        "n_samples": ("1", "number of samples analysed (samples in gaps left out)"),
        "duration_s": ("s", "duration of the recording"),
        "gyr_offset_x": ("deg/s", "gyroscope offset removed, x (session estimate)"),
        "gyr_offset_y": ("deg/s", "gyroscope offset removed, y (session estimate)"),
        "gyr_offset_z": ("deg/s", "gyroscope offset removed, z (session estimate)"),
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
            f"fraction of the sphere's area visited by the tilt (mesh of {c.mesh_n} "
            "vertices), all samples",
        ),
        "visited_fraction_moving": (
            "1",
            "fraction of the sphere's area visited by the tilt while moving",
        ),
        "tilt_immobile_x": ("1", "vMF mean tilt during immobility, sensor x axis"),
        "tilt_immobile_y": ("1", "vMF mean tilt during immobility, sensor y axis"),
        "tilt_immobile_z": ("1", "vMF mean tilt during immobility, sensor z axis"),
        "tilt_immobile_kappa": ("1", "vMF concentration of the tilt during immobility"),
        "tilt_immobile_sagittal_deg": (
            "deg",
            f"angle of the mean immobile tilt to the sagittal plane, positive toward "
            f"the {c.lesion_side} (lesion) side",
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
    """The feature Dataset of a configuration with every value NaN (a failed session).

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
    """A Calibration from a tumble-test Recording (or a Calibration given as is)."""
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
    """Calibrated Recording and the session gyro offset removed (°/s; NaN when it
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


def session_tilt(
    recording: xr.Dataset,
    config: FeatureConfig | None = None,
    *,
    calibration=None,
) -> tuple[xr.Dataset, xr.DataArray]:
    """The corrected Recording and the tilt of one session, as the feature pipeline sees them.

    The first steps of :func:`session_features`, for figures that need the per-sample data
    (tilt maps, angular velocity in a gravity-aligned frame): the tumble-test calibration
    (when given), the session's gyroscope offset (``config.gyr_offset``), then the
    orientation method of ``config`` and the gravity-up direction.

    Parameters
    ----------
    recording : xarray.Dataset
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
    rec, _ = _corrected(recording, config, calibration)
    return rec, _tilt(rec, config)


def _tilt_method(rec: xr.Dataset, config: FeatureConfig) -> tuple[str, dict, bool]:
    """The method, parameters and ``use_mag`` for this Recording: ``config.method``
    when the Recording has what it needs, else ``config.no_gyro_method``.
    """
    have = {v for v in _filters.SENSORS if v in rec}
    if set(_filters.get_method(config.method).needs) <= have:
        return config.method, config.method_params, config.use_mag
    return config.no_gyro_method, config.no_gyro_method_params, False


def _tilt(rec: xr.Dataset, config: FeatureConfig) -> xr.DataArray:
    """Gravity-up direction of a corrected Recording with the configured method (or,
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


def session_features(
    recording: xr.Dataset,
    config: FeatureConfig | None = None,
    *,
    calibration=None,
    check_units: bool = True,
) -> xr.Dataset:
    r"""Head-tilt features of one session, as a Dataset of labelled scalars.

    Parameters
    ----------
    recording : xarray.Dataset
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
    config = config or FeatureConfig()
    if not isinstance(config, FeatureConfig):
        raise TypeError(f"config must be a FeatureConfig, got {type(config).__name__}")
    if not isinstance(recording, xr.Dataset):
        raise TypeError(
            "recording must be a Recording (xarray.Dataset), got "
            f"{type(recording).__name__}"
        )
    _schema.validate(recording, allow_nan=True, check_units=check_units)
    has_gyr = "gyr" in recording
    offset_notes: list[str] = []
    rec, off = _corrected(recording, config, calibration, offset_notes)
    fs = float(rec.attrs["fs"])
    n = rec.sizes["time"]
    if n < 2 * fs:
        raise RecordingError(
            f"the recording is too short for the features ({n} samples, {n / fs:.2f} s;"
            " at least 2 s needed)"
        )
    spec = feature_specs(config)
    reasons: dict[str, str] = {}

    def undefined(keys, reason: str) -> None:
        for k in keys:
            reasons.setdefault(k, reason)

    out: dict[str, float] = {"duration_s": n / fs}
    offset_keys = [f"gyr_offset_{a}" for a in "xyz"]
    speed_keys = [k for k in spec if k.startswith("angular_speed_moving_q")]
    if not has_gyr:
        undefined(offset_keys, NO_GYRO)
    elif offset_notes:
        undefined(offset_keys, offset_notes[0])
    else:
        out.update({k: float(o) for k, o in zip(offset_keys, off)})

    method, _, _ = _tilt_method(rec, config)
    g = _tilt(rec, config)
    # samples in gaps (non-finite sensor values, hence no tilt) are left out below;
    # the immobility rules count them as neither still nor moving
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
    out["n_samples"] = n_valid
    gv = g.values[valid]
    if has_gyr:
        # a gap is never still: a speed above any threshold there (left out below)
        speed = _behavior.angular_speed(rec).fillna(1e9)
        sp = np.asarray(speed, float)[valid]
        imm = _immobile(speed, config, config.threshold_deg_s)[valid]
        rule = (
            f"gyroscope: angular speed < {config.threshold_deg_s:g} deg/s, gaps < "
            f"{config.merge_gap_s:g} s merged, periods < {config.min_duration_s:g} s "
            "dropped"
        )
    else:
        still = _behavior.acc_immobility(
            rec,
            threshold_g=config.acc_threshold_g,
            window_s=config.acc_window_s,
            smooth_s=config.acc_smooth_s,
            merge_gap_s=config.merge_gap_s,
            min_duration_s=config.min_duration_s,
        )
        imm = np.asarray(still, dtype=bool)[valid]
        rule = f"accelerometer: {still.attrs['rule_description']}"
    moving = ~imm
    out["immobile_fraction"] = float(imm.mean())
    auto_keys = ["immobility_threshold_auto", "immobile_fraction_auto"]
    if not config.auto_threshold:
        undefined(auto_keys, "not computed (config.auto_threshold is False)")
    elif not has_gyr:
        undefined(auto_keys, NO_GYRO + " (valley of the angular-speed histogram)")
    else:
        try:
            thr = _behavior.valley_threshold(speed[valid])
        except ValueError as exc:
            undefined(auto_keys, str(exc))
        else:
            out["immobility_threshold_auto"] = float(thr)
            out["immobile_fraction_auto"] = float(
                _immobile(speed, config, thr)[valid].mean()
            )

    mesh = _sphere.sphere_mesh(config.mesh_n)
    for key, mask in (("visited_fraction", None), ("visited_fraction_moving", moving)):
        if mask is not None and not mask.any():
            undefined([key], "no moving samples")
            continue
        tmap = _sphere.tilt_map(g[valid], mesh=mesh, mask=mask)
        out[key] = _sphere.visited_fraction(
            tmap, mesh, min_count=config.visited_min_count, by="area"
        )

    tilt_keys = [f"tilt_immobile_{a}" for a in "xyz"]
    tilt_keys += ["tilt_immobile_kappa", "tilt_immobile_sagittal_deg"]
    if imm.sum() >= 2:
        fit = _sphere.vmf_fit(gv[imm])
        out.update({f"tilt_immobile_{a}": float(m) for a, m in zip("xyz", fit.mu)})
        out["tilt_immobile_kappa"] = float(fit.kappa)
        out["tilt_immobile_sagittal_deg"] = float(
            np.degrees(_sphere.sagittal_angle(fit.mu, config.lesion_side))
        )
    else:
        undefined(tilt_keys, f"fewer than 2 immobile samples ({int(imm.sum())})")

    if not has_gyr:
        undefined(["circling_index", *speed_keys], NO_GYRO)
    elif moving.any():
        whole = n_valid == n
        out["circling_index"] = _behavior.circling_index(
            rec if whole else rec.isel(time=valid),
            g if whole else g[valid],
            moving=moving,
        )
        for q in config.speed_quantiles:
            key = f"angular_speed_moving_q{_tag(100 * q)}"
            out[key] = float(np.quantile(sp[moving], q))
    else:
        undefined(["circling_index", *speed_keys], "no moving samples")

    to_g = _units.conversion_factor(rec["acc"].attrs["units"], "g")
    # DBA is NaN where its window touches a gap
    out["dba_mean"] = float(
        np.nanmean(_behavior.dba(rec, window_s=config.dba_window_s)) * to_g
    )
    out["odba_mean"] = float(
        np.nanmean(_behavior.odba(rec, window_s=config.dba_window_s)) * to_g
    )
    gz = np.clip(gv[:, 2] / np.linalg.norm(gv, axis=1), -1.0, 1.0)
    tilt_deg = np.degrees(np.arccos(gz))
    for t in config.tilt_thresholds_deg:
        out[f"tilted_fraction_{_tag(t)}deg"] = float(np.mean(tilt_deg > t))

    attrs = {
        "source": str(recording.attrs.get("source", "")),
        "sensors": ", ".join(v for v in _filters.SENSORS if v in recording),
        "tilt_method": method,
        "immobility_rule": rule,
        **gaps,
    }
    return _dataset(out, config, attrs, reasons)
