r"""Tumble tests: static orientations of an IMU relative to gravity.

Fayat et al. [1]_ (App. A.1) orient the sensor with a two-axis (pitch, roll) stage so
that gravity visits the points of a spherical Fibonacci lattice,

.. math:: g_i = (\cos\theta_i \sin\phi_i,\ \sin\theta_i\sin\phi_i,\ \cos\phi_i),\quad
          \phi_i = \arccos\!\Big(1 - \frac{2i+1}{N}\Big),\quad \theta_i = \frac{2\pi i}{\Phi},

with :math:`\Phi = (1+\sqrt5)/2`, holding each orientation for 1.2 s and emitting a
trigger at the onset of each rotation (the 400 ms before a trigger are static).
With the stage :math:`R = R_y(\beta)\,R_x(\gamma)` (pitch about the fixed axis, then
roll about the sensor x axis) the tilt is
:math:`g = R^\top e_z = (-\sin\beta,\ \sin\gamma\cos\beta,\ \cos\gamma\cos\beta)`, so
:math:`\beta = -\arcsin g_x` and :math:`\gamma = \operatorname{atan2}(g_y, g_z)`.

The simulated gyroscope is the zero-order-hold angular velocity
:math:`\omega_k = f_s\,\mathrm{Log}(q_k^{*} \otimes q_{k+1})`, so that integrating it
reproduces the stage orientation exactly.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
"""

from __future__ import annotations


import numpy as np
import xarray as xr

from .. import quaternion as _quat
from ..frames import fibonacci_lattice, stage_angles, stage_quaternion
from .sensor import SensorModel, apply_sensor_model, true_sensor_values
from .. import schema as _schema

__all__ = ["stage_angles", "stage_quaternion", "tumble_test", "zoh_angular_velocity"]


def zoh_angular_velocity(q, fs: float) -> np.ndarray:
    r"""Compute the angular velocity whose zero-order-hold integral is ``q``.

    Angular velocity (rad/s, sensor frame) whose zero-order-hold integral is ``q``:
    :math:`\omega_k = f_s\,\mathrm{Log}(q_k^* \otimes q_{k+1})`, last sample 0.

    Parameters
    ----------
    q : array_like (N, 4)
        Unit quaternions (w, x, y, z), sensor to world, one per sample.
    fs : float
        Sampling rate (Hz).

    Returns
    -------
    numpy.ndarray (N, 3)
        Angular velocity (rad/s) in the sensor frame; the last row is 0.
    """
    q = np.asarray(q, float)
    w = np.zeros((q.shape[0], 3))
    if q.shape[0] > 1:
        w[:-1] = _quat.to_rotvec(_quat.mul(_quat.conj(q[:-1]), q[1:])) * fs
    return w


def _min_jerk(n: int) -> np.ndarray:
    # samples 0 .. n-1 of a minimum-jerk profile from 0 to 1; the hold that follows is at 1
    s = np.arange(n) / n
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def tumble_test(
    n_orientations: int = 50,
    fs: float = 300.0,
    *,
    seed: int | np.random.SeedSequence | None,
    kind: str = "fibonacci",
    hold_s: float | None = None,
    move_s: float | None = None,
    sensor: SensorModel | None = None,
    orientation_error_deg: float | None = None,
) -> xr.Dataset:
    """Simulate a tumble test recording.

    Parameters
    ----------
    n_orientations : int
        Number of lattice orientations (``kind="fibonacci"``; ignored for ``"three_point"``).
    fs : float
        Sampling rate (Hz).
    seed : int, SeedSequence or None
        Same seed → bit-identical Recording; ``None`` draws fresh entropy.
    kind : {"fibonacci", "three_point"}
        Motorised stage visiting a Fibonacci lattice (Fayat App. A.1: 1.2 s holds, pitch
        then roll moves), or a hand-made test with the z, x then y axis up (3 s holds,
        orientation errors of a few degrees).
    hold_s, move_s : float, optional
        Hold duration and duration of each stage move (defaults 1.2 / 0.4 s for the
        stage, 3.0 / 1.5 s by hand).
    sensor : SensorModel, optional
        Sensor errors; default every error drawn (:func:`draw_sensor`).
    orientation_error_deg : float, optional
        Standard deviation of the error of each achieved orientation (default 0 for the
        stage, 3° by hand).

    Returns
    -------
    xarray.Dataset
        A Recording with ``q_ref``, ``trigger`` (True at each rotation onset, including
        a final return to the start), ``orientation`` (index of the orientation held,
        −1 at the start position and while moving), attrs ``targets`` (the intended
        gravity directions) and the sensor's ``true_*`` errors.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import simulate
    >>> rec = simulate.tumble_test(8, 50.0, seed=2)
    >>> rec.sizes["time"], int(rec["trigger"].sum())  # 8 orientations and the return
    (960, 9)
    >>> np.round(rec.attrs["true_acc_offset"], 3).tolist()  # g
    [-0.005, -0.042, -0.036]
    """
    if kind not in ("fibonacci", "three_point"):
        raise ValueError(f"kind must be 'fibonacci' or 'three_point', got {kind!r}")
    if fs is None or not np.isfinite(fs) or fs <= 0:
        raise ValueError(f"fs must be a positive number of Hz, got {fs!r}")
    rng = np.random.default_rng(seed)
    if kind == "fibonacci":
        targets = fibonacci_lattice(n_orientations)
        hold_s = 1.2 if hold_s is None else hold_s
        move_s = 0.4 if move_s is None else move_s
        err = 0.0 if orientation_error_deg is None else orientation_error_deg
    else:
        targets = np.eye(3)[[2, 0, 1]]
        hold_s = 3.0 if hold_s is None else hold_s
        move_s = 1.5 if move_s is None else move_s
        err = 3.0 if orientation_error_deg is None else orientation_error_deg
    if hold_s <= 0 or move_s <= 0:
        raise ValueError("hold_s and move_s must be positive")
    beta, gamma = stage_angles(targets)
    if err > 0:
        beta = beta + np.radians(err) * rng.standard_normal(beta.shape)
        gamma = gamma + np.radians(err) * rng.standard_normal(gamma.shape)
    n_hold = max(1, int(round(hold_s * fs)))
    n_move = max(1, int(round(move_s * fs)))
    b_seq, g_seq, idx_seq, trig = (
        [np.zeros(n_hold)],
        [np.zeros(n_hold)],
        [np.full(n_hold, -1)],
        [],
    )
    pos = n_hold
    cur_b, cur_g = 0.0, 0.0
    for i, (b, g) in enumerate(list(zip(beta, gamma)) + [(0.0, 0.0)]):
        trig.append(pos)
        s = _min_jerk(n_move)
        b_seq += [cur_b + (b - cur_b) * s, np.full(n_move, b)]
        g_seq += [np.full(n_move, cur_g), cur_g + (g - cur_g) * s]
        idx_seq += [np.full(2 * n_move, -1)]
        last = i == len(beta)
        b_seq.append(np.full(n_hold, b))
        g_seq.append(np.full(n_hold, g))
        idx_seq.append(np.full(n_hold, -1 if last else i))
        pos += 2 * n_move + n_hold
        cur_b, cur_g = b, g
    bb, gg = np.concatenate(b_seq), np.concatenate(g_seq)
    q = stage_quaternion(bb, gg)
    omega = zoh_angular_velocity(q, fs)
    n = q.shape[0]
    trigger = np.zeros(n, bool)
    trigger[trig] = True
    acc_true = true_sensor_values(q, np.zeros((n, 3)))
    meas = apply_sensor_model(
        {"acc": acc_true, "gyr": np.degrees(omega), "q": q}, sensor, rng, fs
    )
    extra = {
        "trigger": (
            ("time",),
            trigger,
            {"long_name": "digital trigger at each rotation onset"},
        ),
        "orientation": (
            ("time",),
            np.concatenate(idx_seq).astype(np.int16),
            {
                "long_name": "index of the orientation held (-1: start position or moving)"
            },
        ),
        "acc_true": (("time", "axis"), acc_true, {"units": "g", "frame": "sensor"}),
        "gyr_true": (
            ("time", "axis"),
            np.degrees(omega),
            {"units": "deg/s", "frame": "sensor"},
        ),
    }
    attrs = {
        "source": "tiltlab.simulate.tumble_test",
        "sensor": "simulated MPU-9250-like IMU",
        "subject": "tumble test",
        "session": kind,
        "simulated": 1,
        "tumble_kind": kind,
        "hold_s": float(hold_s),
        "move_s": float(move_s),
        "targets": targets.tolist(),
        "achieved_tilt": _quat.gravity(stage_quaternion(beta, gamma)).tolist(),
        "sensor_model": meas["sensor"].to_dict(),
        **meas["truth"],
    }
    return _schema.make_recording(
        meas["acc"],
        meas["gyr"],
        fs,
        mag=meas.get("mag"),
        temp=meas["temp"],
        q_ref=q,
        extra=extra,
        attrs=attrs,
        acc_units="g",
        gyr_units="deg/s",
        mag_units="uT",
        temp_units="degC",
    )
