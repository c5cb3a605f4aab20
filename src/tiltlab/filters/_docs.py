"""Share the numpydoc fragments that the filters' docstrings have in common.

The parameters every filter takes (``fs``, ``mag``, ``q0``, ``init_window_s``, the
labelled-input rules) are described once, in :data:`FRAGMENTS`; a docstring names a
fragment on a line of its own as ``%(name)s`` and :func:`shared_docs` fills it in,
indented as that line.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

__all__ = ["FRAGMENTS", "shared_docs"]

#: numpydoc fragments by name (indented relative to their placeholder line)
FRAGMENTS = {
    "acc_gyr": """\
acc, gyr : array_like or xarray.DataArray, shape (N, 3)
    Specific force (any unit) and angular velocity (rad/s).
    %(labelled)s""",
    "labelled": """\
Labelled inputs (:class:`xarray.DataArray`) are read by their attributes:
``gyr`` is converted from its ``units`` (required) to rad/s, ``acc`` with
``units`` to m/s² (see :mod:`tiltlab.filters`, "Labelled inputs").""",
    "fs": """\
fs : float, optional
    Sampling rate (Hz): mandatory for plain arrays; with labelled inputs it may
    be omitted when they carry ``attrs["fs"]``, and must agree with it when given.""",
    "mag": """\
mag : array_like or xarray.DataArray, shape (N, 3), optional
    Magnetometer (any unit; a ``units`` attribute must be a magnetic-field unit):
    9D, ENU world frame.""",
    "q0_init": """\
q0 : array_like, shape (4,), optional
    Initial orientation; default :func:`initial_orientation` over
    ``init_window_s`` seconds.
init_window_s : float
    Initialisation window (s).""",
    "si_inputs": """\
acc : array_like or xarray.DataArray, shape (N, 3)
    Specific force, m/s² (a labelled DataArray: converted from its ``units``).
gyr : array_like or xarray.DataArray, shape (N, 3)
    Angular rate, rad/s (a labelled DataArray: converted from its ``units``).
fs : float, optional
    Sampling rate, Hz (mandatory for plain arrays; labelled inputs may carry it
    as ``attrs["fs"]``).""",
    "ahrs_init": """\
init_window_s : float
    Duration (s) of the start of the record whose mean orientation starts the
    filter.""",
    "q_z_up": """\
numpy.ndarray, shape (N, 4)
    Unit quaternions (w, x, y, z) sensor → world, world z up, heading arbitrary.""",
    "vqf_mag": """\
mag : array_like or xarray.DataArray, shape (N, 3), optional
    Magnetic field (any consistent unit); given, the 9D filter runs, else 6D.""",
    "q_6d_9d": """\
numpy.ndarray, shape (N, 4)
    Unit quaternions (w, x, y, z) sensor → world, world z up (heading arbitrary
    in 6D).""",
    "offset_bias": """\
gyr_offset : array_like, shape (3,), optional
    Initial gyroscope offset (bias; rad/s, whatever the units of a labelled
    ``gyr``), default zero. Formerly ``b0`` (still accepted, with a
    FutureWarning).
init_window_s : float
    Initialisation window (s).
return_bias : bool
    Also return the bias estimates, shape (N, 3) (rad/s).""",
    "q_out": """\
numpy.ndarray, shape (N, 4)
    Unit quaternions (w, x, y, z) sensor → world.""",
}


def _fill(text: str) -> str:
    """Replace each placeholder line of ``text`` by its fragment, itself filled in."""
    out = []
    for line in text.splitlines():
        key = line.strip()
        if key.startswith("%(") and key.endswith(")s"):
            pad = line[: len(line) - len(line.lstrip())]
            out += [pad + t for t in _fill(FRAGMENTS[key[2:-2]]).splitlines()]
        else:
            out.append(line)
    return "\n".join(out)


def shared_docs(func: F) -> F:
    """Fill the ``%(name)s`` placeholder lines of a docstring from :data:`FRAGMENTS`.

    Parameters
    ----------
    func : callable
        A function whose docstring has placeholder lines (a line holding only
        ``%(name)s`` for a name of :data:`FRAGMENTS`).

    Returns
    -------
    callable
        ``func`` itself, its ``__doc__`` filled in (each fragment indented as its
        placeholder line); an unknown name is a KeyError.
    """
    func.__doc__ = _fill(func.__doc__ or "")
    return func
