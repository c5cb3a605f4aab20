r"""Madgwick's gradient-descent orientation filter (6D or 9D), and a parallel gain batch.

Madgwick evaluates the correction at the prior :math:`q_{k-1}` against :math:`a_k` (as
in ``ahrs`` and Madgwick's reference code): under rotation at rate :math:`|\omega|` this
one-sample lag biases the tilt by up to :math:`|\omega|\Delta t` rad. Its normalised
gradient step never vanishes, so at rest the estimate chatters within
:math:`2\beta\Delta t` rad.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .. import _validate as _v
from ..quaternion import qmul_scalar, rotate_scalar
from ._common import read_sensors, start_orientation
from ._shared_kernel import _unit_sample
from ._docs import shared_docs

__all__ = ["madgwick", "madgwick_batch"]

_C = 0.7071067811865476  # cos 45° = sin 45°


@njit(cache=True, nogil=True)
def _madgwick_kernel(acc, gyr, mag, use_mag, dt, beta, q0, out):
    # q0 and out in ENU; the MARG update runs in Madgwick's NWU earth frame:
    # q_nwu = Rz(-90°) ⊗ q_enu, q_enu = Rz(+90°) ⊗ q_nwu (identical for 6D).
    c = _C
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    if use_mag:
        w, x, y, z = qmul_scalar(c, 0.0, 0.0, -c, w, x, y, z)
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = q0[0], q0[1], q0[2], q0[3]
    for k in range(1, acc.shape[0]):
        # qdot = 1/2 q ⊗ (0, ω)
        dw, dx, dy, dz = qmul_scalar(w, x, y, z, 0.0, gyr[k, 0], gyr[k, 1], gyr[k, 2])
        dw, dx, dy, dz = 0.5 * dw, 0.5 * dx, 0.5 * dy, 0.5 * dz
        ax, ay, az, an = _unit_sample(acc, k)
        if an > 0.0:
            # objective f = R(q)^T d - s and Jacobian J (Madgwick 2010 eqs. 25-26, 31-32)
            f1 = 2.0 * (x * z - w * y) - ax
            f2 = 2.0 * (w * x + y * z) - ay
            f3 = 2.0 * (0.5 - x * x - y * y) - az
            s0 = -2.0 * y * f1 + 2.0 * x * f2
            s1 = 2.0 * z * f1 + 2.0 * w * f2 - 4.0 * x * f3
            s2 = -2.0 * w * f1 + 2.0 * z * f2 - 4.0 * y * f3
            s3 = 2.0 * x * f1 + 2.0 * y * f2
            mx, my, mz, mn = 0.0, 0.0, 0.0, 0.0
            if use_mag:
                mx, my, mz, mn = _unit_sample(mag, k)
            if mn > 0.0:
                # h = R(q) m (earth frame), reference b = (|h_xy|, 0, h_z)
                hx, hy, hz = rotate_scalar(w, x, y, z, mx, my, mz)
                bx = np.sqrt(hx * hx + hy * hy)
                bz = hz
                f4 = 2.0 * bx * (0.5 - y * y - z * z) + 2.0 * bz * (x * z - w * y) - mx
                f5 = 2.0 * bx * (x * y - w * z) + 2.0 * bz * (w * x + y * z) - my
                f6 = 2.0 * bx * (w * y + x * z) + 2.0 * bz * (0.5 - x * x - y * y) - mz
                s0 += (
                    -2.0 * bz * y * f4
                    + (-2.0 * bx * z + 2.0 * bz * x) * f5
                    + 2.0 * bx * y * f6
                )
                s1 += (
                    2.0 * bz * z * f4
                    + (2.0 * bx * y + 2.0 * bz * w) * f5
                    + (2.0 * bx * z - 4.0 * bz * x) * f6
                )
                s2 += (
                    (-4.0 * bx * y - 2.0 * bz * w) * f4
                    + (2.0 * bx * x + 2.0 * bz * z) * f5
                    + (2.0 * bx * w - 4.0 * bz * y) * f6
                )
                s3 += (
                    (-4.0 * bx * z + 2.0 * bz * x) * f4
                    + (-2.0 * bx * w + 2.0 * bz * y) * f5
                    + 2.0 * bx * x * f6
                )
            sn = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2 + s3 * s3)
            if sn > 0.0:
                g = beta / sn  # one division for the four components
                dw -= g * s0
                dx -= g * s1
                dy -= g * s2
                dz -= g * s3
        w, x, y, z = w + dw * dt, x + dx * dt, y + dy * dt, z + dz * dt
        r = 1.0 / np.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w * r, x * r, y * r, z * r
        if use_mag:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = qmul_scalar(
                c, 0.0, 0.0, c, w, x, y, z
            )
        else:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z


@njit(cache=True, nogil=True, parallel=True)
def _madgwick_batch_kernel(acc, gyr, mag, use_mag, dt, betas, q0, out):
    for p in prange(betas.shape[0]):
        _madgwick_kernel(acc, gyr, mag, use_mag, dt, betas[p], q0, out[p])


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
    keeps the tilt of the initial orientation (heading zero).

    >>> import numpy as np
    >>> from tiltlab import filters, quaternion
    >>> up = [0.0, np.sin(np.radians(30.0)), np.cos(np.radians(30.0))]
    >>> acc = np.tile(np.multiply(up, 9.81), (200, 1))
    >>> q = filters.madgwick(acc, np.zeros((200, 3)), 100.0, beta=0.1)
    >>> q.shape
    (200, 4)
    >>> np.round(quaternion.gravity(q[-1]), 3)
    array([0.   , 0.5  , 0.866])
    """
    fs, acc, gyr, m, use_mag = read_sensors(fs, acc, gyr, mag)
    beta = _gradient_step(beta, fs, "beta")
    q0 = start_orientation(q0, acc, m if use_mag else None, fs, init_window_s)
    out = np.empty((acc.shape[0], 4))
    _madgwick_kernel(acc, gyr, m, use_mag, 1.0 / fs, beta, q0, out)
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
