r"""Inertial sensor model and simulated freely-moving sessions.

A measured 3-axis signal is modelled as

.. math:: y_k = \mathrm{Q}\Big(\mathrm{sat}\big(S\,M\,x_k + o(T_k) + b_k + n_k\big)\Big),

with :math:`x_k` the true value (specific force in g or angular velocity in °/s,
sensor frame), :math:`S = I + \mathrm{diag}(s)` the scale-factor errors,
:math:`M = I + E` a small misalignment / cross-axis matrix, :math:`o(T) = o_{ref} +
c\,(T - T_{ref})` the offset at temperature :math:`T`, :math:`b_k` a bias random walk
(:math:`b_{k+1} = b_k + \sigma_b\sqrt{\Delta t}\,\xi_k`), :math:`n_k` white noise of
standard deviation :math:`N\sqrt{f_s/2}` for a noise density :math:`N`,
:math:`\mathrm{sat}` the full-scale clipping and :math:`\mathrm{Q}` 16-bit
quantisation. The magnetometer adds hard-iron (offset) and soft-iron (matrix)
distortions to the local field :math:`m_w = B(0, \cos I, -\sin I)` (ENU, dip angle
:math:`I`, declination 0).

Defaults follow the MPU-9250 datasheet (noise densities 300 µg/√Hz and
0.01 °/s/√Hz, sensitivity tolerance ±3 %, cross-axis ±2 %) and the offset ranges
measured by Fayat et al. [1]_ (5–95th percentiles −0.1…0.07 g and −22.6…10.5 °/s at
29–33 °C), who also found offsets sensitive to temperature.

References
----------
.. [1] R. Fayat et al., "Inertial measurement of head tilt in rodents: principles and
   applications to vestibular research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
.. [2] InvenSense, "MPU-9250 Product Specification", PS-MPU-9250A-01 rev. 1.1, 2016.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import NamedTuple

import numpy as np
import xarray as xr

from .. import quaternion as _quat
from .. import schema as _schema
from ..units import G0
from ._sensor_kernel import measure_kernel
from .kinematics import STATES, BehaviourParams, Lesion, TrueMotion, head_kinematics

__all__ = [
    "magnetometer_readings",
    "SensorModel",
    "apply_sensor_model",
    "simulate_session",
    "recording_from_motion",
    "true_sensor_values",
    "draw_sensor",
    "ACC_OFFSET_RANGE_G",
    "GYR_OFFSET_RANGE_DPS",
]

#: 5th–95th percentile of accelerometer offsets (g) in Fayat et al. 2021, §3.1.
ACC_OFFSET_RANGE_G: tuple[float, float] = (-0.1, 0.07)
#: 5th–95th percentile of gyroscope offsets (°/s) in Fayat et al. 2021, §3.1.
GYR_OFFSET_RANGE_DPS: tuple[float, float] = (-22.6, 10.5)
_Z95 = 1.6448536269514722


def _vec(v, name, shape=(3,)):
    if v is None:
        return None
    a = np.asarray(v, float)
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {a.shape}")
    return a


@dataclass(frozen=True)
class SensorModel:
    """Errors of a 6- or 9-axis MEMS IMU.

    Any error field left ``None`` is drawn per recording by :func:`draw_sensor` from
    the distributions described in the module docstring; give a value to fix it.
    Units: accelerometer g, gyroscope °/s, magnetometer µT, temperature °C.

    Parameters
    ----------
    acc_offset, gyr_offset : 3 floats, optional
        Offsets at ``temp_ref``.
    acc_scale, gyr_scale : 3 floats, optional
        Relative scale-factor errors ``s`` (``S = I + diag(s)``).
    acc_misalign, gyr_misalign : 3×3, optional
        Misalignment / cross-axis matrix ``E`` (``M = I + E``, zero diagonal).
    acc_temp_coef, gyr_temp_coef : 3 floats, optional
        Offset temperature coefficients (per °C).
    acc_noise_density, gyr_noise_density : float
        White-noise densities (g/√Hz, °/s/√Hz).
    acc_bias_walk, gyr_bias_walk : float
        Bias random-walk intensities (g/√s, °/s/√s).
    acc_range, gyr_range : float
        Full scale (± g, ± °/s); values are clipped there.
    quantize : bool
        Round to 16-bit steps of ``2 range / 2**16``.
    temp_start, temp_end, temp_tau_s, temp_ref : float, optional
        Sensor temperature warms from ``temp_start`` to ``temp_end`` with time constant
        ``temp_tau_s``; offsets are given at ``temp_ref``.
    magnetometer : bool
        Also simulate a magnetometer.
    field_uT, dip_deg : float
        Local magnetic field strength and dip (inclination) angle.
    mag_hard_iron : 3 floats, optional ; mag_soft_iron : 3×3, optional
        Hard-iron offset (µT) and soft-iron matrix.
    mag_noise_uT : float
        Magnetometer white-noise standard deviation.
    """

    acc_offset: tuple | None = None
    gyr_offset: tuple | None = None
    acc_scale: tuple | None = None
    gyr_scale: tuple | None = None
    acc_misalign: tuple | None = None
    gyr_misalign: tuple | None = None
    acc_temp_coef: tuple | None = None
    gyr_temp_coef: tuple | None = None
    acc_noise_density: float = 300e-6
    gyr_noise_density: float = 0.01
    acc_bias_walk: float = 2e-5
    gyr_bias_walk: float = 2e-3
    acc_range: float = 16.0
    gyr_range: float = 2000.0
    quantize: bool = True
    temp_start: float | None = None
    temp_end: float | None = None
    temp_tau_s: float = 300.0
    temp_ref: float = 31.0
    magnetometer: bool = False
    field_uT: float = 47.0
    dip_deg: float = 61.0
    mag_hard_iron: tuple | None = None
    mag_soft_iron: tuple | None = None
    mag_noise_uT: float = 0.6

    def __post_init__(self):
        """Check the noise levels, ranges and the shapes of the given errors."""
        for k in (
            "acc_noise_density",
            "gyr_noise_density",
            "acc_bias_walk",
            "gyr_bias_walk",
            "mag_noise_uT",
        ):
            if getattr(self, k) < 0:
                raise ValueError(f"{k} must be >= 0")
        if self.acc_range <= 0 or self.gyr_range <= 0:
            raise ValueError("acc_range and gyr_range must be positive")
        for k in (
            "acc_offset",
            "gyr_offset",
            "acc_scale",
            "gyr_scale",
            "acc_temp_coef",
            "gyr_temp_coef",
            "mag_hard_iron",
        ):
            _vec(getattr(self, k), k)
        for k in ("acc_misalign", "gyr_misalign", "mag_soft_iron"):
            _vec(getattr(self, k), k, (3, 3))

    @classmethod
    def ideal(cls, *, magnetometer: bool = False) -> "SensorModel":
        """Build a perfect sensor (measured = true).

        No offset, scale, misalignment, noise, drift, temperature effect, saturation or
        quantisation.
        """
        z, e = (0.0, 0.0, 0.0), ((0.0,) * 3,) * 3
        return cls(
            acc_offset=z,
            gyr_offset=z,
            acc_scale=z,
            gyr_scale=z,
            acc_misalign=e,
            gyr_misalign=e,
            acc_temp_coef=z,
            gyr_temp_coef=z,
            acc_noise_density=0.0,
            gyr_noise_density=0.0,
            acc_bias_walk=0.0,
            gyr_bias_walk=0.0,
            acc_range=1e9,
            gyr_range=1e12,
            quantize=False,
            temp_start=31.0,
            temp_end=31.0,
            magnetometer=magnetometer,
            mag_hard_iron=z,
            mag_soft_iron=((1.0, 0, 0), (0, 1.0, 0), (0, 0, 1.0)),
            mag_noise_uT=0.0,
        )

    def to_dict(self) -> dict:
        """JSON-serialisable dict."""
        return {
            k: (
                np.asarray(v).tolist()
                if isinstance(v, (tuple, list, np.ndarray))
                else v
            )
            for k, v in asdict(self).items()
        }


def _misalign(rng, sd):
    e = rng.normal(0.0, sd, (3, 3))
    np.fill_diagonal(e, 0.0)
    return e


def draw_sensor(sensor: SensorModel | None, rng: np.random.Generator) -> SensorModel:
    """Fill every ``None`` error of ``sensor`` with a random draw (returns a new model).

    Offsets are normal with the 5–95th percentiles of Fayat et al. (±1.645 σ);
    scale errors N(0, 1 %), cross-axis N(0, 0.5 %), temperature coefficients
    N(0, 0.5 mg/°C) and N(0, 0.15 °/s/°C), temperature warming from U(27, 30) °C to
    U(31, 34) °C, hard iron N(0, 15 µT), soft iron I + symmetric N(0, 3 %).

    Parameters
    ----------
    sensor : SensorModel or None
        Sensor model whose given errors are kept; None: ``SensorModel()``.
    rng : numpy.random.Generator
        Random source of the draws.

    Returns
    -------
    SensorModel
        A new model with every error and both temperatures (°C) set.
    """
    s = sensor or SensorModel()

    def mid_sd(r):
        return 0.5 * (r[0] + r[1]), (r[1] - r[0]) / (2 * _Z95)

    def pick(name, draw):
        v = getattr(s, name)
        return np.asarray(v, float) if v is not None else draw()

    am, asd = mid_sd(ACC_OFFSET_RANGE_G)
    gm, gsd = mid_sd(GYR_OFFSET_RANGE_DPS)
    vals = {
        "acc_offset": pick("acc_offset", lambda: rng.normal(am, asd, 3)),
        "gyr_offset": pick("gyr_offset", lambda: rng.normal(gm, gsd, 3)),
        "acc_scale": pick("acc_scale", lambda: rng.normal(0.0, 0.01, 3)),
        "gyr_scale": pick("gyr_scale", lambda: rng.normal(0.0, 0.01, 3)),
        "acc_misalign": pick("acc_misalign", lambda: _misalign(rng, 0.005)),
        "gyr_misalign": pick("gyr_misalign", lambda: _misalign(rng, 0.005)),
        "acc_temp_coef": pick("acc_temp_coef", lambda: rng.normal(0.0, 0.5e-3, 3)),
        "gyr_temp_coef": pick("gyr_temp_coef", lambda: rng.normal(0.0, 0.15, 3)),
        "mag_hard_iron": pick("mag_hard_iron", lambda: rng.normal(0.0, 15.0, 3)),
    }
    if s.mag_soft_iron is None:
        a = rng.normal(0.0, 0.03, (3, 3))
        vals["mag_soft_iron"] = np.eye(3) + 0.5 * (a + a.T)
    else:
        vals["mag_soft_iron"] = np.asarray(s.mag_soft_iron, float)
    t0 = s.temp_start if s.temp_start is not None else float(rng.uniform(27.0, 30.0))
    t1 = s.temp_end if s.temp_end is not None else float(rng.uniform(31.0, 34.0))
    return replace(
        s,
        temp_start=t0,
        temp_end=t1,
        **{
            k: tuple(map(tuple, v)) if v.ndim == 2 else tuple(v)
            for k, v in vals.items()
        },
    )


class _Triad(NamedTuple):
    # the errors of one 3-axis sensor of a drawn SensorModel, in the kernel's terms
    matrix: np.ndarray  # T = (I + diag(s)) (I + E)
    offset: np.ndarray
    temp_coef: np.ndarray
    noise_sd: float
    walk_sd: float
    full_scale: float


def _triad(s: SensorModel, name: str, fs: float) -> _Triad:
    # the errors of s's accelerometer (name "acc") or gyroscope ("gyr") at rate fs
    scale = np.asarray(getattr(s, f"{name}_scale"), float)
    misalign = np.asarray(getattr(s, f"{name}_misalign"), float)
    return _Triad(
        (np.eye(3) + np.diag(scale)) @ (np.eye(3) + misalign),
        np.asarray(getattr(s, f"{name}_offset"), float),
        np.asarray(getattr(s, f"{name}_temp_coef"), float),
        getattr(s, f"{name}_noise_density") * math.sqrt(fs / 2.0),
        getattr(s, f"{name}_bias_walk") * math.sqrt(1.0 / fs),
        getattr(s, f"{name}_range"),
    )


def _measure(x, triad: _Triad, dtemp, rng, quantize):
    lsb = 2.0 * triad.full_scale / 65536.0
    out = np.empty_like(x)
    b = np.zeros(3)
    n_sat = measure_kernel(
        np.ascontiguousarray(x, dtype=float),
        triad.matrix,
        triad.offset,
        triad.temp_coef,
        dtemp,
        float(triad.noise_sd),
        float(triad.walk_sd),
        -triad.full_scale,
        triad.full_scale - lsb,
        lsb,
        bool(quantize),
        int(rng.integers(0, 2**31 - 1)),
        out,
        b,
    )
    return out, b, int(n_sat)


def _truth(s: SensorModel, triads: dict, bias: dict, sat: dict, dtemp) -> dict:
    # the true errors of the accelerometer and gyroscope, as JSON-serialisable attrs
    names = ("acc", "gyr")
    out = {f"true_{k}_offset": triads[k].offset.tolist() for k in names}
    for k in names:
        out[f"true_{k}_offset_mean"] = (
            triads[k].offset + np.mean(dtemp) * triads[k].temp_coef + bias[k]
        ).tolist()
    out.update({f"true_{k}_matrix": triads[k].matrix.tolist() for k in names})
    out.update({f"true_{k}_temp_coef": triads[k].temp_coef.tolist() for k in names})
    out["true_temp_ref"] = s.temp_ref
    out.update({f"n_saturated_{k}": sat[k] for k in names})
    return out


def apply_sensor_model(
    true: dict, sensor: SensorModel | None, rng: np.random.Generator, fs: float
) -> dict:
    """Corrupt true sensor-frame signals with a sensor model.

    Parameters
    ----------
    true : dict
        ``acc`` (N, 3) specific force in g, ``gyr`` (N, 3) angular velocity in °/s,
        and ``q`` (N, 4) when a magnetometer is simulated.
    sensor : SensorModel or None
        ``None`` errors are drawn with :func:`draw_sensor`.
    rng : numpy.random.Generator
        Random source of the drawn errors and the noise.
    fs : float
        Sampling rate (Hz).

    Returns
    -------
    dict
        ``acc``, ``gyr`` (and ``mag``) measured, ``temp`` (N,), ``sensor`` (the fully
        drawn :class:`SensorModel`) and ``truth`` (JSON-serialisable attrs: the
        effective mean offsets over the recording, saturation counts ...).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import simulate
    >>> true = {"acc": np.tile([0.0, 0.0, 1.0], (200, 1)), "gyr": np.zeros((200, 3))}
    >>> sensor = simulate.SensorModel(
    ...     acc_offset=(0.05, 0.0, 0.0), gyr_offset=(1.0, -2.0, 0.5)
    ... )
    >>> out = simulate.apply_sensor_model(true, sensor, np.random.default_rng(0), 100.0)
    >>> sorted(out)
    ['acc', 'gyr', 'sensor', 'temp', 'truth']
    >>> np.round(out["acc"].mean(axis=0), 2).tolist()  # offset, scale and noise, g
    [0.05, 0.0, 1.01]
    """
    if fs is None or not np.isfinite(fs) or fs <= 0:
        raise ValueError(f"fs must be a positive number of Hz, got {fs!r}")
    acc = np.asarray(true["acc"], float)
    gyr = np.asarray(true["gyr"], float)
    if acc.ndim != 2 or acc.shape[1] != 3 or gyr.shape != acc.shape:
        raise ValueError(
            f"true acc and gyr must both have shape (N, 3), got {acc.shape} and {gyr.shape}"
        )
    s = draw_sensor(sensor, rng)
    n = acc.shape[0]
    t = np.arange(n) / fs
    temp = s.temp_end + (s.temp_start - s.temp_end) * np.exp(-t / s.temp_tau_s)
    dtemp = temp - s.temp_ref
    triads = {"acc": _triad(s, "acc", fs), "gyr": _triad(s, "gyr", fs)}
    meas, bias, sat = {}, {}, {}
    for k, x in (("acc", acc), ("gyr", gyr)):
        meas[k], bias[k], sat[k] = _measure(x, triads[k], dtemp, rng, s.quantize)
    out = {"acc": meas["acc"], "gyr": meas["gyr"], "temp": temp, "sensor": s}
    truth = _truth(s, triads, bias, sat, dtemp)
    if s.magnetometer:
        if "q" not in true:
            raise ValueError("a magnetometer needs the true orientation 'q'")
        out["mag"], m_w = magnetometer_readings(true["q"], s, rng)
        truth.update(
            {
                "true_mag_hard_iron": np.asarray(s.mag_hard_iron, float).tolist(),
                "true_mag_soft_iron": np.asarray(s.mag_soft_iron).tolist(),
                "true_field_world_uT": m_w.tolist(),
            }
        )
    out["truth"] = truth
    return out


def magnetometer_readings(
    q, sensor: SensorModel, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    r"""Magnetometer output (µT) of a drawn sensor (:func:`draw_sensor`) at orientations ``q``.

    The local field in ENU is :math:`m_w = B\,(0, \cos I, -\sin I)` (strength ``field_uT``,
    dip ``dip_deg``, pointing down in the northern hemisphere); the sensor reads
    :math:`W R(q)^\top m_w + h + n` with soft iron :math:`W`, hard iron :math:`h` and white
    noise :math:`n`, quantised to the AK8963's 0.15 µT when ``sensor.quantize``.

    Parameters
    ----------
    q : array_like, shape (N, 4)
        True orientations, unit quaternions (w, x, y, z), sensor to world (ENU).
    sensor : SensorModel
        Drawn sensor (no ``None`` errors): ``field_uT`` (µT), ``dip_deg`` (degrees),
        ``mag_soft_iron`` (3, 3), ``mag_hard_iron`` (µT), ``mag_noise_uT`` (µT, white
        noise standard deviation) and ``quantize``.
    rng : numpy.random.Generator
        Random source of the noise.

    Returns
    -------
    mag : numpy.ndarray, shape (N, 3)
        Readings (µT).
    m_w : numpy.ndarray, shape (3,)
        The world-frame field (µT).
    """
    q = np.asarray(q, float)
    dip = math.radians(sensor.dip_deg)
    m_w = sensor.field_uT * np.array([0.0, math.cos(dip), -math.sin(dip)])
    mag = _quat.rotate_inverse(q, m_w) @ np.asarray(
        sensor.mag_soft_iron, float
    ).T + np.asarray(sensor.mag_hard_iron, float)
    if sensor.mag_noise_uT > 0:
        mag += sensor.mag_noise_uT * rng.standard_normal(mag.shape)
    if sensor.quantize:
        mag = np.round(mag / 0.15) * 0.15  # AK8963 16-bit output: 0.15 µT/LSB
    return mag, m_w


def true_sensor_values(q, a_lin_g) -> np.ndarray:
    r"""Compute the true accelerometer reading (g), :math:`R(q)^\top (e_z + a_{lin})`.

    Parameters
    ----------
    q : array_like, shape (N, 4)
        Orientations, unit quaternions (w, x, y, z), sensor to world.
    a_lin_g : array_like, shape (N, 3)
        Linear acceleration of the sensor (g), world frame, z up.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        Error-free specific force (g) in the sensor frame.
    """
    a = np.asarray(a_lin_g, float)
    return _quat.rotate_inverse(q, a + np.array([0.0, 0.0, 1.0]))


def recording_from_motion(
    motion: TrueMotion,
    *,
    rng: np.random.Generator,
    sensor: SensorModel | None = None,
    keep_true: bool = True,
    attrs: dict | None = None,
) -> xr.Dataset:
    """Turn a :class:`TrueMotion` into a validated Recording through a sensor model.

    Variables: measured ``acc`` (g), ``gyr`` (°/s), ``temp`` (°C), optional ``mag`` (µT);
    truth ``q_ref``, ``a_lin`` (g, world frame), ``state`` (int8, legend in
    ``flag_values``/``flag_meanings``) and, with ``keep_true``, ``acc_true``, ``gyr_true``
    and ``pos`` (m, world frame). True sensor errors are in ``true_*`` attrs.

    Parameters
    ----------
    motion : TrueMotion
        True motion: orientations, angular velocity (rad/s), linear acceleration
        (m/s², world frame), positions (m), states, at ``motion.fs`` (Hz).
    rng : numpy.random.Generator
        Random source of the sensor errors and noise.
    sensor : SensorModel, optional
        Sensor model; its ``None`` errors are drawn (default ``SensorModel()``).
    keep_true : bool, default True
        Also store ``acc_true``, ``gyr_true`` and ``pos``.
    attrs : dict, optional
        Extra attributes of the Recording (override the defaults).

    Returns
    -------
    xarray.Dataset
        The validated Recording.
    """
    fs = motion.fs
    a_lin_g = motion.a_lin / G0
    acc_true = true_sensor_values(motion.q, a_lin_g)
    gyr_true = np.degrees(motion.omega)
    meas = apply_sensor_model(
        {"acc": acc_true, "gyr": gyr_true, "q": motion.q}, sensor, rng, fs
    )
    extra = {
        "state": (
            ("time",),
            motion.state.astype(np.int8),
            {
                "long_name": "behavioural state (ground truth)",
                "flag_values": list(range(len(STATES))),
                "flag_meanings": " ".join(STATES),
            },
        ),
        "a_lin": (
            ("time", "axis"),
            a_lin_g,
            {
                "units": "g",
                "frame": "world",
                "long_name": "true linear acceleration of the sensor",
            },
        ),
    }
    if keep_true:
        extra["acc_true"] = (
            ("time", "axis"),
            acc_true,
            {"units": "g", "frame": "sensor", "long_name": "true specific force"},
        )
        extra["gyr_true"] = (
            ("time", "axis"),
            gyr_true,
            {"units": "deg/s", "frame": "sensor", "long_name": "true angular velocity"},
        )
        extra["pos"] = (
            ("time", "axis"),
            motion.pos,
            {"units": "m", "frame": "world", "long_name": "true sensor position"},
        )
    a = {
        "source": "tiltlab.simulate",
        "sensor": "simulated MPU-9250-like IMU",
        "subject": "simulated rat",
        "session": "simulated",
        "axes": "x forward (nose), y left, z up (dorsal)",
        "simulated": 1,
        "sensor_model": meas["sensor"].to_dict(),
        **motion.params,
        **meas["truth"],
        **dict(attrs or {}),
    }
    return _schema.make_recording(
        meas["acc"],
        meas["gyr"],
        fs,
        acc_units="g",
        gyr_units="deg/s",
        mag=meas.get("mag"),
        temp=meas["temp"],
        q_ref=motion.q,
        extra=extra,
        attrs=a,
        mag_units="uT",
        temp_units="degC",
        axis_labels=["forward (nose)", "left", "up (dorsal)"],
    )


def simulate_session(
    duration_s: float,
    fs: float,
    *,
    seed: int | np.random.SeedSequence | None,
    behaviour: BehaviourParams | None = None,
    sensor: SensorModel | None = None,
    lesion: Lesion | None = None,
    keep_true: bool = True,
    attrs: dict | None = None,
) -> xr.Dataset:
    """Simulate a freely-moving head recording with ground truth.

    Parameters
    ----------
    duration_s, fs : float
        Duration (s) and sampling rate (Hz, mandatory).
    seed : int or SeedSequence or None
        Same seed → bit-identical Recording. ``None`` draws fresh entropy.
    behaviour : BehaviourParams, optional
        Behaviour of the animal (default ``BehaviourParams()``).
    sensor : SensorModel, optional
        Default: every error drawn from the MPU-9250/Fayat distributions;
        :meth:`SensorModel.ideal` for a perfect sensor.
    lesion : Lesion, optional
        A vestibular lesion applied to the behaviour.
    keep_true : bool
        Also store ``acc_true``, ``gyr_true`` and ``pos``.
    attrs : dict, optional
        Extra dataset attributes (provenance).

    Returns
    -------
    xarray.Dataset
        A validated Recording (see :func:`recording_from_motion`).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import simulate
    >>> rec = simulate.simulate_session(5.0, 50.0, seed=1)
    >>> dict(rec.sizes)
    {'time': 250, 'axis': 3, 'quat': 4}
    >>> np.round(rec.attrs["true_gyr_offset"], 2).tolist()  # the drawn offset, °/s
    [-8.99, -13.92, -8.64]
    """
    rng = np.random.default_rng(seed)
    motion = head_kinematics(
        duration_s, fs, behaviour=behaviour, lesion=lesion, rng=rng
    )
    return recording_from_motion(
        motion, rng=rng, sensor=sensor, keep_true=keep_true, attrs=attrs
    )
