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

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
.. [2] S. Benhamou, arXiv:2310.05820, 2023. doi:10.48550/arXiv.2310.05820
"""

from __future__ import annotations

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

__all__ = ["feature_specs", "session_features", "empty_features"]


def _tag(x: float) -> str:
    return f"{x:g}".replace(".", "p").replace("-", "m")


def feature_specs(config: FeatureConfig | None = None) -> dict[str, tuple[str, str]]:
    """Feature names → (units, long_name), in output order, for a configuration."""
    c = config or FeatureConfig()
    thr = f"{c.threshold_deg_s:g} deg/s"
    spec = {
        "n_samples": ("1", "number of samples analysed"),
        "duration_s": ("s", "duration of the recording"),
        "gyr_offset_x": ("deg/s", "gyroscope offset removed, x (session estimate)"),
        "gyr_offset_y": ("deg/s", "gyroscope offset removed, y (session estimate)"),
        "gyr_offset_z": ("deg/s", "gyroscope offset removed, z (session estimate)"),
        "immobile_fraction": (
            "1",
            f"fraction of time immobile (angular speed < {thr}, gaps < "
            f"{c.merge_gap_s:g} s merged, periods < {c.min_duration_s:g} s dropped)",
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
        "tilt_immobile_x": ("1", "vMF mean tilt during immobility, x (nose)"),
        "tilt_immobile_y": ("1", "vMF mean tilt during immobility, y (left)"),
        "tilt_immobile_z": ("1", "vMF mean tilt during immobility, z (up)"),
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


def _dataset(values: dict[str, float], config: FeatureConfig, attrs=None) -> xr.Dataset:
    spec = feature_specs(config)
    data = {
        k: ((), np.float64(values.get(k, np.nan)), {"units": u, "long_name": ln})
        for k, (u, ln) in spec.items()
    }
    a = {
        "feature_config": config.to_json(),
        "config_hash": config.hash(),
        "tiltlab_version": __version__,
        **dict(attrs or {}),
    }
    return xr.Dataset(data, attrs=a)


def empty_features(config: FeatureConfig | None = None) -> xr.Dataset:
    """The feature Dataset of a configuration with every value NaN (a failed session)."""
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


def _corrected(rec: xr.Dataset, config: FeatureConfig, calibration):
    """Calibrated Recording and the session gyro offset removed (°/s)."""
    stacked = False
    if calibration is not None:
        cal = _tumble(calibration, config)
        rec = _calibration.calibrate(rec, cal)
        stacked = "gyr_offset" in cal.corrects()
    off = np.zeros(3)
    if config.gyr_offset == "auto":
        raw = np.asarray(_calibration.robust_gyro_offset(rec), float)
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


def _tilt(rec: xr.Dataset, config: FeatureConfig) -> xr.DataArray:
    """Gravity-up direction of a corrected Recording with the configured method."""
    q = _filters.estimate(
        rec, config.method, use_mag=config.use_mag, **config.method_params
    )
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

    Returns
    -------
    xarray.Dataset
        0-d variables named by :func:`feature_specs`, each with ``units`` and a
        one-line ``long_name``; attrs ``feature_config`` (the configuration's JSON),
        ``config_hash``, ``tiltlab_version``, ``source``. A feature that is undefined
        for this session (no immobility, no movement, a unimodal speed distribution)
        is NaN and the reason is listed in ``attrs["notes"]``.

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
    _schema.validate(recording, allow_nan=True)
    for v in ("acc", "gyr"):
        if not np.isfinite(recording[v].values).all():
            raise RecordingError(f"the Recording's {v!r} has non-finite samples")
    rec, off = _corrected(recording, config, calibration)
    fs = float(rec.attrs["fs"])
    n = rec.sizes["time"]
    if n < 2 * fs:
        raise RecordingError(
            f"the recording is too short for the features ({n} samples, {n / fs:.2f} s;"
            " at least 2 s needed)"
        )
    notes: list[str] = []
    out: dict[str, float] = {"n_samples": n, "duration_s": n / fs}
    out.update({f"gyr_offset_{a}": float(o) for a, o in zip("xyz", off)})

    g = _tilt(rec, config)
    gv = g.values
    speed = _behavior.angular_speed(rec)
    sp = np.asarray(speed, float)
    imm = _immobile(speed, config, config.threshold_deg_s)
    moving = ~imm
    out["immobile_fraction"] = float(imm.mean())
    if config.auto_threshold:
        try:
            thr = _behavior.valley_threshold(speed)
        except ValueError as exc:
            notes.append(f"immobility_threshold_auto: {exc}")
        else:
            out["immobility_threshold_auto"] = float(thr)
            out["immobile_fraction_auto"] = float(_immobile(speed, config, thr).mean())

    mesh = _sphere.sphere_mesh(config.mesh_n)
    for key, mask in (("visited_fraction", None), ("visited_fraction_moving", moving)):
        if mask is not None and not mask.any():
            notes.append(f"{key}: no moving samples")
            continue
        tmap = _sphere.tilt_map(g, mesh=mesh, mask=mask)
        out[key] = _sphere.visited_fraction(
            tmap, mesh, min_count=config.visited_min_count, by="area"
        )

    if imm.sum() >= 2:
        fit = _sphere.vmf_fit(gv[imm])
        out.update({f"tilt_immobile_{a}": float(m) for a, m in zip("xyz", fit.mu)})
        out["tilt_immobile_kappa"] = float(fit.kappa)
        out["tilt_immobile_sagittal_deg"] = float(
            np.degrees(_sphere.sagittal_angle(fit.mu, config.lesion_side))
        )
    else:
        notes.append("tilt_immobile_*: fewer than 2 immobile samples")

    if moving.any():
        out["circling_index"] = _behavior.circling_index(rec, g, moving=moving)
        for q in config.speed_quantiles:
            key = f"angular_speed_moving_q{_tag(100 * q)}"
            out[key] = float(np.quantile(sp[moving], q))
    else:
        notes.append("circling_index, angular_speed_moving_*: no moving samples")

    to_g = _units.conversion_factor(rec["acc"].attrs["units"], "g")
    out["dba_mean"] = float(
        np.mean(_behavior.dba(rec, window_s=config.dba_window_s)) * to_g
    )
    out["odba_mean"] = float(
        np.mean(_behavior.odba(rec, window_s=config.dba_window_s)) * to_g
    )
    gz = np.clip(gv[:, 2] / np.linalg.norm(gv, axis=1), -1.0, 1.0)
    tilt_deg = np.degrees(np.arccos(gz))
    for t in config.tilt_thresholds_deg:
        out[f"tilted_fraction_{_tag(t)}deg"] = float(np.mean(tilt_deg > t))

    attrs = {"source": str(recording.attrs.get("source", ""))}
    if notes:
        attrs["notes"] = "; ".join(notes)
    return _dataset(out, config, attrs)
