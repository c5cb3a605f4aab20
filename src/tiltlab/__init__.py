"""tiltlab: head and body orientation from inertial sensors.

Modules follow the data flow of the book: :mod:`tiltlab.schema` (the Recording
contract), :mod:`tiltlab.units`, :mod:`tiltlab.io` (readers and writers),
:mod:`tiltlab.datasets` (the real-data registry) and :mod:`tiltlab.quaternion`
(numba kernels). Import submodules explicitly, e.g. ``import tiltlab.datasets``.
"""

__version__ = "0.1.0"
