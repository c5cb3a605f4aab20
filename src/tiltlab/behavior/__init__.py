r"""Compute behavioural read-outs from head inertial data.

Angular speed, immobility, circling and activity:

* :mod:`~tiltlab.behavior.speed` — angular speed, its still/moving modes and valley,
  gyroscope spectrum, realism table (Fayat et al. 2021 §2.9, Fig. A3);
* :mod:`~tiltlab.behavior.immobility` — immobility on :func:`tiltlab.dsp.still_mask`:
  Fayat's gyroscope rule (§2.9), or a VeDBA rule on recordings without a gyroscope
  (:func:`immobility` picks the rule from the data and records it in its attrs);
* :mod:`~tiltlab.behavior.circling` — azimuthal speed and circling index (§2.10);
* :mod:`~tiltlab.behavior.activity` — static acceleration, DBA/ODBA, one value per step
  (Benhamou 2023 §2, §9).

Without a gyroscope (most bio-logging tags), activity (DBA/ODBA) and immobility (its
accelerometer rule) are computed; angular speed, its spectrum and circling need the
angular velocity and refuse such a Recording by name.

Every function that takes per-sample data accepts a Recording (it reads ``gyr`` or
``acc``), a labelled DataArray or a plain array with ``fs``/``units`` given explicitly.
``fs`` and units are read from the attributes; a missing or contradictory one is a
:class:`~tiltlab._validate.RecordingError` naming it. Labelled input gives labelled
output (DataArrays with ``time``, ``fs`` and ``units``); plain input gives plain
arrays. Thresholds carry their unit in their name (``threshold_deg_s``).

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from ..intervals import intervals_to_mask, mask_to_intervals  # noqa: F401 (convenience)
from .activity import *  # noqa: F401,F403
from .activity import __all__ as _activity
from .circling import *  # noqa: F401,F403
from .circling import __all__ as _circling
from .immobility import *  # noqa: F401,F403
from .immobility import __all__ as _immobility
from .realism import realism_table
from .speed import *  # noqa: F401,F403
from .speed import __all__ as _speed

__all__ = [*_speed, *_immobility, *_circling, *_activity, "realism_table"]
