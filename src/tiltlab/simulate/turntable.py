r"""Back-and-forth rotations about one sensor axis (a robotic-arm accuracy test).

LaCanna (2018) [1]_ fixed a MetaWear C-Pro to the wrist of a robotic arm (Barrett WAM)
and rotated one joint, aligned with one sensor axis at a time, back and forth by one
radian, reading the integrated gyroscope angle after each rotation (his Table 5).
:func:`back_and_forth` generates the true motion of such a test: a still lead-in, then
``n_rotations`` cycles of a rotation by ``+amplitude`` and back, each move a
minimum-jerk profile

.. math:: \theta(u) = A\,(10u^3 - 15u^4 + 6u^5), \qquad u = t/D \in [0, 1],

whose peak rate :math:`1.875\,A/D` is ``peak_rate_deg_s``, separated by still holds.
The sensor starts level (z up); the accelerometer reads gravity in the rotating sensor
frame. Feed the result to :func:`tiltlab.simulate.apply_sensor_model`, or run the whole
test with :func:`radian_test`, which returns a table shaped like his Table 5.

References
----------
.. [1] C. Q. LaCanna, "Inertial measurement units for tracking human pose and motions:
   testing and calibration", MSc thesis, Rutgers University, 2018 (Methods, "Accuracy
   Testing with Robotic Arm"; Table 5).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

import pandas as pd

from .. import calibration as _cal
from .. import quaternion as _quat
from .sensor import SensorModel, apply_sensor_model

__all__ = ["TurntableMotion", "back_and_forth", "radian_test"]

_AXES = {"x": 0, "y": 1, "z": 2}


class TurntableMotion(NamedTuple):
    """Result of :func:`back_and_forth`.

    ``acc`` (N, 3) true specific force (g), ``gyr`` (N, 3) true angular velocity (°/s),
    ``q`` (N, 4) sensor → world quaternion, ``angle_rad`` (N,) rotation angle,
    ``holds`` (2 n_rotations + 1, 2) half-open sample intervals of the still holds (the
    last ``hold_s`` of the lead-in, then alternately rotated and back), ``fs`` (Hz).
    """

    acc: np.ndarray
    gyr: np.ndarray
    q: np.ndarray
    angle_rad: np.ndarray
    holds: np.ndarray
    fs: float


def back_and_forth(
    axis: str,
    fs: float,
    *,
    amplitude_rad: float = 1.0,
    n_rotations: int = 5,
    peak_rate_deg_s: float = 60.0,
    hold_s: float = 3.0,
    lead_s: float = 30.0,
) -> TurntableMotion:
    """Generate the true motion of repeated rotations by ``amplitude_rad`` and back.

    Parameters
    ----------
    axis : {"x", "y", "z"}
        Sensor axis of the rotation.
    fs : float
        Sampling rate (Hz).
    amplitude_rad : float
        Rotation of each move (rad), non-zero; LaCanna: 1 rad.
    n_rotations : int
        Number of out-and-back cycles (LaCanna's Table 5 lists five).
    peak_rate_deg_s : float
        Peak angular speed of each move (°/s).
    hold_s : float
        Still hold after each move (s).
    lead_s : float
        Still lead-in before the first move (s), e.g. to measure the drift.

    Returns
    -------
    TurntableMotion
        The true signals, the angle and the hold intervals.

    Examples
    --------
    >>> from tiltlab.simulate.turntable import back_and_forth
    >>> m = back_and_forth("x", 25.0, n_rotations=2)
    >>> m.holds.shape, round(float(m.angle_rad.max()), 6)
    ((5, 2), 1.0)
    """
    if axis not in _AXES:
        raise ValueError(f"axis must be one of 'x', 'y', 'z'; got {axis!r}")
    for name, v in [
        ("fs", fs),
        ("peak_rate_deg_s", peak_rate_deg_s),
        ("hold_s", hold_s),
        ("lead_s", lead_s),
    ]:
        if not np.isfinite(v) or v <= 0:
            raise ValueError(f"{name} must be a positive number, got {v!r}")
    if not np.isfinite(amplitude_rad) or amplitude_rad == 0:
        raise ValueError(
            f"amplitude_rad must be finite and non-zero, got {amplitude_rad!r}"
        )
    if int(n_rotations) != n_rotations or n_rotations < 1:
        raise ValueError(f"n_rotations must be a positive integer, got {n_rotations!r}")
    amp_deg = np.degrees(abs(amplitude_rad))
    move_s = 1.875 * amp_deg / peak_rate_deg_s
    n_lead, n_hold = int(round(lead_s * fs)), int(round(hold_s * fs))
    n_move = max(int(round(move_s * fs)), 2)
    u = np.arange(1, n_move + 1) / n_move  # the move ends exactly at the target
    shape = 10 * u**3 - 15 * u**4 + 6 * u**5
    dshape = 30 * u**2 * (1 - u) ** 2 * fs / n_move  # d(shape)/dt (1/s), exact
    first = (max(n_lead - n_hold, 0), n_lead)  # the end of the lead-in, like a hold
    pieces, holds, level, start = [np.zeros(n_lead)], [first], 0.0, n_lead
    rates = [np.zeros(n_lead)]
    for k in range(2 * int(n_rotations)):
        target = amplitude_rad if k % 2 == 0 else 0.0
        pieces += [level + (target - level) * shape, np.full(n_hold, target)]
        rates += [(target - level) * dshape, np.zeros(n_hold)]
        start += n_move
        holds.append((start, start + n_hold))
        start += n_hold
        level = target
    angle = np.concatenate(pieces)
    rate = np.concatenate(rates)  # rad/s, the analytic derivative at each sample
    i = _AXES[axis]
    gyr = np.zeros((angle.size, 3))
    gyr[:, i] = np.degrees(rate)
    q = np.zeros((angle.size, 4))
    q[:, 0], q[:, 1 + i] = np.cos(angle / 2), np.sin(angle / 2)
    acc = _quat.gravity(q)
    return TurntableMotion(
        acc, gyr, q, angle, np.array(holds, dtype=np.int64), float(fs)
    )


def radian_test(
    sensor: SensorModel | None,
    rng: np.random.Generator,
    fs: float,
    *,
    fs_assumed: float | None = None,
    drift: str = "first_window",
    prior_deg_s=None,
    **motion,
) -> pd.DataFrame:
    """Simulate LaCanna's 1-rad rotation test about each axis and read the changes.

    For each axis: :func:`back_and_forth` at ``fs``, measured through ``sensor``
    (:func:`~tiltlab.simulate.apply_sensor_model`), integrated with a sampling interval of
    ``1/fs_assumed`` and drift-corrected (:func:`tiltlab.calibration.correct_drift`;
    ``"first_window"`` uses the still lead-in), then the change of the rotated axis's
    angle from each rest hold to the next rotated hold
    (:func:`tiltlab.calibration.hold_changes`).

    Parameters
    ----------
    sensor : SensorModel or None
        Sensor errors (``None`` fields drawn per axis's run).
    rng : numpy.random.Generator
        Random source of the drawn errors and noise.
    fs : float
        True sampling rate (Hz).
    fs_assumed : float, optional
        Rate used to integrate (Hz); default ``fs``. A clock slower than its nominal rate
        (``fs < fs_assumed``) shrinks every angle by ``fs / fs_assumed``.
    drift : {"first_window", "prior", "none"}
        Drift removal; ``"first_window"`` fits the slope of the lead-in.
    prior_deg_s : array_like (3,), optional
        Drift rate (°/s) removed by ``"prior"``.
    **motion
        Options of :func:`back_and_forth` (``n_rotations``, ``peak_rate_deg_s``,
        ``hold_s``, ``lead_s``, ``amplitude_rad``).

    Returns
    -------
    pandas.DataFrame
        One row per rotation (index ``rotation`` from 1), columns ``x_deg``, ``y_deg``,
        ``z_deg``: the measured change (°) of the rotated axis, with ``units`` and
        ``long_name`` attrs (the layout of LaCanna's Table 5).
    """
    if drift not in ("first_window", "prior", "none"):
        raise ValueError(
            f"drift must be one of 'first_window', 'prior', 'none'; got {drift!r}"
        )
    f_int = fs if fs_assumed is None else float(fs_assumed)
    if not np.isfinite(f_int) or f_int <= 0:
        raise ValueError(
            f"fs_assumed must be a positive number of Hz, got {fs_assumed!r}"
        )
    cols = {}
    for i, axis in enumerate("xyz"):
        m = back_and_forth(axis, fs, **motion)
        meas = apply_sensor_model({"acc": m.acc, "gyr": m.gyr}, sensor, rng, fs)["gyr"]
        lead_s = m.holds[0, 1] / f_int  # the whole still lead-in
        kw = {"window_s": lead_s} if drift == "first_window" else {}
        if drift == "prior":
            kw = {"prior_deg_s": prior_deg_s}
        c = _cal.correct_drift(meas, f_int, method=drift, **kw)
        cols[f"{axis}_deg"] = _cal.hold_changes(c.angle, f_int, holds=m.holds)[0::2, i]
    df = pd.DataFrame(
        cols, index=pd.RangeIndex(1, len(cols["x_deg"]) + 1, name="rotation")
    )
    df.attrs = {
        "title": "simulated 1-rad rotation test",
        "units": {k: "deg" for k in cols},
        "long_name": {k: f"angle change after a rotation about {k[0]}" for k in cols},
    }
    return df
