"""A simulated motion-capture study: rats with their own sensor, tumble test and session.

Fayat et al. (2021, §2.5–2.6) calibrate each rat's IMU with a tumble test and then record
it with concurrent motion capture. :func:`mocap_study` simulates that protocol for
several rats: per rat a sensor with its own errors (:func:`~tiltlab.simulate.draw_sensor`),
its tumble test (:func:`~tiltlab.simulate.tumble_test`) and the calibration estimated
from it (:func:`tiltlab.calibration.tumble_calibration`), and a session with markers
(:func:`~tiltlab.simulate.simulate_mocap_session`), calibrated as a lab would. The
optical reference is then computed from the markers by
:func:`tiltlab.evaluate.mocap_reference`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import xarray as xr

from .. import calibration as _calibration
from .mocap import simulate_mocap_session
from .sensor import SensorModel, draw_sensor
from .tumble import tumble_test

__all__ = ["MocapRat", "mocap_study"]


class MocapRat(NamedTuple):
    """One simulated rat of :func:`mocap_study`.

    Attributes
    ----------
    recording : xarray.Dataset
        The session's IMU Recording, calibrated by the rat's tumble test.
    mocap : xarray.Dataset
        The session's markers (:func:`~tiltlab.simulate.mocap_markers`).
    raw : xarray.Dataset
        The same Recording as recorded, before calibration.
    calibration : tiltlab.calibration.Calibration
        The calibration estimated from the rat's tumble test.
    sensor : SensorModel
        The rat's sensor, with its drawn errors (the truth the calibration estimates).
    """

    recording: xr.Dataset
    mocap: xr.Dataset
    raw: xr.Dataset
    calibration: object
    sensor: SensorModel


def mocap_study(
    rats: int | Sequence[int],
    duration_s: float,
    fs: float = 300.0,
    *,
    seed: int,
    sensor_model: SensorModel | None = None,
    n_tumble: int = 50,
) -> dict[int, MocapRat]:
    """Simulate rats with a tumble-test calibration and a motion-capture session each.

    Rat ``i``'s random draws come from the seeds ``[seed, i]`` (its sensor),
    ``[seed, i, 1]`` (its tumble test) and ``[seed, i, 2]`` (its session), so a rat is
    the same whichever other rats are simulated with it.

    Parameters
    ----------
    rats : int or sequence of int
        How many rats (numbered from 0), or their numbers.
    duration_s : float
        Length of each session (s).
    fs : float
        IMU sampling rate of the sessions and the tumble tests (Hz).
    seed : int
        Seed of the study.
    sensor_model : SensorModel, optional
        The sensors' given errors (e.g. a magnetometer taken as calibrated); the
        ``None`` ones are drawn per rat. Default ``SensorModel()``.
    n_tumble : int
        Orientations of each tumble test.

    Returns
    -------
    dict of int to MocapRat
        Rat number → its calibrated and raw Recordings, markers, calibration and sensor.

    Raises
    ------
    ValueError
        No rat, a negative or repeated rat number, or ``n_tumble`` below 6.

    Examples
    --------
    >>> from tiltlab import evaluate, simulate
    >>> study = simulate.mocap_study(1, 60.0, 100.0, seed=0, n_tumble=12)
    >>> rat = study[0]
    >>> ref = evaluate.mocap_reference(rat.recording, rat.mocap)
    >>> sorted(v for v in ("acc", "gyr", "tilt_ref") if v in ref)
    ['acc', 'gyr', 'tilt_ref']
    """
    ids = list(range(int(rats))) if np.ndim(rats) == 0 else [int(r) for r in rats]
    if not ids:
        raise ValueError("rats: no rat to simulate")
    if min(ids) < 0 or len(set(ids)) != len(ids):
        raise ValueError(f"rats must be distinct non-negative numbers, got {ids}")
    if int(n_tumble) < 6:
        raise ValueError(f"n_tumble must be at least 6 orientations, got {n_tumble}")
    study = {}
    for i in ids:
        sensor = draw_sensor(sensor_model, np.random.default_rng([seed, i]))
        tumble = tumble_test(int(n_tumble), fs, seed=[seed, i, 1], sensor=sensor)
        cal = _calibration.tumble_calibration(tumble).calibration
        raw, mocap = simulate_mocap_session(
            duration_s, fs, seed=[seed, i, 2], sensor=sensor
        )
        study[i] = MocapRat(_calibration.calibrate(raw, cal), mocap, raw, cal, sensor)
    return study
