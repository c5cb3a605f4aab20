r"""Estimate orientations: numba filters, one method registry and :func:`estimate`.

The orientation filters' numba kernels, one method registry and the :func:`estimate`
wrapper (layer 5).

Every filter turns a Recording's accelerometer (specific force), gyroscope and
optionally magnetometer samples into unit quaternions ``q`` (scalar first) that
rotate **sensor → world**, world z up. With a magnetometer ("9D") the world frame
is ENU (x east, y magnetic north, z up); without one ("6D") the heading of the
world frame is arbitrary (fixed by the initial orientation).

Gaps and dropouts: :func:`estimate` refuses a Recording whose time axis has gaps or
whose samples contain NaN runs (``gaps="raise"``, the default, with a message saying
where), or estimates each contiguous segment separately from its own initial orientation
(``gaps="segments"``: NaN in the gaps, the segments recorded in the output's attrs).

Methods
-------
``lowpass``
    Tilt from the normalised, zero-phase low-passed accelerometer (2nd-order
    Butterworth, forward–backward; scipy). Heading zero; needs no gyroscope.
``davenport``
    Accelerometer + magnetometer, no gyroscope: Davenport's q-method on every sample
    (optionally low-passed first), ENU world frame [6]_.
``complementary``
    Gyroscope integration corrected towards the accelerometer (and magnetometer)
    by geometric rotations in the world frame, with time constants.
``madgwick``
    Gradient-descent correction (Madgwick 2010/2011).
``mahony``
    Explicit complementary filter with proportional and integral (gyro bias) terms
    (Mahony 2008).
``learned_gain``
    Mahony's filter (6D) whose gains a tiny learned model schedules from short windows
    of the sensors (:mod:`~tiltlab.filters.learned_gain`; weights trained by
    :mod:`tiltlab.learn.gain_schedule`).
``ekf``
    Quaternion-state extended Kalman filter with the gravity (and magnetic field)
    direction as measurement (the formulation of the ``ahrs`` package).
``eskf``
    Error-state Kalman filter (Solà 2017; the ESKF baseline of Zaheer et al. 2023):
    attitude and gyro bias, accelerometer direction with an adaptive variance, and a
    heading-only magnetometer update.
``smoother``
    Offline (non-causal) tilt: rest-detected gyro bias, strapdown integration, and a
    zero-phase low-pass of the specific force expressed in the integrated frame; for
    post-hoc analysis.
``rts_smoother``
    Offline error-state EKF (attitude, gyro bias and scale, velocity, position; zero-velocity
    and bounded-position pseudo-measurements, adaptive accelerometer weighting) with a
    Rauch–Tung–Striebel backward pass.
``vqf``, ``offline_vqf``
    Adapters to the ``vqf`` package (Laidig & Seel 2023), for comparison.
``riann``
    Adapter to RIANN (Weber, Gühmann & Seel 2021), a published recurrent network for
    6D attitude estimation (``riann`` package, ONNX; extra ``learn``).
``imufusion``
    Adapter to the ``imufusion`` package (x-io Fusion AHRS, 6D), for comparison.
``ahrs_madgwick``, ``ahrs_mahony``, ``ahrs_ekf``
    Adapters to the pure-Python ``ahrs`` package (6D; slow: use short recordings), for
    comparison; the EKF runs with ``frame='NED'`` (really z up, see below).

Recordings without a gyroscope
------------------------------
Most bio-logging tags record acceleration (and a magnetic field) only. Every method
declares the variables it needs (:attr:`Method.needs`); ``methods(needs="acc")``,
``methods(needs=("acc", "mag"))`` or ``methods(needs=recording)`` list the ones that
run on such data, and :func:`estimate` refuses any other with a
:class:`~tiltlab._validate.RecordingError` naming the method, the missing sensor and
the methods that would run.

Package layout
--------------
One module per method family — :mod:`~tiltlab.filters.lowpass`,
:mod:`~tiltlab.filters.complementary`, :mod:`~tiltlab.filters.madgwick`,
:mod:`~tiltlab.filters.mahony`, :mod:`~tiltlab.filters.ekf`,
:mod:`~tiltlab.filters.eskf`,
:mod:`~tiltlab.filters.smoothers` (``smoother``, ``rest_gyro_bias``),
:mod:`~tiltlab.filters.rts` and :mod:`~tiltlab.filters.adapters` — plus
:mod:`~tiltlab.filters.registry` (:data:`METHODS`: each method's function, whether it
supports a magnetometer, and its parameter defaults, read from the function's
signature: the one place they are written) and :mod:`~tiltlab.filters.recordings`
(:func:`estimate`, :func:`gravity`). The array functions take SI inputs (``acc`` m/s²
or any unit where only its direction matters, ``gyr`` rad/s) and a mandatory ``fs``,
or labelled inputs (below); durations end in ``_s``, frequencies in ``_hz``. Scoring
against references (``broad_errors``, ``tilt_rmse``, ``grid_search``) lives in
:mod:`tiltlab.evaluate`.

Labelled inputs
---------------
Every array function (the filters, :func:`lowpass_tilt`, :func:`rest_gyro_bias`,
:func:`davenport`, :func:`magnetic_dip`, :func:`vector_observation` and the adapters)
also takes labelled :class:`xarray.DataArray` inputs, such as a Recording's own
``rec["acc"]`` and ``rec["gyr"]``, and honours their attributes as
:func:`tiltlab._validate.signal` reads them (the policy of :mod:`tiltlab.behavior` and
:mod:`tiltlab.sphere`). They are converted once, on entry, to the plain arrays the
kernels use, so ``madgwick(rec["acc"], rec["gyr"], rec.attrs["fs"])`` gives exactly
``estimate(rec, "madgwick")``:

* ``gyr``: converted from its ``units`` attribute (``"deg/s"``, ``"rad/s"``, …) to
  rad/s; a labelled ``gyr`` without ``units`` is a
  :class:`~tiltlab._validate.RecordingError` (its unit matters);
* ``acc``: converted from its ``units`` (``"g"``, ``"m/s^2"``) to m/s², which leaves
  its direction as it is; without ``units`` it is accepted as is by the methods that
  use only its direction (``madgwick``, ``mahony``, ``ekf``, ``complementary``,
  ``lowpass_tilt``, ``davenport``, ``magnetic_dip``, ``vector_observation``) and
  refused by those that use m/s² (``eskf``, ``smoother``, ``rts_smoother``,
  ``rest_gyro_bias``, the adapters);
* ``mag``: kept as it is (only its direction is used); a ``units`` attribute must be
  a magnetic-field unit;
* a unit of the wrong quantity (``acc`` in ``"deg/s"``) or an unknown one is a
  :class:`~tiltlab.units.UnitsError` naming the input;
* ``fs``: an ``fs`` argument that contradicts an input's ``attrs["fs"]`` is refused
  (the message gives both rates), as are inputs whose ``fs`` attributes disagree; the
  argument may be omitted when the inputs carry ``attrs["fs"]`` (plain arrays still
  need it: tiltlab never assumes a rate); a ``time`` coordinate must agree with the
  rate;
* ``time`` coordinates of different lengths, or more than half a sample apart, are
  refused.

Each input is read on its own: a plain array keeps its documented unit even next to a
labelled one. Plain arrays behave exactly as before, and the outputs are plain arrays
in every case (:func:`estimate` labels its output). Initial states given as arguments
(``gyr_offset``) and bias outputs stay in rad/s.

Sample indexing
---------------
All recursive filters use the convention of the ``ahrs`` package: ``q[0]`` is the
initial orientation and ``q[k]`` is obtained from ``q[k-1]`` with the samples of
index ``k`` (gyroscope ``ω_k`` over ``Δt = 1/fs``, then the correction with
``a_k`` and ``m_k``). This differs by one sample from
:func:`tiltlab.quaternion.integrate_gyro`, which uses ``ω_k`` to go from ``k`` to
``k+1``.

Madgwick and Mahony evaluate their correction at the prior ``q[k-1]`` against ``a_k``
(as in ``ahrs`` and Madgwick's reference code [5]_): under rotation at rate ``|ω|``
this one-sample lag biases the tilt by up to ``|ω|·Δt`` rad. The EKF and the
complementary filter predict first and have no such lag. Madgwick's normalised
gradient step never vanishes, so at rest its estimate chatters within ``2·β·Δt`` rad.

Parity with ``ahrs`` 0.4.0 and its defects
-----------------------------------------
For identical parameters, sampling interval and initial state, :func:`madgwick`,
:func:`mahony` and :func:`ekf` reproduce ``ahrs.filters.Madgwick``, ``Mahony`` and
``EKF`` to ~1e-13 (tests assert 1e-10), except where ``ahrs`` is wrong; those
defects are *not* inherited:

* ``ahrs`` silently assumes 100 Hz when ``frequency`` is not given; here ``fs`` is
  mandatory.
* ``ahrs`` Madgwick and Mahony skip the whole update (accelerometer correction and
  bias integration included) when the gyroscope sample is exactly zero; here the
  correction is always applied. The EKF of ``ahrs`` skips the gyroscope prediction
  when the accelerometer sample is zero; here the prediction is always made.
* ``ahrs`` EKF with ``frame='ENU'`` uses the reference gravity ``(0, 0, -1)``
  although an accelerometer at rest measures the specific force *up*, so its
  output is upside down. Its ``frame='NED'`` uses ``(0, 0, 1)``, i.e. it is really
  a z-up filter; the parity test therefore compares with ``frame='NED'`` and an
  explicit ENU magnetic reference ``magnetic_ref=(0, cos δ, −sin δ)``.
* ``ahrs`` EKF without ``magnetic_ref`` silently uses the field of Munich (WMM);
  here the dip angle is a parameter or is measured from the initial samples.
* ``ahrs`` Madgwick MARG works in Madgwick's NWU earth frame (x magnetic north,
  z up) but initialises with ``ecompass(..., frame='NED')``; it also ignores
  ``q0`` with a magnetometer. Here the filter runs in Madgwick's frame internally
  and inputs/outputs are converted to ENU, ``q_ENU = R_z(90°) ⊗ q_NWU``.
  The parity test checks exactly this transformation.
* ``ahrs`` Madgwick divides by the norm of the gradient without checking it; here a
  zero gradient skips the correction.

References
----------
.. [1] S. O. H. Madgwick, A. J. L. Harrison, R. Vaidyanathan, "Estimation of IMU and
   MARG orientation using a gradient descent algorithm", IEEE ICORR 2011.
   doi:10.1109/ICORR.2011.5975346
.. [2] R. Mahony, T. Hamel, J.-M. Pflimlin, "Nonlinear complementary filters on the
   special orthogonal group", IEEE TAC 53(5):1203–1218, 2008.
   doi:10.1109/TAC.2008.923738
.. [3] R. G. Valenti, I. Dryanovski, J. Xiao, "Keeping a good attitude: a
   quaternion-based orientation filter for IMUs and MARGs", Sensors 15(8):19302, 2015.
   doi:10.3390/s150819302
.. [4] J. L. Crassidis, F. L. Markley, Y. Cheng, "Survey of nonlinear attitude
   estimation methods", J. Guid. Control Dyn. 30(1):12–28, 2007. doi:10.2514/1.22452
.. [5] S. O. H. Madgwick, "An efficient orientation filter for inertial and
   inertial/magnetic sensor arrays", report, University of Bristol, 2010.
.. [6] M. D. Shuster, S. D. Oh, "Three-axis attitude determination from vector
   observations", J. Guid. Control 4(1):70–77, 1981. doi:10.2514/3.19717
.. [7] D. Laidig, T. Seel, "VQF: Highly accurate IMU orientation estimation with bias
   estimation and magnetic disturbance rejection", Information Fusion 91:187–204,
   2023. doi:10.1016/j.inffus.2022.10.014
.. [8] D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust
   Inertial Orientation Estimation", Data 6(7):72, 2021. doi:10.3390/data6070072
.. [9] M. Garillos-Manliguez (ahrs), "AHRS: Attitude and Heading Reference Systems",
   Python package, version 0.4.0.
"""

from ._common import initial_orientation, tilt_quaternion
from .adapters import (
    run_ahrs_ekf,
    run_ahrs_madgwick,
    run_ahrs_mahony,
    run_imufusion,
    run_offline_vqf,
    run_riann,
    run_vqf,
)
from .complementary import complementary, complementary_angles
from .ekf import EkfTuning, ekf
from .eskf import EskfTuning, eskf
from .lowpass import lowpass_tilt
from .learned_gain import GainWeights, learned_gain, load_gain_weights
from .madgwick import madgwick, madgwick_batch
from .mahony import mahony
from .recordings import (
    ESTIMATE_GAP_POLICIES,
    Inputs,
    estimate,
    gravity,
    prepare,
    run,
    run_method,
)
from .registry import (
    METHODS,
    PARAMETER_UNITS,
    SENSORS,
    Method,
    defaults,
    get_method,
    methods,
    missing_sensor_message,
    vector_observation,
)
from .rts import RtsTuning, rts_smoother
from .smoothers import rest_gyro_bias, smoother
from .vectors import davenport, magnetic_dip

__all__ = [
    "METHODS",
    "PARAMETER_UNITS",
    "SENSORS",
    "Method",
    "methods",
    "missing_sensor_message",
    "vector_observation",
    "get_method",
    "defaults",
    "estimate",
    "gravity",
    "prepare",
    "run_method",
    "run",
    "Inputs",
    "ESTIMATE_GAP_POLICIES",
    "initial_orientation",
    "tilt_quaternion",
    "lowpass_tilt",
    "complementary",
    "complementary_angles",
    "madgwick",
    "madgwick_batch",
    "mahony",
    "learned_gain",
    "GainWeights",
    "load_gain_weights",
    "ekf",
    "EkfTuning",
    "eskf",
    "EskfTuning",
    "smoother",
    "rest_gyro_bias",
    "rts_smoother",
    "RtsTuning",
    "run_vqf",
    "run_offline_vqf",
    "run_imufusion",
    "run_riann",
    "davenport",
    "magnetic_dip",
    "run_ahrs_madgwick",
    "run_ahrs_mahony",
    "run_ahrs_ekf",
]
