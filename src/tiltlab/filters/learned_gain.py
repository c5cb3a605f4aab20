r"""Mahony's filter with a learned gain schedule (6D): gains from short sensor windows.

A tiny log-linear model maps causal features of the last 0.1–1 s of accelerometer and
gyroscope samples to the proportional and integral gains of
:func:`~tiltlab.filters.mahony` and to a third, rest-bias gain that pulls the gyro-bias
estimate towards the measured rate; the correction uses the specific force low-passed
in the world frame (VQF's device against linear accelerations). With all weights zero it *is* the parent filter
with its tuned fixed gains (:func:`~tiltlab.filters.mahony` itself when the rest-bias
gain is 0); :mod:`tiltlab.learn.gain_schedule` trains the weights by back-propagation
through the whole filter recursion. Weights trained on BROAD ship with the package:
``tiltlab/_weights/learned_gain/weights.json`` (with ``SHA256SUMS``; ``tools/train_learned_gain.py``
writes them).

The filter is 6D: the inclination (tilt) needs no magnetometer, and a magnetometer
correction would only add the magnetic disturbances of indoor recordings to it.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from .. import _validate as _v
from ..io.checksums import SUMS_FILE, file_sha256, read_sums, write_sums
from ._common import offset_vector, read_sensors, start_orientation
from ._docs import shared_docs
from ._shared_kernel import _attitude_step, _gravity_error, _unit_sample

__all__ = [
    "BROAD_WEIGHTS",
    "FEATURES",
    "GainWeights",
    "gain_features",
    "gain_schedule",
    "learned_gain",
    "load_gain_weights",
    "save_gain_weights",
]

#: format tag written into (and required in) every weights file
FORMAT = "tiltlab.learned_gain/1"
#: the name of the checksum file next to a weights file (``sha256sum`` format)
SUMS_NAME = SUMS_FILE
#: standard gravity used to make the accelerometer features unitless (m/s²)
G0 = 9.80665
#: the causal features: (raw signal, smoothing time constant in s, log offset)
#: ``acc_dev``: | ‖a‖ − g | / g; ``gyr``: ‖ω‖ (rad/s); ``jerk``: ‖a_k − a_{k−1}‖ fs / g (1/s)
FEATURES = (
    ("acc_dev", 0.1, 1e-3),
    ("acc_dev", 1.0, 1e-3),
    ("gyr", 0.1, 1e-2),
    ("gyr", 1.0, 1e-2),
    ("jerk", 0.1, 1e-1),
)
_RAW = {"acc_dev": 0, "gyr": 1, "jerk": 2}
#: ``weights="broad"``: the schedule trained on all 30 BROAD trials of the CNN folds
BROAD_WEIGHTS = (
    Path(__file__).resolve().parents[1] / "_weights" / "learned_gain" / "weights.json"
)
#: the schedule's log-gain s is clipped to this range (gains x0.00005 … x400)
S_RANGE = (-10.0, 6.0)


class GainWeights(NamedTuple):
    """The parameters of a learned gain schedule (see :func:`learned_gain`).

    Attributes
    ----------
    kp, ki, kb : float
        The parent's fixed gains: proportional (rad/s), integral (rad/s²) and
        rest-bias (1/s, see :func:`learned_gain`); the gains when the schedule is zero.
    tau_acc_s : float
        Time constant (s) of the world-frame low-pass of the specific force whose
        direction the filter corrects towards (0: the accelerometer sample itself,
        as :func:`~tiltlab.filters.mahony`).
    mean, std : numpy.ndarray, shape (F,)
        Standardisation of the :data:`FEATURES` (fitted on the training trials).
    w_p, w_i, w_b : numpy.ndarray, shape (F + 1,)
        Weights of the three log-gain schedules: bias first, then one per feature.
    meta : dict
        Free-form provenance (training trials, folds, losses); not used by the filter.
    """

    kp: float
    ki: float
    kb: float
    tau_acc_s: float
    mean: np.ndarray
    std: np.ndarray
    w_p: np.ndarray
    w_i: np.ndarray
    w_b: np.ndarray
    meta: dict

    @classmethod
    def parent(
        cls,
        kp: float,
        ki: float,
        kb: float = 0.0,
        tau_acc_s: float = 0.0,
        mean=None,
        std=None,
    ) -> GainWeights:
        """Return the zero schedule: the parent with fixed gains ``kp``, ``ki``, ``kb``.

        With ``kb = 0`` and ``tau_acc_s = 0`` it is :func:`~tiltlab.filters.mahony`
        (6D).

        Parameters
        ----------
        kp, ki, kb : float
            Fixed proportional (rad/s), integral (rad/s²) and rest-bias (1/s) gains.
        tau_acc_s : float
            World-frame low-pass time constant (s) of the specific force (0: none).
        mean, std : array_like, shape (F,), optional
            Feature standardisation (default 0 and 1).

        Returns
        -------
        GainWeights
            Weights whose schedule is zero everywhere.
        """
        f = len(FEATURES)
        return _checked_weights(
            kp,
            ki,
            kb,
            tau_acc_s,
            np.zeros(f) if mean is None else mean,
            np.ones(f) if std is None else std,
            np.zeros(f + 1),
            np.zeros(f + 1),
            np.zeros(f + 1),
            {},
        )


def _checked_weights(
    kp, ki, kb, tau_acc_s, mean, std, w_p, w_i, w_b, meta
) -> GainWeights:
    f = len(FEATURES)
    arrays = {}
    for name, a, n in (
        ("mean", mean, f),
        ("std", std, f),
        ("w_p", w_p, f + 1),
        ("w_i", w_i, f + 1),
        ("w_b", w_b, f + 1),
    ):
        x = np.array(a, dtype=float).reshape(-1)
        if x.shape != (n,):
            raise ValueError(f"gain weights: {name} must have {n} values, got {x.size}")
        if not np.all(np.isfinite(x)):
            raise ValueError(f"gain weights: {name} has non-finite values")
        arrays[name] = x
    if np.any(arrays["std"] <= 0):
        raise ValueError("gain weights: std must be positive")
    return GainWeights(
        _v.nonnegative(kp, "kp"),
        _v.nonnegative(ki, "ki"),
        _v.nonnegative(kb, "kb"),
        _v.nonnegative(tau_acc_s, "tau_acc_s"),
        arrays["mean"],
        arrays["std"],
        arrays["w_p"],
        arrays["w_i"],
        arrays["w_b"],
        dict(meta),
    )


def save_gain_weights(weights: GainWeights, path: str | os.PathLike) -> str:
    """Write ``weights`` as JSON and record its SHA-256 in the folder's ``SHA256SUMS``.

    Parameters
    ----------
    weights : GainWeights
        The schedule to save.
    path : str or os.PathLike
        The JSON file to write (its folder must exist).

    Returns
    -------
    str
        The file's SHA-256 (hex).
    """
    path = Path(path)
    doc = {
        "format": FORMAT,
        "features": [list(f) for f in FEATURES],
        "s_range": list(S_RANGE),
        "kp": float(weights.kp),
        "ki": float(weights.ki),
        "kb": float(weights.kb),
        "tau_acc_s": float(weights.tau_acc_s),
        "mean": weights.mean.tolist(),
        "std": weights.std.tolist(),
        "w_p": weights.w_p.tolist(),
        "w_i": weights.w_i.tolist(),
        "w_b": weights.w_b.tolist(),
        "meta": weights.meta,
    }
    path.write_text(json.dumps(doc, indent=1) + "\n")
    digest = file_sha256(path)
    sums = path.parent / SUMS_NAME
    listed = read_sums(sums) if sums.exists() else {}
    write_sums(path.parent, listed | {path.name: digest})
    return digest


def load_gain_weights(
    path: str | os.PathLike, sha256: str | None = None
) -> GainWeights:
    """Read a weights file, refusing it unless its SHA-256 matches the recorded one.

    Parameters
    ----------
    path : str or os.PathLike
        A JSON file written by :func:`save_gain_weights`.
    sha256 : str, optional
        The expected digest; default the file's line in ``SHA256SUMS`` in its folder.

    Returns
    -------
    GainWeights
        The verified weights.

    Raises
    ------
    ValueError
        If the file has no recorded checksum, its checksum differs, or its content
        is not a weights file of this format.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"gain weights file {str(path)!r} does not exist")
    if sha256 is None:
        sums = path.parent / SUMS_NAME
        if not sums.is_file():
            raise ValueError(
                f"gain weights {path.name!r}: no {SUMS_NAME} file next to it to verify "
                "its checksum (pass sha256=... or save it with save_gain_weights)"
            )
        found = read_sums(sums)
        if path.name not in found:
            raise ValueError(f"gain weights {path.name!r} is not listed in {sums}")
        sha256 = found[path.name]
    actual = file_sha256(path)
    if actual.lower() != str(sha256).lower():
        raise ValueError(
            f"gain weights {str(path)!r} fail their checksum: sha256 {actual}, expected "
            f"{sha256} (the file was changed or corrupted)"
        )
    doc = json.loads(path.read_text())
    if doc.get("format") != FORMAT:
        raise ValueError(
            f"gain weights {path.name!r}: format {doc.get('format')!r}, expected "
            f"{FORMAT!r}"
        )
    if [tuple(f) for f in doc.get("features", [])] != list(FEATURES):
        raise ValueError(f"gain weights {path.name!r} were trained on other features")
    return _checked_weights(
        doc["kp"],
        doc["ki"],
        doc["kb"],
        doc["tau_acc_s"],
        doc["mean"],
        doc["std"],
        doc["w_p"],
        doc["w_i"],
        doc["w_b"],
        doc.get("meta", {}),
    )


@njit(cache=True, nogil=True)
def _features_kernel(acc, gyr, fs, taus, kinds, offsets, out):
    # causal exponentially smoothed features, log(offset + EMA)
    n, f = acc.shape[0], taus.shape[0]
    ema = np.zeros(f)
    alpha = np.empty(f)
    for j in range(f):
        alpha[j] = 1.0 - np.exp(-1.0 / (fs * taus[j]))
    raw = np.empty(3)
    for k in range(n):
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        raw[0] = abs(np.sqrt(ax * ax + ay * ay + az * az) - G0) / G0
        gx, gy, gz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        raw[1] = np.sqrt(gx * gx + gy * gy + gz * gz)
        if k > 0:
            dx, dy, dz = ax - acc[k - 1, 0], ay - acc[k - 1, 1], az - acc[k - 1, 2]
            raw[2] = np.sqrt(dx * dx + dy * dy + dz * dz) * fs / G0
        else:
            raw[2] = 0.0
        for j in range(f):
            r = raw[kinds[j]]
            ema[j] = r if k == 0 else ema[j] + alpha[j] * (r - ema[j])
            out[k, j] = np.log(offsets[j] + ema[j])


def gain_features(acc: np.ndarray, gyr: np.ndarray, fs: float) -> np.ndarray:
    r"""Compute the causal features of the gain schedule (before standardisation).

    For each entry ``(signal, τ, ε)`` of :data:`FEATURES`:
    :math:`\phi_k = \log(\varepsilon + m_k)`, :math:`m_k = m_{k-1} + \alpha (r_k -
    m_{k-1})`, :math:`\alpha = 1 - e^{-1/(f_s\tau)}`, :math:`m_0 = r_0`, with ``r``
    one of :math:`|\,\|a\| - g\,|/g`, :math:`\|\omega\|` and
    :math:`\|a_k - a_{k-1}\|\,f_s/g`.

    Parameters
    ----------
    acc, gyr : numpy.ndarray, shape (N, 3)
        Accelerometer (m/s²) and gyroscope (rad/s) samples, already checked (see
        :func:`learned_gain`).
    fs : float
        Sampling rate (Hz).

    Returns
    -------
    numpy.ndarray, shape (N, F)
        The features, one column per entry of :data:`FEATURES`.
    """
    a = np.ascontiguousarray(acc, dtype=float)
    g = np.ascontiguousarray(gyr, dtype=float)
    out = np.empty((a.shape[0], len(FEATURES)))
    taus = np.array([f[1] for f in FEATURES])
    kinds = np.array([_RAW[f[0]] for f in FEATURES], dtype=np.int64)
    offsets = np.array([f[2] for f in FEATURES])
    _features_kernel(a, g, float(fs), taus, kinds, offsets, out)
    return out


def gain_schedule(features: np.ndarray, weights: GainWeights):
    r"""Return the per-sample gains and whether each log-gain was clipped.

    .. math::
        k_{j,k} = k_j\, e^{s_j(\tilde\phi_k)},\quad j \in \{P, I, B\},
        \quad s_j(\tilde\phi) = \mathrm{clip}(w_{j,0} + w_j^\top \tilde\phi),
        \quad \tilde\phi = (\phi - \mu)/\sigma

    Parameters
    ----------
    features : numpy.ndarray, shape (N, F)
        From :func:`gain_features`.
    weights : GainWeights
        The schedule.

    Returns
    -------
    tuple
        ``(gains, z, free)``: gains (3, N) (rows P, I, B), standardised features
        with a leading column of ones (N, F + 1), and a boolean (3, N) mask of the
        samples whose log-gain is not clipped.
    """
    z = np.empty((features.shape[0], features.shape[1] + 1))
    z[:, 0] = 1.0
    z[:, 1:] = (features - weights.mean) / weights.std
    s = np.stack([z @ weights.w_p, z @ weights.w_i, z @ weights.w_b])
    lo, hi = S_RANGE
    free = (s > lo) & (s < hi)
    k = np.array([weights.kp, weights.ki, weights.kb])[:, None]
    return k * np.exp(np.clip(s, lo, hi)), z, free


@njit(cache=True, nogil=True, inline="always")
def _rotation(w, x, y, z):
    # the rotation matrix R(q) (sensor -> world), row by row
    return (
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )


@njit(cache=True, nogil=True)
def _varying_mahony_kernel(acc, gyr, dt, alpha, gains, q0, b0, out, bias, facc):
    # Mahony's 6D step (as _mahony_kernel, same operations when alpha == 1) with
    # per-sample gains gains[0], gains[1] and the rest-bias pull gains[2] dt (ω - b);
    # alpha < 1: the error is taken against the world-frame low-passed specific force
    # f (stored in facc) instead of the accelerometer sample
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    bx_, by_, bz_ = b0[0], b0[1], b0[2]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    bias[0, 0], bias[0, 1], bias[0, 2] = bx_, by_, bz_
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = _rotation(w, x, y, z)
    ax, ay, az = acc[0, 0], acc[0, 1], acc[0, 2]
    fx = r00 * ax + r01 * ay + r02 * az
    fy = r10 * ax + r11 * ay + r12 * az
    fz = r20 * ax + r21 * ay + r22 * az
    facc[0, 0], facc[0, 1], facc[0, 2] = fx, fy, fz
    h = 0.5 * dt
    for k in range(1, acc.shape[0]):
        ox, oy, oz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        have = False
        ex, ey, ez = 0.0, 0.0, 0.0
        if alpha < 1.0:
            r00, r01, r02, r10, r11, r12, r20, r21, r22 = _rotation(w, x, y, z)
            ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
            fx += alpha * (r00 * ax + r01 * ay + r02 * az - fx)
            fy += alpha * (r10 * ax + r11 * ay + r12 * az - fy)
            fz += alpha * (r20 * ax + r21 * ay + r22 * az - fz)
            fn = np.sqrt(fx * fx + fy * fy + fz * fz)
            if fn > 0.0:
                # e = R^T (u × e_z), u = f / |f|
                cx, cy = fy / fn, -fx / fn
                ex = r00 * cx + r10 * cy
                ey = r01 * cx + r11 * cy
                ez = r02 * cx + r12 * cy
                have = True
        else:
            ax, ay, az, an = _unit_sample(acc, k)
            if an > 0.0:
                cx, cy, cz = _gravity_error(w, x, y, z, ax, ay, az)
                ex, ey, ez = 0.0 + cx, 0.0 + cy, 0.0 + cz  # as Mahony's ex += ...
                have = True
        if have:
            kp, ki, kb = gains[0, k], gains[1, k], gains[2, k]
            rx = kb * dt * (ox - bx_)
            ry = kb * dt * (oy - by_)
            rz = kb * dt * (oz - bz_)
            bx_ -= ki * ex * dt
            by_ -= ki * ey * dt
            bz_ -= ki * ez * dt
            bx_ += rx
            by_ += ry
            bz_ += rz
            ox = ox - bx_ + kp * ex
            oy = oy - by_ + kp * ey
            oz = oz - bz_ + kp * ez
        else:
            ox, oy, oz = ox - bx_, oy - by_, oz - bz_
        w, x, y, z = _attitude_step(w, x, y, z, ox, oy, oz, h)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
        bias[k, 0], bias[k, 1], bias[k, 2] = bx_, by_, bz_
        facc[k, 0], facc[k, 1], facc[k, 2] = fx, fy, fz


def smoothing_factor(tau_acc_s: float, fs: float) -> float:
    r"""Return the per-sample factor :math:`\alpha = 1 - e^{-1/(f_s\tau)}` (1 at τ = 0).

    Parameters
    ----------
    tau_acc_s : float
        Time constant (s) of the world-frame low-pass of the specific force.
    fs : float
        Sampling rate (Hz).

    Returns
    -------
    float
        The factor; 1 (no smoothing: Mahony's correction) for ``tau_acc_s = 0``.
    """
    return 1.0 if tau_acc_s == 0 else float(-np.expm1(-1.0 / (fs * tau_acc_s)))


def _read_weights(weights: Any) -> GainWeights:
    if isinstance(weights, GainWeights):
        return weights
    if weights is None:
        raise ValueError(
            "learned_gain needs weights: 'broad', a GainWeights or the path of a "
            "weights JSON file"
        )
    if isinstance(weights, str) and weights == "broad":
        if not BROAD_WEIGHTS.is_file():
            raise FileNotFoundError(
                f"weights='broad' reads {BROAD_WEIGHTS}, which this installation "
                "lacks (the package ships it as package data); pass a weights file"
            )
        return load_gain_weights(BROAD_WEIGHTS)
    if isinstance(weights, (str, os.PathLike)):
        return load_gain_weights(weights)
    raise TypeError(
        f"weights must be a GainWeights or a file path, got {type(weights).__name__}"
    )


@shared_docs
def learned_gain(
    acc,
    gyr,
    fs: float | None = None,
    *,
    weights: str = "broad",
    q0=None,
    gyr_offset=None,
    init_window_s: float = 0.1,
    return_bias: bool = False,
):
    r"""Mahony's 6D filter whose gains a learned model schedules from the sensors.

    The step of :func:`~tiltlab.filters.mahony` without magnetometer, with
    per-sample gains, a rest-bias term and, when ``tau_acc_s > 0``, the error taken
    against the specific force low-passed in the world frame (as VQF does [2]_):

    .. math::
        f_k = f_{k-1} + \alpha\,(R(q_{k-1})\, a_k - f_{k-1}),\quad
        e_k = R(q_{k-1})^\top \Big(\frac{f_k}{\|f_k\|} \times e_z\Big),

    .. math::
        b_k = b_{k-1} - k_{I,k}\, e_k\, \Delta t + k_{B,k}\,(\omega_k - b_{k-1})\,
        \Delta t,\quad
        \Omega_k = \omega_k - b_k + k_{P,k}\, e_k

    then :math:`q_k` as in :func:`~tiltlab.filters.mahony`, with
    :math:`\alpha = 1 - e^{-\Delta t/\tau}` (:func:`smoothing_factor`; with
    :math:`\tau = 0`, :math:`\alpha = 1` and :math:`e_k = \hat a_k \times
    R(q_{k-1})^\top e_z`, Mahony's error), :math:`f_0 = R(q_0) a_0`, and
    :math:`k_{j,k} = k_j e^{s_j}` (:math:`j = P, I, B`) from :func:`gain_schedule`
    of the causal :func:`gain_features` (short exponential windows of the
    accelerometer's deviation from 1 g, its change, and the turn rate). Linear
    accelerations average out of :math:`f` over a few seconds, since the velocity
    stays bounded. The rest-bias term pulls the bias towards the measured rate,
    which is the bias itself when the sensor rests: the schedule learns to open it
    at rest (it observes all three bias components, where the integral term sees
    only the two horizontal ones). Zero schedule weights give the fixed-gain
    parent; with ``kb = 0`` and ``tau_acc_s = 0`` that is exactly
    :func:`~tiltlab.filters.mahony` with ``kp``, ``ki``. The schedule is trained by
    back-propagation through the filter
    (:func:`tiltlab.learn.gain_schedule.train_schedule`), in the spirit of learned
    adaptive filter gains [1]_.

    Parameters
    ----------
    %(acc_gyr)s
    %(fs)s
    weights : str, os.PathLike or GainWeights
        ``"broad"`` (default: the schedule trained on BROAD, :data:`BROAD_WEIGHTS`),
        a weights file (verified against its ``SHA256SUMS``; see
        :func:`load_gain_weights`) or loaded weights.
    q0 : array_like, shape (4,), optional
        Initial orientation; default :func:`initial_orientation` over
        ``init_window_s`` seconds.
    gyr_offset : array_like, shape (3,), optional
        Initial gyroscope bias (rad/s); default zero.
    init_window_s : float
        Seconds of accelerometer used for the initial orientation.
    return_bias : bool
        Also return the bias estimate (N, 3).

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions sensor → world (heading arbitrary); with ``return_bias`` a
        tuple ``(q, b)``.

    Notes
    -----
    ``acc`` must be in m/s² (the features compare its norm with g). Fixed gains
    whose step would overshoot (``kp/fs > 2``, ``ki/fs² > 1``, ``kb/fs > 1``) are
    refused like :func:`mahony`'s; the scheduled gains are capped at those limits
    (which never bind for the BROAD weights at BROAD's 285.7 Hz, where they were
    trained).

    References
    ----------
    .. [1] M. Brossard, A. Barrau, S. Bonnabel, "AI-IMU dead-reckoning", IEEE Trans.
       Intell. Veh. 5(4):585–595, 2020. doi:10.1109/TIV.2020.2980758
       (a network adapting a Kalman filter's noise parameters from IMU windows).
    .. [2] D. Laidig, T. Seel, "VQF: Highly accurate IMU orientation estimation with
       bias estimation and magnetic disturbance rejection", Information Fusion
       91:187–204, 2023. doi:10.1016/j.inffus.2022.10.014

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab.filters import GainWeights, learned_gain, mahony
    >>> acc = np.tile([0.0, 0.0, 9.81], (200, 1)); gyr = np.zeros((200, 3))
    >>> q = learned_gain(acc, gyr, 100.0, weights=GainWeights.parent(1.0, 0.03))
    >>> bool(np.allclose(q, mahony(acc, gyr, 100.0, kp=1.0, ki=0.03)))
    True
    """
    fs, acc, gyr, _, _ = read_sensors(fs, acc, gyr, None, acc_si=True)
    w = _read_weights(weights)
    limit = np.array([2.0 * fs, fs**2, fs])
    fixed = np.array([w.kp, w.ki, w.kb])
    if np.any(fixed > limit):
        raise ValueError(
            f"the fixed gains kp = {w.kp:g}, ki = {w.ki:g}, kb = {w.kb:g} are too large "
            f"for fs = {fs:g} Hz: kp/fs, ki/fs², kb/fs must stay below 2, 1 and 1, or "
            "the filter overshoots and diverges"
        )
    gains = gain_schedule(gain_features(acc, gyr, fs), w)[0]
    gains = np.minimum(gains, limit[:, None])
    b0 = offset_vector(gyr_offset)
    q0 = start_orientation(q0, acc, None, fs, init_window_s)
    out = np.empty((acc.shape[0], 4))
    bias = np.empty((acc.shape[0], 3))
    alpha = smoothing_factor(w.tau_acc_s, fs)
    _varying_mahony_kernel(
        acc, gyr, 1.0 / fs, alpha, gains, q0, b0, out, bias, np.empty((len(acc), 3))
    )
    return (out, bias) if return_bias else out
