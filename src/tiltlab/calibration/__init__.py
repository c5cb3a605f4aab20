r"""Sensor calibration and drift: still periods, fits, offsets, clocks and alignment.

Sensor calibration and drift: still periods, accelerometer sphere/ellipsoid fits,
gyroscope offsets and drift, tumble-test design, temperature models, magnetometer
calibration, clocks between streams and frame alignment.

Layer 4: uses only :mod:`tiltlab.units`, :mod:`tiltlab._validate`, :mod:`tiltlab.dsp`,
:mod:`tiltlab.frames`, :mod:`tiltlab.intervals` and :mod:`tiltlab.quaternion`.

Every function that takes per-sample data and a sampling rate takes the data first
(a Recording, a labelled DataArray — ``fs`` and ``units`` are read from the attrs — or
a plain array with an explicit ``fs``), then ``fs``, then keyword-only options.
Durations end in ``_s``, frequencies in ``_hz``, thresholds in their unit
(``threshold_deg_s``, ``acc_std_threshold_g``).

Submodules (all public names are re-exported here):

* :mod:`~tiltlab.calibration.static` — still-period detection (on
  :func:`tiltlab.dsp.still_mask`), per-period statistics, gyro offsets;
* :mod:`~tiltlab.calibration.accel` — Fayat offset fit, 9-parameter ellipsoid fit,
  12-parameter known-direction fit, Fibonacci lattice and stage angles;
* :mod:`~tiltlab.calibration.orientations` — tumble-test design: lattice subsets,
  orientation-count studies, systematic offset uncertainty;
* :mod:`~tiltlab.calibration.temperature` — polynomial offset-vs-temperature models;
* :mod:`~tiltlab.calibration.drift` — integrated static angles, LaCanna's three drift
  corrections, Allan deviation;
* :mod:`~tiltlab.calibration.magnetometer` — four-point (Benhamou Eq. 4), min/max, ellipsoid;
* :mod:`~tiltlab.calibration.clocks` — lag by cross-correlation, TTL slip repair;
* :mod:`~tiltlab.calibration.alignment` — head frame from markers, marker QC, Kabsch
  alignment, mounting rotation;
* :mod:`~tiltlab.calibration.markers` — motion-capture marker gaps, short ones filled
  by quadratic interpolation;
* :mod:`~tiltlab.calibration.apply` — the :class:`Calibration` record and :func:`calibrate`.
* :mod:`~tiltlab.calibration.summaries` — per-sample norm error, Allan noise table.
* :mod:`~tiltlab.calibration.published` — LaCanna's Tables 2–6 and their summaries (not
  re-exported here).
"""

from ._util import CalibrationError
from .accel import *  # noqa: F401,F403
from .accel import __all__ as _a
from .alignment import *  # noqa: F401,F403
from .alignment import __all__ as _e
from .apply import *  # noqa: F401,F403
from .apply import __all__ as _b
from .clocks import *  # noqa: F401,F403
from .clocks import __all__ as _c
from .drift import *  # noqa: F401,F403
from .drift import __all__ as _d
from .magnetometer import *  # noqa: F401,F403
from .magnetometer import __all__ as _f
from .markers import *  # noqa: F401,F403
from .markers import __all__ as _m
from .orientations import *  # noqa: F401,F403
from .orientations import __all__ as _o
from .static import *  # noqa: F401,F403
from .static import __all__ as _g
from .summaries import *  # noqa: F401,F403
from .summaries import __all__ as _s
from .temperature import *  # noqa: F401,F403
from .temperature import __all__ as _h

__all__ = ["CalibrationError", *_a, *_e, *_b, *_c, *_d, *_f, *_o, *_g, *_h, *_s, *_m]
