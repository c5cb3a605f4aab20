r"""Madgwick's gradient-descent orientation filter (6D or 9D), and a parallel gain batch.

Madgwick evaluates the correction at the prior :math:`q_{k-1}` against :math:`a_k` (as
in ``ahrs`` and Madgwick's reference code): under rotation at rate :math:`|\omega|` this
one-sample lag biases the tilt by up to :math:`|\omega|\Delta t` rad. Its normalised
gradient step never vanishes, so at rest the estimate chatters within
:math:`2\beta\Delta t` rad.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as _v
from ._common import read_sensors, start_orientation
from ._docs import shared_docs
from ._madgwick_kernel import (
    _madgwick6_kernel,
    _madgwick9_kernel,
    _madgwick_batch_kernel,
)

__all__ = ["madgwick", "madgwick_batch"]


#: largest gradient step per sample, beta/fs (rad): below 1 the update cannot cancel
#: the quaternion (its gyroscope part is orthogonal to q), and 0.5 keeps its norm ≥ 0.5
MAX_STEP_RAD = 0.5


def _gradient_step(beta, fs: float, name: str) -> float:
    """Check a gain ``beta`` (rad/s): ``>= 0`` and ``beta/fs <= MAX_STEP_RAD``."""
    beta = _v.nonnegative(beta, name)
    if beta / fs > MAX_STEP_RAD:
        raise ValueError(
            f"{name} = {beta:g} rad/s is too large for fs = {fs:g} Hz: the gradient "
            f"step per sample ({name}/fs = {beta / fs:.3g} rad) must stay at most "
            f"{MAX_STEP_RAD:g} rad, or the update can cancel the quaternion"
        )
    return beta


@shared_docs
def madgwick(
    acc,
    gyr,
    fs: float | None = None,
    *,
    mag=None,
    beta: float = 0.05,
    q0=None,
    init_window_s: float = 0.1,
) -> np.ndarray:
    r"""Madgwick's gradient-descent orientation filter (6D or 9D).

    .. math::
        \dot q = \tfrac12\, q \otimes (0, \omega_k) - \beta\,
        \frac{\nabla f}{\|\nabla f\|},\qquad \nabla f = J^\top(q)\, f(q),
        \qquad q_k = \frac{q_{k-1} + \dot q\,\Delta t}{\|\cdot\|}

    with :math:`f = R(q)^\top d - \hat s` stacked over gravity (:math:`d = e_z`,
    :math:`\hat s = \hat a`) and, in 9D, the magnetic field (:math:`d = b = (b_x, 0, b_z)`
    in Madgwick's earth frame, :math:`b_x = \|h_{xy}\|`, :math:`b_z = h_z`,
    :math:`h = R(q)\hat m`). In 9D the kernel runs in Madgwick's NWU frame and converts
    inputs/outputs to ENU (:math:`q_{ENU} = R_z(90°) \otimes q_{NWU}`), which leaves the
    update equivariant. Equal to ``ahrs.filters.Madgwick`` for the same ``beta``
    (``gain``), ``Dt = 1/fs`` and initial state (:mod:`tiltlab.filters` lists its
    defects). A zero gradient skips the correction.

    Parameters
    ----------
    acc, gyr : array_like or xarray.DataArray, shape (N, 3)
        Specific force (any unit, normalised per sample) and angular velocity (rad/s).
        %(labelled)s
    %(fs)s
    %(mag)s
    beta : float
        Gradient step (rad/s), ``>= 0`` and at most ``0.5 * fs`` (a larger step per
        sample can cancel the quaternion).
    %(q0_init)s

    Returns
    -------
    %(q_out)s

    Examples
    --------
    A sensor lying still, tilted 30° about x, gyroscope reading zero: the filter
    keeps the tilt of the initial orientation (heading zero), chattering within
    ``2 * beta / fs`` = 0.002 rad around it (which way each step goes depends on
    rounding: only the tilt to 0.01 is shown).

    >>> import numpy as np
    >>> from tiltlab import filters, quaternion
    >>> up = [0.0, np.sin(np.radians(30.0)), np.cos(np.radians(30.0))]
    >>> acc = np.tile(np.multiply(up, 9.81), (200, 1))
    >>> q = filters.madgwick(acc, np.zeros((200, 3)), 100.0, beta=0.1)
    >>> q.shape
    (200, 4)
    >>> np.round(quaternion.gravity(q[-1]), 2)
    array([0.  , 0.5 , 0.87])
    """
    fs, acc, gyr, m, use_mag = read_sensors(fs, acc, gyr, mag)
    beta = _gradient_step(beta, fs, "beta")
    q0 = start_orientation(q0, acc, m if use_mag else None, fs, init_window_s)
    out = np.empty((acc.shape[0], 4))
    if use_mag:  # one kernel each, so that a first call compiles only the one it runs
        _madgwick9_kernel(acc, gyr, m, 1.0 / fs, beta, q0, out)
    else:
        _madgwick6_kernel(acc, gyr, 1.0 / fs, beta, q0, out)
    return out


def madgwick_batch(
    acc,
    gyr,
    fs: float | None = None,
    *,
    betas,
    mag=None,
    q0=None,
    init_window_s: float = 0.1,
) -> np.ndarray:
    """Madgwick over several gains at once, in parallel (numba ``prange`` over ``betas``).

    Parameters
    ----------
    acc, gyr, fs, mag, q0, init_window_s
        As for :func:`madgwick`.
    betas : array_like, shape (P,)
        Gradient steps (rad/s), each ``>= 0`` and at most ``0.5 * fs``.

    Returns
    -------
    numpy.ndarray, shape (P, N, 4)
        ``out[p]`` equals ``madgwick(acc, gyr, fs, beta=betas[p], ...)`` exactly.
    """
    fs, acc, gyr, m, use_mag = read_sensors(fs, acc, gyr, mag)
    b = _v.vectors(np.atleast_1d(betas), "betas", width=None, ndim=1)
    for j, v in enumerate(b):
        _gradient_step(v, fs, f"betas[{j}]")
    q0 = start_orientation(q0, acc, m if use_mag else None, fs, init_window_s)
    out = np.empty((b.shape[0], acc.shape[0], 4))
    _madgwick_batch_kernel(
        acc, gyr, m, use_mag, 1.0 / fs, np.ascontiguousarray(b), q0, out
    )
    return out
