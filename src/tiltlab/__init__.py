"""tiltlab: head and body orientation from inertial sensors.

Modules follow the data flow of the book: :mod:`tiltlab.schema` (the Recording
contract), :mod:`tiltlab.units`, :mod:`tiltlab.io` (readers and writers),
:mod:`tiltlab.datasets` (the real-data registry) and :mod:`tiltlab.quaternion`
(numba kernels). Import submodules explicitly, e.g. ``import tiltlab.datasets``.

:class:`RecordingError` is the error every module raises for data that break the
Recording contract (a missing sampling rate or unit, a wrong shape, a unit the values
contradict: :class:`tiltlab.quality.UnitCheckError` is one).
"""

__version__ = "0.1.0"

from ._validate import RecordingError  # noqa: E402 (the version first)

__all__ = ["RecordingError", "__version__"]
