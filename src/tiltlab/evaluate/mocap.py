r"""Reference head tilt from motion capture, in the IMU frame (Fayat et al. 2021, §2.6)."""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = ["mocap_reference"]


def mocap_reference(
    rec: xr.Dataset,
    mocap: xr.Dataset,
    *,
    threshold_deg_s: float | str = 12.0,
    gyr_offset=None,
    drop_fraction: float = 0.02,
    cutoff_hz: float = 2.0,
) -> xr.Dataset:
    r"""Compute the reference head tilt from motion-capture markers, in the IMU frame (Fayat §2.6).

    The pipeline: (1) TTL synchronisation: the IMU samples flagged ``sync`` carry the
    video TTLs emitted every ``ttl_every`` frames; clock slips are repaired
    (:func:`tiltlab.calibration.repair_ttl_slips`) to get one mocap frame per IMU
    sample; (2) marker quality control: the frames with the ``drop_fraction`` largest
    deviations of the marker-1–2 distance from its median are dropped
    (:func:`tiltlab.calibration.marker_distance_qc`); (3) head frame from markers 1–3
    and tilt :math:`z^h = R_h^\top e_z` (:func:`tiltlab.calibration.tilt_from_markers`);
    (4) immobility from the angular speed (:func:`tiltlab.behavior.immobility`, Fayat
    §2.9); (5) the IMU→head rotation :math:`R` by Kabsch alignment of the normalised
    low-passed (``cutoff_hz``) acceleration with :math:`z^h` during immobility
    (:func:`tiltlab.calibration.imu_to_head_alignment`); (6) the reference in the IMU
    frame :math:`g^{ref} = R^\top z^h`.

    Parameters
    ----------
    rec : xarray.Dataset
        IMU Recording with a boolean ``sync`` variable (TTL-bearing samples); already
        offset-corrected if offsets are to be corrected.
    mocap : xarray.Dataset
        Markers (``markers`` (frame, marker, axis), boolean ``ttl``; attr ``ttl_every``),
        as from :func:`tiltlab.simulate.simulate_mocap_session`.
    threshold_deg_s : float or "auto"
        Immobility threshold (°/s), see :func:`tiltlab.behavior.immobility`.
    gyr_offset : array_like (3,), optional
        Gyroscope offset (units of ``rec.gyr``) for the immobility detection.
    drop_fraction : float
        Fraction of the valid mocap frames dropped by the marker-distance quality
        control, in [0, 1) (default 0.02, 2 %), see
        :func:`tiltlab.calibration.marker_distance_qc`.
    cutoff_hz : float
        Low-pass cut-off (Hz) of the acceleration used for the IMU→head alignment
        (default 2 Hz, as in Fayat et al.), see
        :func:`tiltlab.calibration.imu_to_head_alignment`.

    Returns
    -------
    xarray.Dataset
        ``rec`` restricted to the synchronised span, with ``tilt_ref`` (time, axis; NaN
        where QC dropped the frame), ``immobile`` (time) and attrs ``qc_dropped``,
        ``optical_tilt_uncertainty_deg``, ``kabsch_rms_deg``, ``n_clock_slips``.
    """
    from .. import behavior
    from .. import calibration as cal

    for v in ("sync", "acc", "gyr"):
        if v not in rec:
            raise ValueError(f"rec needs a {v!r} variable")
    if "markers" not in mocap or "ttl" not in mocap:
        raise ValueError("mocap needs 'markers' and 'ttl' variables")
    cycle = int(mocap.attrs.get("ttl_every", 0))
    if cycle < 1:
        raise ValueError("mocap has no valid 'ttl_every' attribute")
    ttl_imu = np.flatnonzero(rec["sync"].values.astype(bool))
    ttl_frames = np.flatnonzero(mocap["ttl"].values.astype(bool))
    if ttl_frames.size == 0:
        raise ValueError("mocap has no TTL frame")
    n = min(ttl_imu.size, ttl_frames.size)
    rep = cal.repair_ttl_slips(
        mocap["markers"].transpose("frame", "marker", "axis").values,
        ttl_imu[:n],
        cycle=cycle,
        first_frame=int(ttl_frames[0]),
    )
    out = rec.isel(time=rep.imu_index)
    p1, p2, p3 = rep.mocap[:, 0], rep.mocap[:, 1], rep.mocap[:, 2]
    qc = cal.marker_distance_qc(p1, p2, drop_fraction=drop_fraction)
    tilt_head = cal.tilt_from_markers(p1, p2, p3)
    tilt_head[~qc.keep] = np.nan
    im = behavior.immobility(
        out, threshold_deg_s=threshold_deg_s, gyr_offset=gyr_offset
    )
    acc = out["acc"].transpose("time", "axis").values
    al = cal.imu_to_head_alignment(
        acc, tilt_head, float(rec.attrs["fs"]), still=im.values, cutoff_hz=cutoff_hz
    )
    g_imu = tilt_head @ al.matrix  # R^T z for each row z
    out = out.assign(
        tilt_ref=(
            ("time", "axis"),
            g_imu,
            {
                "units": "1",
                "frame": "sensor",
                "long_name": "reference gravity-up direction from motion capture",
            },
        ),
        immobile=im,
    )
    out.attrs.update(
        {
            "qc_dropped": int((~qc.keep).sum()),
            "optical_tilt_uncertainty_deg": qc.tilt_uncertainty_deg,
            "kabsch_rms_deg": al.rms_deg,
            "n_clock_slips": int(rep.n_duplicated + rep.n_deleted),
            "immobility_threshold_deg_s": float(im.attrs["threshold_deg_s"]),
        }
    )
    return out
