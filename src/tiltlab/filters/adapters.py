"""Adapt reference implementations for comparison: ``vqf``, ``imufusion``, ``ahrs``, ``riann``.

``vqf`` (VQF and offlineVQF, Laidig & Seel 2023), ``imufusion`` (x-io Fusion AHRS), the pure-Python ``ahrs``
package (Madgwick, Mahony, EKF) and ``riann`` (RIANN, the published recurrent network of
Weber, Gühmann & Seel 2021).

Each adapter takes the filters' inputs — ``acc`` in m/s², ``gyr`` in rad/s, ``fs`` in
Hz, optional ``mag`` — and returns (N, 4) scalar-first quaternions sensor → world with
world z up. Labelled DataArrays are read as by the filters (:mod:`tiltlab.filters`,
"Labelled inputs"): ``acc`` and ``gyr`` are converted from their ``units`` attributes
(required) and ``fs`` may come from their attributes. The packages are optional (extra ``compare``; ``riann`` and
``onnxruntime``: extra ``learn``) and imported on first use.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as _v
from .. import units as _units
from ._common import (
    init_samples,
    initial_orientation,
    read_sensors,
    sensor_inputs,
    unlabel,
)
from ._docs import shared_docs

__all__ = [
    "vqf_parameter_names",
    "run_vqf",
    "run_offline_vqf",
    "run_imufusion",
    "run_ahrs_madgwick",
    "run_ahrs_mahony",
    "run_ahrs_ekf",
    "run_riann",
]


def vqf_parameter_names() -> frozenset[str]:
    """List the ``vqf`` package's own parameters (``tauAcc``, ``restThGyr``, …).

    Returns
    -------
    frozenset of str
        The parameter names of ``vqf.VQF``.
    """
    import vqf

    return frozenset(vqf.VQF(0.01).params)


def _vqf(acc, gyr, fs, mag, offline: bool, params: dict) -> np.ndarray:
    import vqf

    fs, a, g, m, use_mag = read_sensors(fs, acc, gyr, mag, acc_si=True)
    unknown = sorted(set(params) - vqf_parameter_names())
    if unknown:
        raise ValueError(
            f"unknown vqf parameter(s) {unknown}; "
            f"valid: {sorted(vqf_parameter_names())}"
        )
    m = m if use_mag else None
    if offline:
        res = vqf.offlineVQF(g, a, m, 1.0 / fs, dict(params) or None)
    else:
        res = vqf.VQF(1.0 / fs, **params).updateBatch(g, a, m)
    return np.asarray(res["quat9D" if use_mag else "quat6D"])


@shared_docs
def run_vqf(acc, gyr, fs: float | None = None, *, mag=None, **vqf_params) -> np.ndarray:
    """Run VQF (``vqf.VQF(...).updateBatch``), 6D or 9D.

    ``vqf_params`` are the ``vqf`` package's own parameters with its own defaults (e.g.
    ``tauAcc`` in s).

    Parameters
    ----------
    %(si_inputs)s
    %(vqf_mag)s
    **vqf_params
        Parameters of ``vqf.VQF`` (e.g. ``tauAcc`` in s); an unknown name is a
        ValueError.

    Returns
    -------
    %(q_6d_9d)s
    """
    return _vqf(acc, gyr, fs, mag, False, vqf_params)


@shared_docs
def run_offline_vqf(
    acc, gyr, fs: float | None = None, *, mag=None, **vqf_params
) -> np.ndarray:
    """Run offlineVQF (``vqf.offlineVQF``, non-causal), 6D or 9D.

    The same inputs and outputs as :func:`run_vqf`; the estimate uses past and future
    samples.

    Parameters
    ----------
    acc, gyr, fs, mag
        As for :func:`run_vqf`.
    **vqf_params
        Parameters of ``vqf.offlineVQF`` (its ``tauAcc``, ``restThGyr``, …, the names
        of :func:`vqf_parameter_names`); an unknown name is a ValueError.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        As for :func:`run_vqf`.
    """
    return _vqf(acc, gyr, fs, mag, True, vqf_params)


@shared_docs
def run_imufusion(
    acc,
    gyr,
    fs: float | None = None,
    *,
    gain: float = 0.5,
    acceleration_rejection_deg: float = 10.0,
    rejection_timeout_s: float = 5.0,
) -> np.ndarray:
    """x-io Fusion AHRS (``imufusion``), 6D, NWU world (z up: tilt comparable).

    ``gyr`` rad/s → °/s and ``acc`` m/s² → g for the package; ``gain`` is Fusion's
    gain, ``acceleration_rejection_deg`` its acceleration-rejection threshold (°) and
    ``rejection_timeout_s`` its rejection timeout (s).

    Parameters
    ----------
    %(si_inputs)s
    gain : float
        Fusion's gain (≥ 0; 0 integrates the gyroscope alone).
    acceleration_rejection_deg : float
        Acceleration-rejection threshold (°).
    rejection_timeout_s : float
        Rejection timeout (s).

    Returns
    -------
    %(q_z_up)s
    """
    import imufusion

    fs, acc, gyr, _, _ = read_sensors(fs, acc, gyr, acc_si=True)
    gain = _v.nonnegative(gain, "gain")
    rej = _v.nonnegative(acceleration_rejection_deg, "acceleration_rejection_deg")
    timeout = _v.nonnegative(rejection_timeout_s, "rejection_timeout_s")
    settings = imufusion.AhrsSettings(
        sample_rate=fs,
        convention=imufusion.CONVENTION_NWU,
        gain=gain,
        gyroscope_range=1e6,
        acceleration_rejection=rej,
        magnetic_rejection=0.0,
        rejection_timeout=int(round(timeout * fs)),
    )
    a = imufusion.Ahrs()
    a.set_settings(settings)
    a.set_sample_period(1.0 / fs)
    g = np.degrees(gyr)
    ac = acc / _units.G0
    out = np.empty((acc.shape[0], 4))
    for k in range(acc.shape[0]):
        a.update_no_magnetometer(g[k], ac[k])
        out[k] = a.get_quaternion()
    return out


def _ahrs_start(acc, gyr, fs, init_window_s):
    fs, acc, gyr, _, _ = read_sensors(fs, acc, gyr, acc_si=True)
    q0 = initial_orientation(acc[: init_samples(init_window_s, fs)])
    return acc, gyr, fs, q0


@shared_docs
def run_ahrs_madgwick(
    acc, gyr, fs: float | None = None, *, beta: float = 0.05, init_window_s: float = 0.1
) -> np.ndarray:
    """Run ``ahrs.filters.Madgwick`` (6D) with an explicit ``frequency``.

    Started at :func:`initial_orientation` of the first ``init_window_s`` seconds.

    Parameters
    ----------
    %(si_inputs)s
    beta : float
        Madgwick's gain β (≥ 0, rad/s).
    %(ahrs_init)s

    Returns
    -------
    %(q_z_up)s
    """
    import ahrs.filters as af

    acc, gyr, fs, q0 = _ahrs_start(acc, gyr, fs, init_window_s)
    beta = _v.nonnegative(beta, "beta")
    f = af.Madgwick(gyr=gyr, acc=acc, frequency=fs, gain=beta, q0=q0)
    return np.asarray(f.Q, float)


@shared_docs
def run_ahrs_mahony(
    acc,
    gyr,
    fs: float | None = None,
    *,
    kp: float = 1.0,
    ki: float = 0.3,
    init_window_s: float = 0.1,
) -> np.ndarray:
    """``ahrs.filters.Mahony`` (6D), started as :func:`run_ahrs_madgwick`.

    ``ahrs`` rejects ``k_I = 0`` (and ``k_P = 0``); the smallest positive float stands
    in for zero.

    Parameters
    ----------
    %(si_inputs)s
    kp : float
        Proportional gain k_P (≥ 0).
    ki : float
        Integral gain k_I (≥ 0; 1/s).
    %(ahrs_init)s

    Returns
    -------
    %(q_z_up)s
    """
    import ahrs.filters as af

    acc, gyr, fs, q0 = _ahrs_start(acc, gyr, fs, init_window_s)
    kp = max(_v.nonnegative(kp, "kp"), 5e-324)
    ki = max(_v.nonnegative(ki, "ki"), 5e-324)
    f = af.Mahony(gyr=gyr, acc=acc, frequency=fs, k_P=kp, k_I=ki, q0=q0)
    return np.asarray(f.Q, float)


@shared_docs
def run_ahrs_ekf(
    acc,
    gyr,
    fs: float | None = None,
    *,
    var_gyr: float = 0.3**2,
    var_acc: float = 0.5**2,
    init_window_s: float = 0.1,
) -> np.ndarray:
    """Run ``ahrs.filters.EKF`` (6D) with ``frame='NED'``, started as :func:`run_ahrs_madgwick`.

    ``frame='NED'`` is really z up: ``ahrs``'s ``frame='ENU'`` is upside down.

    Parameters
    ----------
    %(si_inputs)s
    var_gyr : float
        Gyroscope noise variance ((rad/s)², ≥ 0).
    var_acc : float
        Accelerometer noise variance ((m/s²)², > 0).
    %(ahrs_init)s

    Returns
    -------
    %(q_z_up)s
    """
    import ahrs.filters as af

    acc, gyr, fs, q0 = _ahrs_start(acc, gyr, fs, init_window_s)
    noises = [
        _v.nonnegative(var_gyr, "var_gyr"),
        _v.positive(var_acc, "var_acc"),
        0.8**2,
    ]
    f = af.EKF(gyr=gyr, acc=acc, frequency=fs, frame="NED", q0=q0, noises=noises)
    return np.asarray(f.Q, float)


#: Samples per call of the RIANN network (memory bound; results do not depend on it).
RIANN_CHUNK = 50_000


@shared_docs
def run_riann(
    acc, gyr, fs: float | None = None, *, mag=None, threads: int | None = None
) -> np.ndarray:
    """Run RIANN, a published recurrent network for attitude estimation (``riann``), 6D.

    The network takes the sampling interval as an input, so any rate is accepted.

    Parameters
    ----------
    %(si_inputs)s
    mag : None
        Present for the adapters' uniform signature only: RIANN is a 6D method, and any
        ``mag`` other than None is a ValueError.
    threads : int, optional
        Threads of the ONNX runtime within the network's operations (None: the
        runtime's default, one per core). Pass 1 when several recordings run in
        parallel processes: threads beyond the idle cores wait on each other.

    Returns
    -------
    numpy.ndarray, shape (N, 4), float64
        Unit quaternions (w, x, y, z) sensor → world, world z up, heading arbitrary.

    Raises
    ------
    ImportError
        The ``riann`` package (or ``onnxruntime``) is not installed.
    ValueError
        ``mag`` given, an invalid ``fs``, non-finite or mismatched ``acc``/``gyr``, or
        ``threads`` below 1.

    Notes
    -----
    The network is the ONNX model shipped inside the ``riann`` package (no download),
    run on CPU by ``onnxruntime`` with a zero initial hidden state, so the first
    samples are a transient. Its output already follows tiltlab's convention
    (scalar-first, sensor → world, world z up: at rest, :func:`tiltlab.quaternion.gravity`
    of the output is the direction of ``acc``), so it is only cast to float64 and
    renormalised (the network computes in float32). The model path is passed
    explicitly because ``riann`` 0.2.0's own default lookup depends on the working
    directory. The sequence is fed to the network in chunks of :data:`RIANN_CHUNK`
    samples with the recurrent state carried from one to the next, which gives the
    same numbers as one call over the whole sequence (``RIANN.predict``) with bounded
    memory: a single call needs ~4 kB per sample, 28 GB for 6 h at 300 Hz.

    References
    ----------
    .. [1] D. Weber, C. Gühmann, T. Seel, "RIANN — A Robust Neural Network
       Outperforms Attitude Estimation Filters", AI 2(3):444–463, 2021.
       https://doi.org/10.3390/ai2030028
    """
    try:
        import importlib.resources

        import onnxruntime as rt
        import riann  # noqa: F401  (the package that ships the model)
    except ImportError as e:
        raise ImportError(
            "run_riann needs the 'riann' package and onnxruntime: install the learn "
            "extra (pip install tiltlab[learn])"
        ) from e

    fs, acc, gyr, _ = unlabel(fs, acc=acc, gyr=gyr, acc_si=True)
    if mag is not None:
        raise ValueError(
            "RIANN is a 6D method (accelerometer and gyroscope) and takes no "
            "magnetometer: pass mag=None"
        )
    options = rt.SessionOptions()
    if threads is not None:
        options.intra_op_num_threads = int(_v.integer(threads, "threads", minimum=1))
        options.inter_op_num_threads = 1
    acc, gyr, _, _ = sensor_inputs(acc, gyr)
    model = importlib.resources.files("riann") / "riann.onnx"
    with importlib.resources.as_file(model) as path:
        session = rt.InferenceSession(str(path), options)
    # Chunks with the recurrent state carried across them: the same numbers as one
    # call over the whole sequence (bitwise, checked in the tests), with memory bounded
    # by the chunk (the runtime's work arrays grow by ~4 kB per sample of a call).
    x = np.concatenate([acc, gyr, np.full((acc.shape[0], 1), 1.0 / fs)], axis=1)
    x = x.astype(np.float32)
    h = np.zeros((2, 1, 1, 200), dtype=np.float32)
    q = np.empty((acc.shape[0], 4))
    for start in range(0, acc.shape[0], RIANN_CHUNK):
        out = session.run([], {"input": x[None, start : start + RIANN_CHUNK], "h0": h})
        q[start : start + RIANN_CHUNK] = out[0][0]
        h = out[1]
    return q / np.linalg.norm(q, axis=1, keepdims=True)
