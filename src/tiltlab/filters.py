r"""Orientation filters: numba kernels, the :func:`estimate` wrapper, parameter grids
and BROAD-style evaluation.

Every filter turns a Recording's accelerometer (specific force), gyroscope and
optionally magnetometer samples into unit quaternions ``q`` (scalar first) that
rotate **sensor → world**, world z up. With a magnetometer ("9D") the world frame
is ENU (x east, y magnetic north, z up); without one ("6D") the heading of the
world frame is arbitrary (fixed by the initial orientation).

Methods
-------
``lowpass``
    Tilt from the normalised, zero-phase low-passed accelerometer (2nd-order
    Butterworth, forward–backward; scipy). 6D only, heading zero.
``complementary``
    Gyroscope integration corrected towards the accelerometer (and magnetometer)
    by geometric rotations in the world frame, with time constants.
``madgwick``
    Gradient-descent correction (Madgwick 2010/2011).
``mahony``
    Explicit complementary filter with proportional and integral (gyro bias) terms
    (Mahony 2008).
``ekf``
    Quaternion-state extended Kalman filter with the gravity (and magnetic field)
    direction as measurement (the formulation of the ``ahrs`` package).
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
``imufusion``
    Adapter to the ``imufusion`` package (x-io Fusion AHRS, 6D), for comparison.
``ahrs_madgwick``, ``ahrs_mahony``, ``ahrs_ekf``
    Adapters to the pure-Python ``ahrs`` package (6D; slow: use short recordings), for
    comparison; the EKF runs with ``frame='NED'`` (really z up, see below).

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

from __future__ import annotations

import itertools
import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import xarray as xr
from numba import njit, prange

from . import quaternion as quat
from .quaternion import rotate_scalar, zoh_step_scalar
from . import units as _units
from .units import check_fs as _check_fs

__all__ = [
    "METHODS",
    "initial_orientation",
    "lowpass_tilt",
    "complementary",
    "madgwick",
    "mahony",
    "ekf",
    "smoother",
    "rts_smoother",
    "rest_gyro_bias",
    "madgwick_batch",
    "estimate",
    "gravity",
    "grid_search",
    "broad_errors",
    "tilt_rmse",
]

_SQRT_HALF = np.sqrt(0.5)


# ====================================================================== kernels


@njit(cache=True, nogil=True)
def _madgwick_kernel(acc, gyr, mag, use_mag, dt, beta, q0, out):
    # q0 and out in ENU; the MARG update runs in Madgwick's NWU earth frame:
    # q_nwu = Rz(-90°) ⊗ q_enu, q_enu = Rz(+90°) ⊗ q_nwu (identical for 6D).
    c = 0.7071067811865476
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    if use_mag:
        w, x, y, z = c * w + c * z, c * x + c * y, c * y - c * x, c * z - c * w
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = q0[0], q0[1], q0[2], q0[3]
    for k in range(1, acc.shape[0]):
        gx, gy, gz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        # qdot = 1/2 q ⊗ (0, ω)
        dw = 0.5 * (-x * gx - y * gy - z * gz)
        dx = 0.5 * (w * gx + y * gz - z * gy)
        dy = 0.5 * (w * gy - x * gz + z * gx)
        dz = 0.5 * (w * gz + x * gy - y * gx)
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        an = np.sqrt(ax * ax + ay * ay + az * az)
        if an > 0.0:
            ax, ay, az = ax / an, ay / an, az / an
            # objective f = R(q)^T d - s and Jacobian J (Madgwick 2010 eqs. 25-26, 31-32)
            f1 = 2.0 * (x * z - w * y) - ax
            f2 = 2.0 * (w * x + y * z) - ay
            f3 = 2.0 * (0.5 - x * x - y * y) - az
            s0 = -2.0 * y * f1 + 2.0 * x * f2
            s1 = 2.0 * z * f1 + 2.0 * w * f2 - 4.0 * x * f3
            s2 = -2.0 * w * f1 + 2.0 * z * f2 - 4.0 * y * f3
            s3 = 2.0 * x * f1 + 2.0 * y * f2
            mx, my, mz = 0.0, 0.0, 0.0
            mn = 0.0
            if use_mag:
                mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
                mn = np.sqrt(mx * mx + my * my + mz * mz)
            if mn > 0.0:
                mx, my, mz = mx / mn, my / mn, mz / mn
                # h = R(q) m (earth frame), reference b = (|h_xy|, 0, h_z)
                hx, hy, hz = rotate_scalar(w, x, y, z, mx, my, mz)
                bx = np.sqrt(hx * hx + hy * hy)
                bz = hz
                f4 = 2.0 * bx * (0.5 - y * y - z * z) + 2.0 * bz * (x * z - w * y) - mx
                f5 = 2.0 * bx * (x * y - w * z) + 2.0 * bz * (w * x + y * z) - my
                f6 = 2.0 * bx * (w * y + x * z) + 2.0 * bz * (0.5 - x * x - y * y) - mz
                s0 += -2.0 * bz * y * f4 + (-2.0 * bx * z + 2.0 * bz * x) * f5 + 2.0 * bx * y * f6
                s1 += 2.0 * bz * z * f4 + (2.0 * bx * y + 2.0 * bz * w) * f5 + (2.0 * bx * z - 4.0 * bz * x) * f6
                s2 += (-4.0 * bx * y - 2.0 * bz * w) * f4 + (2.0 * bx * x + 2.0 * bz * z) * f5 + (2.0 * bx * w - 4.0 * bz * y) * f6
                s3 += (-4.0 * bx * z + 2.0 * bz * x) * f4 + (-2.0 * bx * w + 2.0 * bz * y) * f5 + 2.0 * bx * x * f6
            sn = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2 + s3 * s3)
            if sn > 0.0:
                dw -= beta * s0 / sn
                dx -= beta * s1 / sn
                dy -= beta * s2 / sn
                dz -= beta * s3 / sn
        w, x, y, z = w + dw * dt, x + dx * dt, y + dy * dt, z + dz * dt
        n = np.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w / n, x / n, y / n, z / n
        if use_mag:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = c * w - c * z, c * x - c * y, c * y + c * x, c * z + c * w
        else:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z


@njit(cache=True, nogil=True, parallel=True)
def _madgwick_batch_kernel(acc, gyr, mag, use_mag, dt, betas, q0, out):
    for p in prange(betas.shape[0]):
        _madgwick_kernel(acc, gyr, mag, use_mag, dt, betas[p], q0, out[p])


@njit(cache=True, nogil=True)
def _mahony_kernel(acc, gyr, mag, use_mag, dt, kp, ki, q0, b0, out, bias):
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    bx_, by_, bz_ = b0[0], b0[1], b0[2]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    bias[0, 0], bias[0, 1], bias[0, 2] = bx_, by_, bz_
    for k in range(1, acc.shape[0]):
        ox, oy, oz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        an = np.sqrt(ax * ax + ay * ay + az * az)
        ex, ey, ez = 0.0, 0.0, 0.0
        have = False
        if an > 0.0:
            ax, ay, az = ax / an, ay / an, az / an
            # estimated gravity-up in the sensor frame: third row of R(q)
            vx = 2.0 * (x * z - w * y)
            vy = 2.0 * (w * x + y * z)
            vz = 1.0 - 2.0 * (x * x + y * y)
            ex += ay * vz - az * vy
            ey += az * vx - ax * vz
            ez += ax * vy - ay * vx
            have = True
        if use_mag:
            mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
            mn = np.sqrt(mx * mx + my * my + mz * mz)
            if mn > 0.0:
                mx, my, mz = mx / mn, my / mn, mz / mn
                hx, hy, hz = rotate_scalar(w, x, y, z, mx, my, mz)
                # expected field in the sensor frame: R^T (0, |h_xy|, h_z) (ENU: y north)
                hn = np.sqrt(hx * hx + hy * hy)
                wx, wy, wz = rotate_scalar(w, -x, -y, -z, 0.0, hn, hz)
                wn = np.sqrt(wx * wx + wy * wy + wz * wz)
                wx, wy, wz = wx / wn, wy / wn, wz / wn
                ex += my * wz - mz * wy
                ey += mz * wx - mx * wz
                ez += mx * wy - my * wx
                have = True
        if have:
            bx_ -= ki * ex * dt
            by_ -= ki * ey * dt
            bz_ -= ki * ez * dt
            ox = ox - bx_ + kp * ex
            oy = oy - by_ + kp * ey
            oz = oz - bz_ + kp * ez
        else:
            ox, oy, oz = ox - bx_, oy - by_, oz - bz_
        h = 0.5 * dt
        nw = w + h * (-x * ox - y * oy - z * oz)
        nx = x + h * (w * ox + y * oz - z * oy)
        ny = y + h * (w * oy - x * oz + z * ox)
        nz = z + h * (w * oz + x * oy - y * ox)
        n = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        w, x, y, z = nw / n, nx / n, ny / n, nz / n
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
        bias[k, 0], bias[k, 1], bias[k, 2] = bx_, by_, bz_


@njit(cache=True, nogil=True)
def _mahony_batch_kernel_one(acc, gyr, mag, use_mag, dt, kp, ki, q0, b0, out):
    bias = np.empty((acc.shape[0], 3))
    _mahony_kernel(acc, gyr, mag, use_mag, dt, kp, ki, q0, b0, out, bias)


@njit(cache=True, nogil=True)
def _invert_small(A, m, Ainv, work):
    # Gauss-Jordan with partial pivoting on the leading m x m block of A
    for i in range(m):
        for j in range(m):
            work[i, j] = A[i, j]
            Ainv[i, j] = 1.0 if i == j else 0.0
    for col in range(m):
        piv = col
        best = abs(work[col, col])
        for r in range(col + 1, m):
            if abs(work[r, col]) > best:
                best = abs(work[r, col])
                piv = r
        if piv != col:
            for j in range(m):
                t = work[col, j]
                work[col, j] = work[piv, j]
                work[piv, j] = t
                t = Ainv[col, j]
                Ainv[col, j] = Ainv[piv, j]
                Ainv[piv, j] = t
        d = work[col, col]
        for j in range(m):
            work[col, j] /= d
            Ainv[col, j] /= d
        for r in range(m):
            if r != col:
                f = work[r, col]
                if f != 0.0:
                    for j in range(m):
                        work[r, j] -= f * work[col, j]
                        Ainv[r, j] -= f * Ainv[col, j]


@njit(cache=True, nogil=True)
def _ekf_h_rows(H, row, v, w, x, y, z):
    # rows of d(R(q)^T v)/dq (ahrs/EKF convention, factor 2 included)
    v0, v1, v2 = v[0], v[1], v[2]
    H[row, 0] = 2.0 * (v0 * w + v1 * z - v2 * y)
    H[row, 1] = 2.0 * (v0 * x + v1 * y + v2 * z)
    H[row, 2] = 2.0 * (-v0 * y + v1 * x - v2 * w)
    H[row, 3] = 2.0 * (-v0 * z + v1 * w + v2 * x)
    H[row + 1, 0] = 2.0 * (-v0 * z + v1 * w + v2 * x)
    H[row + 1, 1] = 2.0 * (v0 * y - v1 * x + v2 * w)
    H[row + 1, 2] = 2.0 * (v0 * x + v1 * y + v2 * z)
    H[row + 1, 3] = 2.0 * (-v0 * w - v1 * z + v2 * y)
    H[row + 2, 0] = 2.0 * (v0 * y - v1 * x + v2 * w)
    H[row + 2, 1] = 2.0 * (v0 * z - v1 * w - v2 * x)
    H[row + 2, 2] = 2.0 * (v0 * w + v1 * z - v2 * y)
    H[row + 2, 3] = 2.0 * (v0 * x + v1 * y + v2 * z)


@njit(cache=True, nogil=True)
def _ekf_h_pred(hp, row, v, w, x, y, z):
    # R(q)^T v for a unit q
    hp[row], hp[row + 1], hp[row + 2] = rotate_scalar(w, -x, -y, -z, v[0], v[1], v[2])


@njit(cache=True, nogil=True)
def _ekf_kernel(acc, gyr, mag, use_mag, dt, var_gyr, var_acc, var_mag, m_ref, P0, q0, out):
    a_ref = np.array([0.0, 0.0, 1.0])
    P = P0.copy()
    Pt = np.empty((4, 4))
    FP = np.empty((4, 4))
    W = np.empty((4, 3))
    H = np.empty((6, 4))
    PHt = np.empty((4, 6))
    S = np.empty((6, 6))
    Si = np.empty((6, 6))
    work = np.empty((6, 6))
    K = np.empty((4, 6))
    KH = np.empty((4, 4))
    meas = np.empty(6)
    hp = np.empty(6)
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    hdt = 0.5 * dt
    for k in range(1, acc.shape[0]):
        gx, gy, gz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        # ---- prediction: q_t = (I + dt/2 Ω(ω)) q, F = I + Ω(dt ω / 2)
        tw = w - hdt * (gx * x + gy * y + gz * z)
        tx = x + hdt * (gx * w + gz * y - gy * z)
        ty = y + hdt * (gy * w - gz * x + gx * z)
        tz = z + hdt * (gz * w + gy * x - gx * y)
        ox, oy, oz = hdt * gx, hdt * gy, hdt * gz
        # W = dq_t/dω (at the prior q)
        W[0, 0], W[0, 1], W[0, 2] = -hdt * x, -hdt * y, -hdt * z
        W[1, 0], W[1, 1], W[1, 2] = hdt * w, -hdt * z, hdt * y
        W[2, 0], W[2, 1], W[2, 2] = hdt * z, hdt * w, -hdt * x
        W[3, 0], W[3, 1], W[3, 2] = -hdt * y, hdt * x, hdt * w
        # FP = F P
        for j in range(4):
            p0, p1, p2, p3 = P[0, j], P[1, j], P[2, j], P[3, j]
            FP[0, j] = p0 - ox * p1 - oy * p2 - oz * p3
            FP[1, j] = ox * p0 + p1 + oz * p2 - oy * p3
            FP[2, j] = oy * p0 - oz * p1 + p2 + ox * p3
            FP[3, j] = oz * p0 + oy * p1 - ox * p2 + p3
        # Pt = FP F^T + var_gyr W W^T
        for i in range(4):
            p0, p1, p2, p3 = FP[i, 0], FP[i, 1], FP[i, 2], FP[i, 3]
            Pt[i, 0] = p0 - ox * p1 - oy * p2 - oz * p3
            Pt[i, 1] = ox * p0 + p1 + oz * p2 - oy * p3
            Pt[i, 2] = oy * p0 - oz * p1 + p2 + ox * p3
            Pt[i, 3] = oz * p0 + oy * p1 - ox * p2 + p3
            for j in range(4):
                Pt[i, j] += var_gyr * (W[i, 0] * W[j, 0] + W[i, 1] * W[j, 1] + W[i, 2] * W[j, 2])
        # ---- correction
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        an = np.sqrt(ax * ax + ay * ay + az * az)
        m = 0
        if an > 0.0:
            meas[0], meas[1], meas[2] = ax / an, ay / an, az / an
            m = 3
            if use_mag:
                mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
                mn = np.sqrt(mx * mx + my * my + mz * mz)
                if mn > 0.0:
                    meas[3], meas[4], meas[5] = mx / mn, my / mn, mz / mn
                    m = 6
        if m == 0:
            n = np.sqrt(tw * tw + tx * tx + ty * ty + tz * tz)
            w, x, y, z = tw / n, tx / n, ty / n, tz / n
            for i in range(4):
                for j in range(4):
                    P[i, j] = Pt[i, j]
        else:
            # expected measurement at the normalised q_t, Jacobian at the raw q_t (as ahrs)
            n = np.sqrt(tw * tw + tx * tx + ty * ty + tz * tz)
            _ekf_h_pred(hp, 0, a_ref, tw / n, tx / n, ty / n, tz / n)
            _ekf_h_rows(H, 0, a_ref, tw, tx, ty, tz)
            if m == 6:
                _ekf_h_pred(hp, 3, m_ref, tw / n, tx / n, ty / n, tz / n)
                _ekf_h_rows(H, 3, m_ref, tw, tx, ty, tz)
            for i in range(4):
                for r in range(m):
                    PHt[i, r] = Pt[i, 0] * H[r, 0] + Pt[i, 1] * H[r, 1] + Pt[i, 2] * H[r, 2] + Pt[i, 3] * H[r, 3]
            for r in range(m):
                for s in range(m):
                    S[r, s] = H[r, 0] * PHt[0, s] + H[r, 1] * PHt[1, s] + H[r, 2] * PHt[2, s] + H[r, 3] * PHt[3, s]
                S[r, r] += var_acc if r < 3 else var_mag
            _invert_small(S, m, Si, work)
            for i in range(4):
                for r in range(m):
                    acc_ = 0.0
                    for s in range(m):
                        acc_ += PHt[i, s] * Si[s, r]
                    K[i, r] = acc_
            for i in range(4):
                for j in range(4):
                    acc_ = 0.0
                    for r in range(m):
                        acc_ += K[i, r] * H[r, j]
                    KH[i, j] = acc_
            for i in range(4):
                for j in range(4):
                    acc_ = Pt[i, j]
                    for l in range(4):
                        acc_ -= KH[i, l] * Pt[l, j]
                    P[i, j] = acc_
            cw, cx, cy, cz = tw, tx, ty, tz
            for r in range(m):
                v = meas[r] - hp[r]
                cw += K[0, r] * v
                cx += K[1, r] * v
                cy += K[2, r] * v
                cz += K[3, r] * v
            n = np.sqrt(cw * cw + cx * cx + cy * cy + cz * cz)
            w, x, y, z = cw / n, cx / n, cy / n, cz / n
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z


@njit(cache=True, nogil=True)
def _complementary_kernel(acc, gyr, mag, use_mag, dt, k_acc, k_mag, q0, out):
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    for k in range(1, acc.shape[0]):
        # exact zero-order-hold propagation q ← q ⊗ exp(ω dt / 2)
        w, x, y, z = zoh_step_scalar(w, x, y, z, gyr[k, 0] * dt, gyr[k, 1] * dt, gyr[k, 2] * dt)
        # accelerometer: rotate the world-frame measured "up" towards e_z (axis horizontal)
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        an = np.sqrt(ax * ax + ay * ay + az * az)
        if an > 0.0 and k_acc > 0.0:
            ax, ay, az = ax / an, ay / an, az / an
            gx, gy, gz = rotate_scalar(w, x, y, z, ax, ay, az)
            s = np.sqrt(gx * gx + gy * gy)
            if s > 0.0:
                ang = k_acc * np.arctan2(s, gz)
                sh, ch = np.sin(0.5 * ang), np.cos(0.5 * ang)
                ux, uy = sh * gy / s, -sh * gx / s
                # Δq = (ch, ux, uy, 0); q ← Δq ⊗ q
                nw = ch * w - ux * x - uy * y
                nx = ch * x + ux * w + uy * z
                ny = ch * y + uy * w - ux * z
                nz = ch * z + ux * y - uy * x
                w, x, y, z = nw, nx, ny, nz
        if use_mag and k_mag > 0.0:
            mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
            hx, hy, _ = rotate_scalar(w, x, y, z, mx, my, mz)
            if hx != 0.0 or hy != 0.0:
                # azimuth of the horizontal field, counter-clockwise from north (+y)
                phi = np.arctan2(-hx, hy)
                ang = -k_mag * phi
                sh, ch = np.sin(0.5 * ang), np.cos(0.5 * ang)
                nw = ch * w - sh * z
                nx = ch * x - sh * y
                ny = ch * y + sh * x
                nz = ch * z + sh * w
                w, x, y, z = nw, nx, ny, nz
        n = np.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w / n, x / n, y / n, z / n
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z


# ---------------------------------------------------------------- error-state RTS smoother

_RTS_N = 15  # error state: attitude (world frame) φ, gyro bias b, velocity v, position p, gyro scale s
_RTS_X = 12  # nominal state besides q: b, v, p, s


@njit(cache=True, nogil=True, inline="always")
def _rts_rotmat(w, x, y, z, R):
    R[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    R[0, 1] = 2.0 * (x * y - w * z)
    R[0, 2] = 2.0 * (x * z + w * y)
    R[1, 0] = 2.0 * (x * y + w * z)
    R[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    R[1, 2] = 2.0 * (y * z - w * x)
    R[2, 0] = 2.0 * (x * z - w * y)
    R[2, 1] = 2.0 * (y * z + w * x)
    R[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@njit(cache=True, nogil=True)
def _rts_transition(w, x, y, z, a, wc0, wc1, wc2, dt, R, F):
    # F = ∂δx_k/∂δx_{k-1} of the world-frame error state (φ, b, v, p, s), evaluated at the
    # predicted attitude q_{k|k-1} (R = R(q)), the corrected rate ω_c and the specific force
    # a_k; returns R a_k
    _rts_rotmat(w, x, y, z, R)
    sx = R[0, 0] * a[0] + R[0, 1] * a[1] + R[0, 2] * a[2]
    sy = R[1, 0] * a[0] + R[1, 1] * a[1] + R[1, 2] * a[2]
    sz = R[2, 0] * a[0] + R[2, 1] * a[1] + R[2, 2] * a[2]
    for i in range(_RTS_N):
        for j in range(_RTS_N):
            F[i, j] = 1.0 if i == j else 0.0
    for i in range(3):
        for j in range(3):
            F[i, 3 + j] = -dt * R[i, j]  # δφ ← δφ − Δt R δb − Δt R diag(ω_c) δs
        F[i, 12] = -dt * R[i, 0] * wc0
        F[i, 13] = -dt * R[i, 1] * wc1
        F[i, 14] = -dt * R[i, 2] * wc2
        F[9 + i, 6 + i] = dt  # δp ← δp + Δt δv
    # δv ← δv − Δt [s]× δφ ;  δp ← δp − Δt²/2 [s]× δφ
    h = 0.5 * dt * dt
    F[6, 1], F[6, 2] = dt * sz, -dt * sy
    F[7, 0], F[7, 2] = -dt * sz, dt * sx
    F[8, 0], F[8, 1] = dt * sy, -dt * sx
    F[9, 1], F[9, 2] = h * sz, -h * sy
    F[10, 0], F[10, 2] = -h * sz, h * sx
    F[11, 0], F[11, 1] = h * sy, -h * sx
    return sx, sy, sz


@njit(cache=True, nogil=True)
def _rts_propagate(F, P, Qd, FP, out):
    # out = F P Fᵀ + diag(Qd), over the non-zeros of the sparse F (≤ 7 per row); FP = F P
    n = _RTS_N
    idx = np.empty((n, n), np.int64)
    cnt = np.zeros(n, np.int64)
    for i in range(n):
        for l in range(n):
            if F[i, l] != 0.0:
                idx[i, cnt[i]] = l
                cnt[i] += 1
    for i in range(n):
        for j in range(n):
            s = 0.0
            for t in range(cnt[i]):
                l = idx[i, t]
                s += F[i, l] * P[l, j]
            FP[i, j] = s
    for i in range(n):
        for j in range(i, n):
            s = 0.0
            for t in range(cnt[j]):
                l = idx[j, t]
                s += FP[i, l] * F[j, l]
            out[i, j] = s
            out[j, i] = s
        out[i, i] += Qd[i]


@njit(cache=True, nogil=True)
def _rts_scalar_update(P, h, r, var, dx, Ph):
    # one scalar measurement r = h·δx + ν, ν ~ N(0, var), innovation taken at the current δx
    n = _RTS_N
    nz = np.empty(n, np.int64)  # h is sparse (1 or 2 non-zeros)
    m = 0
    for j in range(n):
        if h[j] != 0.0:
            nz[m] = j
            m += 1
    for i in range(n):
        s = 0.0
        for t in range(m):
            s += P[i, nz[t]] * h[nz[t]]
        Ph[i] = s
    S = var
    innov = r
    for t in range(m):
        S += h[nz[t]] * Ph[nz[t]]
        innov -= h[nz[t]] * dx[nz[t]]
    if not (S > 0.0):
        return
    for i in range(n):
        dx[i] += Ph[i] * innov / S
    for i in range(n):
        f = Ph[i] / S
        for j in range(i, n):
            v = P[i, j] - f * Ph[j]
            P[i, j] = v
            P[j, i] = v


@njit(cache=True, nogil=True)
def _rts_chol_solve(A, B, L):
    # B ← A⁻¹ B for a symmetric positive-definite A (Cholesky A = L Lᵀ, in place of B);
    # returns False (B untouched) when A is not numerically positive definite
    n = A.shape[0]
    for j in range(n):
        d = A[j, j]
        for l in range(j):
            d -= L[j, l] * L[j, l]
        if not (d > 0.0):
            return False
        d = np.sqrt(d)
        L[j, j] = d
        for i in range(j + 1, n):
            v = A[i, j]
            for l in range(j):
                v -= L[i, l] * L[j, l]
            L[i, j] = v / d
    m = B.shape[1]
    for c in range(m):
        for i in range(n):  # L y = b
            v = B[i, c]
            for l in range(i):
                v -= L[i, l] * B[l, c]
            B[i, c] = v / L[i, i]
        for i in range(n - 1, -1, -1):  # Lᵀ x = y
            v = B[i, c]
            for l in range(i + 1, n):
                v -= L[l, i] * B[l, c]
            B[i, c] = v / L[i, i]
    return True


@njit(cache=True, nogil=True, inline="always")
def _rts_boxplus(w, x, y, z, px, py, pz):
    # exp(φ/2) ⊗ q (world-frame perturbation), normalised
    ang = np.sqrt(px * px + py * py + pz * pz)
    if ang > 1e-12:
        sh = np.sin(0.5 * ang) / ang
        dw, dx, dy, dz = np.cos(0.5 * ang), sh * px, sh * py, sh * pz
    else:
        dw, dx, dy, dz = 1.0, 0.5 * px, 0.5 * py, 0.5 * pz
    nw = dw * w - dx * x - dy * y - dz * z
    nx = dw * x + dx * w + dy * z - dz * y
    ny = dw * y - dx * z + dy * w + dz * x
    nz = dw * z + dx * y - dy * x + dz * w
    n = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
    return nw / n, nx / n, ny / n, nz / n


@njit(cache=True, nogil=True, inline="always")
def _rts_boxminus(w, x, y, z, rw, rx, ry, rz):
    # φ with q = exp(φ/2) ⊗ r:  φ = Log(q ⊗ r⁻¹)
    ew = w * rw + x * rx + y * ry + z * rz
    ex = -w * rx + x * rw - y * rz + z * ry
    ey = -w * ry + x * rz + y * rw - z * rx
    ez = -w * rz - x * ry + y * rx + z * rw
    if ew < 0.0:
        ew, ex, ey, ez = -ew, -ex, -ey, -ez
    s = np.sqrt(ex * ex + ey * ey + ez * ez)
    if s < 1e-12:
        return 2.0 * ex, 2.0 * ey, 2.0 * ez
    f = 2.0 * np.arctan2(s, ew) / s
    return f * ex, f * ey, f * ez


@njit(cache=True, nogil=True)
def _rts_kernel(acc, gyr, rest, dt, grav, q0, x0, P0, Qd, var_acc, norm_gain, var_vel, var_pos, var_zupt,
                smooth, out_q, out_x):
    n_s = acc.shape[0]
    n = _RTS_N
    qf = np.empty((n_s, 4))
    xf = np.empty((n_s, _RTS_X))
    qp = np.empty((n_s, 4))
    xp = np.empty((n_s, _RTS_X))
    Pf = np.empty((n_s, n, n)) if smooth else np.empty((1, n, n))
    P = P0.copy()
    Pt = np.empty((n, n))
    F = np.empty((n, n))
    FP = np.empty((n, n))
    R = np.empty((3, 3))
    h = np.zeros(n)
    Ph = np.empty(n)
    dx = np.empty(n)
    x = x0.copy()
    w, qx, qy, qz = q0[0], q0[1], q0[2], q0[3]
    qf[0, 0], qf[0, 1], qf[0, 2], qf[0, 3] = w, qx, qy, qz
    qp[0, :] = qf[0, :]
    xf[0, :] = x
    xp[0, :] = x
    if smooth:
        Pf[0] = P
    for k in range(1, n_s):
        # ---- prediction with ω_k, a_k (nominal state, then error covariance)
        # ω_c = (ω_k − b) / (1 + s): gyro corrected for bias and scale error
        wc0 = (gyr[k, 0] - x[0]) / (1.0 + x[9])
        wc1 = (gyr[k, 1] - x[1]) / (1.0 + x[10])
        wc2 = (gyr[k, 2] - x[2]) / (1.0 + x[11])
        w, qx, qy, qz = zoh_step_scalar(w, qx, qy, qz, wc0 * dt, wc1 * dt, wc2 * dt)
        nq = np.sqrt(w * w + qx * qx + qy * qy + qz * qz)
        w, qx, qy, qz = w / nq, qx / nq, qy / nq, qz / nq
        sx, sy, sz = _rts_transition(w, qx, qy, qz, acc[k], wc0, wc1, wc2, dt, R, F)
        fz = sz - grav
        # nominal: p ← p + Δt v + Δt²/2 f, v ← v + Δt f, f = R(q) a_k − g e_z
        # (nominal x = (b, v, p, s): b = x[0:3], v = x[3:6], p = x[6:9], s = x[9:12])
        x[6] += dt * x[3] + 0.5 * dt * dt * sx
        x[7] += dt * x[4] + 0.5 * dt * dt * sy
        x[8] += dt * x[5] + 0.5 * dt * dt * fz
        x[3] += dt * sx
        x[4] += dt * sy
        x[5] += dt * fz
        _rts_propagate(F, P, Qd, FP, Pt)
        for i in range(n):
            for j in range(n):
                P[i, j] = Pt[i, j]
        qp[k, 0], qp[k, 1], qp[k, 2], qp[k, 3] = w, qx, qy, qz
        for i in range(_RTS_X):
            xp[k, i] = x[i]
        # ---- sequential scalar updates of the error state δx (exact for diagonal noise)
        for i in range(n):
            dx[i] = 0.0
        vv = var_zupt if rest[k] else var_vel
        if vv > 0.0 and np.isfinite(vv):
            for i in range(3):
                h[:] = 0.0
                h[6 + i] = 1.0
                _rts_scalar_update(P, h, -x[3 + i], vv, dx, Ph)
        if var_pos > 0.0 and np.isfinite(var_pos):
            for i in range(3):
                h[:] = 0.0
                h[9 + i] = 1.0
                _rts_scalar_update(P, h, -x[6 + i], var_pos, dx, Ph)
        an = np.sqrt(acc[k, 0] ** 2 + acc[k, 1] ** 2 + acc[k, 2] ** 2)
        if an > 0.0 and var_acc > 0.0 and np.isfinite(var_acc):
            e = norm_gain * (an - grav) / grav
            va = var_acc * (1.0 + e * e)
            # ĝ = R(q)ᵀ e_z (third row of R);  ∂ĝ/∂δφ = Rᵀ [e_z]×
            for i in range(3):
                h[:] = 0.0
                h[0] = R[1, i]
                h[1] = -R[0, i]
                _rts_scalar_update(P, h, acc[k, i] / an - R[2, i], va, dx, Ph)
        # ---- injection: q ← exp(δφ/2) ⊗ q, (b, v, p, s) += δ
        w, qx, qy, qz = _rts_boxplus(w, qx, qy, qz, dx[0], dx[1], dx[2])
        for i in range(_RTS_X):
            x[i] += dx[3 + i]
        for i in range(n):
            for j in range(i + 1, n):
                s = 0.5 * (P[i, j] + P[j, i])
                P[i, j] = s
                P[j, i] = s
        qf[k, 0], qf[k, 1], qf[k, 2], qf[k, 3] = w, qx, qy, qz
        for i in range(_RTS_X):
            xf[k, i] = x[i]
        if smooth:
            Pf[k] = P
    if not smooth:
        out_q[:, :] = qf
        out_x[:, :] = xf
        return
    # ---- Rauch–Tung–Striebel backward pass on the error state
    out_q[n_s - 1, :] = qf[n_s - 1, :]
    out_x[n_s - 1, :] = xf[n_s - 1, :]
    C = np.empty((n, n))
    Lw = np.zeros((n, n))
    sc = np.empty(n)
    d = np.empty(n)
    for k in range(n_s - 2, -1, -1):
        wc0 = (gyr[k + 1, 0] - xf[k, 0]) / (1.0 + xf[k, 9])
        wc1 = (gyr[k + 1, 1] - xf[k, 1]) / (1.0 + xf[k, 10])
        wc2 = (gyr[k + 1, 2] - xf[k, 2]) / (1.0 + xf[k, 11])
        _rts_transition(qp[k + 1, 0], qp[k + 1, 1], qp[k + 1, 2], qp[k + 1, 3], acc[k + 1], wc0, wc1, wc2, dt, R, F)
        Pk = Pf[k]
        _rts_propagate(F, Pk, Qd, FP, Pt)
        d[0], d[1], d[2] = _rts_boxminus(out_q[k + 1, 0], out_q[k + 1, 1], out_q[k + 1, 2], out_q[k + 1, 3],
                                         qp[k + 1, 0], qp[k + 1, 1], qp[k + 1, 2], qp[k + 1, 3])
        for i in range(_RTS_X):
            d[3 + i] = out_x[k + 1, i] - xp[k + 1, i]
        # δ = G d with G = P_k|k Fᵀ P_{k+1|k}⁻¹:  solve P_{k+1|k} y = d, then δ = (F P_k|k)ᵀ y;
        # the solve after a symmetric diagonal (Jacobi) scaling, the states' variances
        # differing by many decades
        for i in range(n):
            sc[i] = 1.0 / np.sqrt(Pt[i, i])
        for i in range(n):
            C[i, 0] = d[i] * sc[i]
            for j in range(n):
                Pt[i, j] *= sc[i] * sc[j]
        if not _rts_chol_solve(Pt, C[:, :1], Lw):  # not numerically positive definite: LU
            C[:, :1] = np.linalg.solve(Pt, np.ascontiguousarray(C[:, :1]))
        for i in range(n):
            C[i, 0] *= sc[i]
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += FP[j, i] * C[j, 0]
            dx[i] = s
        out_q[k, 0], out_q[k, 1], out_q[k, 2], out_q[k, 3] = _rts_boxplus(qf[k, 0], qf[k, 1], qf[k, 2], qf[k, 3],
                                                                        dx[0], dx[1], dx[2])
        for i in range(_RTS_X):
            out_x[k, i] = xf[k, i] + dx[3 + i]


# ====================================================================== helpers


def _vec(a, name: str, n: int | None = None) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3), got {a.shape}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name} has {a.shape[0]} samples, expected {n}")
    if a.shape[0] == 0:
        raise ValueError(f"{name} has no samples")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinite values; filters need finite samples")
    return a


def _inputs(acc, gyr, mag):
    acc = _vec(acc, "acc")
    gyr = _vec(gyr, "gyr", acc.shape[0])
    if mag is None:
        return acc, gyr, np.zeros((1, 3)), False
    return acc, gyr, _vec(mag, "mag", acc.shape[0]), True


def _q0(q0, acc, mag, fs, init_window) -> np.ndarray:
    if q0 is None:
        n = max(1, int(round(init_window * fs)))
        return initial_orientation(acc[:n], None if mag is None else mag[:n])
    q0 = np.asarray(q0, dtype=np.float64).reshape(-1)
    if q0.shape != (4,) or not np.all(np.isfinite(q0)) or np.linalg.norm(q0) == 0:
        raise ValueError(f"q0 must be a finite non-zero quaternion (w, x, y, z), got {q0!r}")
    return q0 / np.linalg.norm(q0)


def _positive(value, name: str, allow_zero: bool = False, allow_inf: bool = False) -> float:
    v = float(value)
    if np.isnan(v) or v < 0 or (v == 0 and not allow_zero) or (np.isinf(v) and not allow_inf):
        kind = "non-negative" if allow_zero else "positive"
        raise ValueError(f"{name} must be {kind}{'' if allow_inf else ' and finite'}, got {value!r}")
    return v


def _tilt_quaternion(g: np.ndarray) -> np.ndarray:
    """Minimal rotations (zero heading part) taking unit vectors ``g`` (sensor) to e_z (world)."""
    g = np.asarray(g, float)
    q = np.stack([1.0 + g[..., 2], g[..., 1], -g[..., 0], np.zeros(g.shape[:-1])], axis=-1)
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    flip = n[..., 0] < 1e-9  # g = -e_z: half turn about x
    q = np.where(flip[..., None], np.array([0.0, 1.0, 0.0, 0.0]), q / np.where(n == 0, 1.0, n))
    return q


# ====================================================================== public array API


def initial_orientation(acc, mag=None) -> np.ndarray:
    r"""Orientation from a few (quasi-static) samples, TRIAD-style.

    The mean specific force :math:`\bar a` defines world up. Without magnetometer the
    quaternion is the minimal rotation taking :math:`\hat a` to :math:`e_z` (its heading
    part is zero: :math:`q_z = 0`). With magnetometer, TRIAD [6]_ with the gravity as the
    primary vector: east :math:`e = \bar m \times \hat a / \|\cdot\|`, north
    :math:`n = \hat a \times e`, and :math:`R = [e; n; \hat a]` (rows: the world axes in
    sensor coordinates, ENU).

    Parameters
    ----------
    acc : array_like, shape (N, 3) or (3,)
        Accelerometer samples (any unit).
    mag : array_like, shape (N, 3) or (3,), optional
        Magnetometer samples (any unit).

    Returns
    -------
    numpy.ndarray, shape (4,)
        Unit quaternion, sensor → world.
    """
    a = np.atleast_2d(np.asarray(acc, float)).mean(axis=0)
    an = np.linalg.norm(a)
    if not np.isfinite(an) or an == 0:
        raise ValueError("cannot initialise: the mean accelerometer sample is zero or not finite")
    up = a / an
    if mag is None:
        return _tilt_quaternion(up)
    m = np.atleast_2d(np.asarray(mag, float)).mean(axis=0)
    east = np.cross(m, up)
    en = np.linalg.norm(east)
    if not np.isfinite(en) or en < 1e-12 * max(np.linalg.norm(m), 1e-300):
        raise ValueError("cannot initialise: magnetometer is zero or parallel to gravity")
    east /= en
    north = np.cross(up, east)
    return quat.from_matrix(np.stack([east, north, up]))


def lowpass_tilt(acc, fs: float, *, fc: float = 1.0, order: int = 2) -> np.ndarray:
    r"""Tilt from the low-passed accelerometer (zero-phase Butterworth; scipy).

    :math:`g_s = \mathrm{LP}(a) / \|\mathrm{LP}(a)\|`, with a Butterworth filter of
    ``order`` applied forward and backward (``scipy.signal.sosfiltfilt``; effective
    order ``2·order``, zero phase). The quaternion is the minimal rotation taking
    :math:`g_s` to :math:`e_z` (heading part zero).

    Parameters
    ----------
    acc : array_like, shape (N, 3)
    fs : float
        Sampling rate (Hz), mandatory.
    fc : float
        Cut-off frequency (Hz), ``0 < fc < fs/2``.
    order : int
        Butterworth order of each pass.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    from scipy import signal

    fs = _check_fs(fs)
    acc = _vec(acc, "acc")
    fc = _positive(fc, "fc")
    if fc >= fs / 2:
        raise ValueError(f"fc must be below the Nyquist frequency {fs / 2} Hz, got {fc}")
    sos = signal.butter(int(order), fc, btype="low", fs=fs, output="sos")
    padlen = min(acc.shape[0] - 1, 3 * (2 * sos.shape[0] + 1))
    lp = signal.sosfiltfilt(sos, acc, axis=0, padlen=padlen) if acc.shape[0] > 1 else acc.copy()
    n = np.linalg.norm(lp, axis=1, keepdims=True)
    if np.any(n == 0):
        raise ValueError("the low-passed acceleration vanishes; no tilt can be defined")
    return _tilt_quaternion(lp / n)


def complementary(acc, gyr, fs: float, *, mag=None, tau_acc: float = 1.0, tau_mag: float = 5.0,
                  q0=None, init_window: float = 0.1) -> np.ndarray:
    r"""Geometric complementary filter (6D or 9D).

    Prediction :math:`q \leftarrow q \otimes \exp(\omega_k \Delta t/2)`. Correction in
    the world frame, in the spirit of Valenti et al. [3]_: the measured up direction
    :math:`g_w = R(q)\hat a_k` is rotated towards :math:`e_z` about the horizontal axis
    :math:`g_w \times e_z` by the fraction :math:`k_a = 1 - e^{-\Delta t/\tau_a}` of the
    angle between them (heading untouched); with a magnetometer, a rotation about
    :math:`e_z` by :math:`-k_m \varphi` where :math:`\varphi` is the azimuth of the
    horizontal part of :math:`R(q)\hat m` from north (+y, ENU) and
    :math:`k_m = 1 - e^{-\Delta t/\tau_m}` (tilt untouched).

    Parameters
    ----------
    acc, gyr : array_like, shape (N, 3)
        Specific force (any unit) and angular velocity (rad/s).
    fs : float
        Sampling rate (Hz), mandatory.
    mag : array_like, shape (N, 3), optional
        Magnetometer (any unit): 9D, ENU world frame.
    tau_acc, tau_mag : float
        Time constants (s) of the accelerometer and magnetometer corrections; ``inf``
        disables a correction.
    q0 : array_like, shape (4,), optional
        Initial orientation; default :func:`initial_orientation` over ``init_window`` s.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    fs = _check_fs(fs)
    acc, gyr, m, use_mag = _inputs(acc, gyr, mag)
    dt = 1.0 / fs
    k_acc = -np.expm1(-dt / _positive(tau_acc, "tau_acc", allow_inf=True))
    k_mag = -np.expm1(-dt / _positive(tau_mag, "tau_mag", allow_inf=True))
    q0 = _q0(q0, acc, mag if use_mag else None, fs, init_window)
    out = np.empty((acc.shape[0], 4))
    _complementary_kernel(acc, gyr, m, use_mag, dt, k_acc, k_mag, q0, out)
    return out


def madgwick(acc, gyr, fs: float, *, mag=None, beta: float = 0.05, q0=None, init_window: float = 0.1) -> np.ndarray:
    r"""Madgwick's gradient-descent orientation filter (6D or 9D) [1]_.

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
    (``gain``), ``Dt = 1/fs`` and initial state (module notes list its defects).

    Parameters
    ----------
    acc, gyr : array_like, shape (N, 3)
        Specific force (any unit, normalised per sample) and angular velocity (rad/s).
    fs : float
        Sampling rate (Hz), mandatory.
    mag : array_like, shape (N, 3), optional
        Magnetometer (any unit): 9D, ENU world frame.
    beta : float
        Gradient step (rad/s).
    q0 : array_like, shape (4,), optional
        Initial orientation; default :func:`initial_orientation` over ``init_window`` s.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    fs = _check_fs(fs)
    acc, gyr, m, use_mag = _inputs(acc, gyr, mag)
    beta = _positive(beta, "beta", allow_zero=True)
    q0 = _q0(q0, acc, mag if use_mag else None, fs, init_window)
    out = np.empty((acc.shape[0], 4))
    _madgwick_kernel(acc, gyr, m, use_mag, 1.0 / fs, beta, q0, out)
    return out


def madgwick_batch(acc, gyr, fs: float, betas, *, mag=None, q0=None, init_window: float = 0.1) -> np.ndarray:
    """Madgwick over several gains at once, in parallel (numba ``prange`` over ``betas``).

    Returns
    -------
    numpy.ndarray, shape (len(betas), N, 4)
        ``out[p]`` equals ``madgwick(acc, gyr, fs, beta=betas[p], ...)`` exactly.
    """
    fs = _check_fs(fs)
    acc, gyr, m, use_mag = _inputs(acc, gyr, mag)
    betas = np.ascontiguousarray(np.atleast_1d(np.asarray(betas, float)))
    if betas.ndim != 1 or np.any(~np.isfinite(betas)) or np.any(betas < 0):
        raise ValueError("betas must be a 1-D array of non-negative finite gains")
    q0 = _q0(q0, acc, mag if use_mag else None, fs, init_window)
    out = np.empty((betas.shape[0], acc.shape[0], 4))
    _madgwick_batch_kernel(acc, gyr, m, use_mag, 1.0 / fs, betas, q0, out)
    return out


def mahony(acc, gyr, fs: float, *, mag=None, kp: float = 1.0, ki: float = 0.3, q0=None, b0=None,
           init_window: float = 0.1, return_bias: bool = False):
    r"""Mahony's explicit complementary filter with integral (gyro-bias) term [2]_.

    .. math::
        e_k = \hat a_k \times R(q)^\top e_z \;+\; \hat m_k \times \hat v_m,\qquad
        b_k = b_{k-1} - k_I\, e_k\, \Delta t,\qquad
        \Omega = \omega_k - b_k + k_P\, e_k

    .. math::
        q_k = \frac{q_{k-1} + \tfrac12\, q_{k-1} \otimes (0, \Omega)\,\Delta t}{\|\cdot\|}

    with :math:`\hat v_m = R(q)^\top (0, \|h_{xy}\|, h_z)` normalised,
    :math:`h = R(q)\hat m` (ENU: magnetic north along +y). ``b`` is the estimated
    gyroscope bias. Equal to ``ahrs.filters.Mahony`` for the same gains, ``Dt = 1/fs``,
    ``q0`` and ``b0`` (module notes list its defects).

    Parameters
    ----------
    acc, gyr : array_like, shape (N, 3)
    fs : float
        Sampling rate (Hz), mandatory.
    mag : array_like, shape (N, 3), optional
    kp, ki : float
        Proportional (rad/s) and integral (rad/s²) gains.
    q0 : array_like, shape (4,), optional
    b0 : array_like, shape (3,), optional
        Initial gyro bias (rad/s), default zero.
    return_bias : bool
        Also return the bias estimates, shape (N, 3).
    """
    fs = _check_fs(fs)
    acc, gyr, m, use_mag = _inputs(acc, gyr, mag)
    kp = _positive(kp, "kp", allow_zero=True)
    ki = _positive(ki, "ki", allow_zero=True)
    b0 = np.zeros(3) if b0 is None else np.asarray(b0, float).reshape(3).copy()
    q0 = _q0(q0, acc, mag if use_mag else None, fs, init_window)
    out = np.empty((acc.shape[0], 4))
    bias = np.empty((acc.shape[0], 3))
    _mahony_kernel(acc, gyr, m, use_mag, 1.0 / fs, kp, ki, q0, b0, out, bias)
    return (out, bias) if return_bias else out


def _dip_from(acc, mag) -> float:
    a = np.mean(acc, axis=0)
    mm = np.mean(mag, axis=0)
    s = np.dot(a, mm) / (np.linalg.norm(a) * np.linalg.norm(mm))
    return float(np.degrees(np.arcsin(np.clip(-s, -1.0, 1.0))))


def ekf(acc, gyr, fs: float, *, mag=None, var_gyr: float = 0.3**2, var_acc: float = 0.5**2,
        var_mag: float = 0.8**2, dip: float | None = None, P0=None, q0=None, init_window: float = 0.1) -> np.ndarray:
    r"""Quaternion-state extended Kalman filter (6D or 9D), ``ahrs`` formulation [4]_ [9]_.

    State :math:`q` (4), prediction :math:`q_t = (I + \tfrac{\Delta t}{2}\Omega(\omega_k))
    q_{k-1}`, :math:`F = I + \Omega(\tfrac{\Delta t}{2}\omega_k)`,
    :math:`P_t = F P F^\top + \sigma_\omega^2 W W^\top` with
    :math:`W = \partial q_t/\partial\omega`. Measurement
    :math:`z = (\hat a_k, \hat m_k)`, model :math:`h(q) = (R(q)^\top e_z, R(q)^\top r)`
    (world z up, ENU magnetic reference :math:`r = (0, \cos\delta, -\sin\delta)` for dip
    :math:`\delta`), :math:`R = \mathrm{diag}(\sigma_a^2 I_3, \sigma_m^2 I_3)`,
    :math:`K = P_t H^\top (H P_t H^\top + R)^{-1}`, :math:`P = (I - K H) P_t`,
    :math:`q_k = (q_t + K(z - h))/\|\cdot\|`. As in ``ahrs``, :math:`h` is evaluated at
    the normalised and :math:`H` at the unnormalised :math:`q_t` (equal to first order).

    Equal to ``ahrs.filters.EKF(frame='NED', magnetic_ref=r, noises=[var_gyr, var_acc,
    var_mag], Dt=1/fs, q0=q0)``; ``ahrs``'s ``frame='ENU'`` is upside down (module notes).

    Parameters
    ----------
    acc, gyr : array_like, shape (N, 3)
    fs : float
        Sampling rate (Hz), mandatory.
    mag : array_like, shape (N, 3), optional
    var_gyr, var_acc, var_mag : float
        Gyroscope noise variance ((rad/s)²) and measurement variances of the unit
        accelerometer and magnetometer directions.
    dip : float, optional
        Magnetic dip (inclination) in degrees, positive when the field points down;
        default: measured from the initial samples.
    P0 : array_like, shape (4, 4), optional
        Initial covariance, default identity.
    """
    fs = _check_fs(fs)
    acc, gyr, m, use_mag = _inputs(acc, gyr, mag)
    var_gyr = _positive(var_gyr, "var_gyr", allow_zero=True)
    var_acc = _positive(var_acc, "var_acc")
    var_mag = _positive(var_mag, "var_mag")
    n0 = max(1, int(round(init_window * fs)))
    if use_mag and dip is None:
        dip = _dip_from(acc[:n0], m[:n0])
    d = np.radians(0.0 if dip is None else float(dip))
    m_ref = np.array([0.0, np.cos(d), -np.sin(d)])
    P0 = np.eye(4) if P0 is None else np.ascontiguousarray(np.asarray(P0, float))
    if P0.shape != (4, 4):
        raise ValueError(f"P0 must have shape (4, 4), got {P0.shape}")
    q0 = _q0(q0, acc, mag if use_mag else None, fs, init_window)
    out = np.empty((acc.shape[0], 4))
    _ekf_kernel(acc, gyr, m, use_mag, 1.0 / fs, var_gyr, var_acc, var_mag, m_ref, P0, q0, out)
    return out


def rest_gyro_bias(acc, gyr, fs: float, *, window: float = 0.5, gyr_thresh: float = np.radians(2.0),
                   acc_thresh: float = 0.2, min_rest: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    r"""Gyroscope bias from detected rest periods.

    A sample is at rest when, over a centred window of ``window`` s, the mean angular
    velocity and the RMS deviation of ω are below ``gyr_thresh`` (rad/s) and the RMS
    deviation of :math:`\|a\|` is below ``acc_thresh`` (units of ``acc``). The bias is
    the mean ω over rest samples (zero if there are fewer than ``min_rest`` s of them).

    Returns
    -------
    bias : numpy.ndarray, shape (3,)
    rest : numpy.ndarray of bool, shape (N,)
    """
    from scipy.ndimage import uniform_filter1d

    fs = _check_fs(fs)
    acc = _vec(acc, "acc")
    gyr = _vec(gyr, "gyr", acc.shape[0])
    n = max(3, int(round(window * fs)))
    gm = uniform_filter1d(gyr, n, axis=0, mode="nearest")
    # (clipped at 0: the running mean of tiny squares can round to a negative number)
    gdev = np.sqrt(np.maximum(uniform_filter1d(np.sum((gyr - gm) ** 2, axis=1), n, mode="nearest"), 0.0))
    an = np.linalg.norm(acc, axis=1)
    adev = np.sqrt(np.maximum(uniform_filter1d((an - uniform_filter1d(an, n, mode="nearest")) ** 2, n, mode="nearest"), 0.0))
    rest = (np.linalg.norm(gm, axis=1) < gyr_thresh) & (gdev < gyr_thresh) & (adev < acc_thresh)
    bias = gyr[rest].mean(axis=0) if rest.sum() >= min_rest * fs else np.zeros(3)
    return bias, rest


def smoother(acc, gyr, fs: float, *, fc: float = 0.1, order: int = 2, bias=None, q0=None) -> np.ndarray:
    r"""Offline (non-causal) tilt smoother: zero-phase low-pass of the specific force in the
    gyroscope-integrated frame.

    1. Gyro bias :math:`b` from rest periods (:func:`rest_gyro_bias`) unless given.
    2. Strapdown integration :math:`q_g` of :math:`\omega - b` (any start). Because
       :math:`q_g = D(t) \otimes q` with a slowly drifting world-frame offset :math:`D`,
       the specific force in that frame is :math:`R(q_g)\,a = R(D)\,(g\,e_z + \ddot p)`.
    3. A forward–backward Butterworth low-pass (cut-off ``fc``) removes the motion
       acceleration :math:`\ddot p` (its time average is :math:`\Delta v / T \to 0`
       for bounded velocity) but keeps the slow :math:`R(D)\,e_z`: the up direction of
       the drifting frame.
    4. :math:`q = C \otimes q_g` with :math:`C` the minimal rotation taking that up
       direction to :math:`e_z`; heading remains the gyroscope's (relative, drifting).

    This is the offline analogue of filtering the accelerometer in an almost-inertial
    frame (Laidig & Seel [7]_); being zero phase, it has no lag. Gyro-bias
    states and motion acceleration are handled by steps 1 and 3. (Tried and rejected on
    BROAD: down-weighting samples with :math:`|\,\|a\| - g\,|` large, which biases the
    average; a least-squares refinement of :math:`b` from the corrections, no gain.)

    Parameters
    ----------
    acc : array_like, shape (N, 3)
        Specific force in m/s² (the rest detector's threshold is in m/s²).
    gyr : array_like, shape (N, 3)
        Angular velocity (rad/s).
    fs : float
        Sampling rate (Hz), mandatory.
    fc : float
        Cut-off (Hz) of the low-pass: below the motion frequencies, above the drift of
        :math:`D` (bias residual, gyro scale errors).
    order : int
        Butterworth order of each pass.
    bias : array_like, shape (3,), optional
        Known gyro bias (rad/s).
    q0 : array_like, shape (4,), optional
        Start of the integration (fixes the heading origin); default identity.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    from scipy import signal

    fs = _check_fs(fs)
    acc = _vec(acc, "acc")
    gyr = _vec(gyr, "gyr", acc.shape[0])
    fc = _positive(fc, "fc")
    if fc >= fs / 2:
        raise ValueError(f"fc must be below the Nyquist frequency {fs / 2} Hz, got {fc}")
    b = rest_gyro_bias(acc, gyr, fs)[0] if bias is None else np.asarray(bias, float).reshape(3)
    w = gyr - b
    q0 = quat.identity() if q0 is None else _q0(q0, acc, None, fs, 0.0)
    # filters' indexing: q[k] = q[k-1] ⊗ exp(ω_k Δt / 2)
    qg = quat.integrate_gyro(np.vstack([w[1:], w[-1:]]), fs, q0)
    ag = quat.rotate(qg, acc)
    sos = signal.butter(int(order), fc, btype="low", fs=fs, output="sos")
    if acc.shape[0] > 3 * (2 * sos.shape[0] + 1):
        ag = signal.sosfiltfilt(sos, ag, axis=0)
    n = np.linalg.norm(ag, axis=1, keepdims=True)
    if np.any(n == 0):
        raise ValueError("the low-passed acceleration vanishes; no tilt can be defined")
    return quat.mul(_tilt_quaternion(ag / n), qg)


def rts_smoother(acc, gyr, fs: float, *, gyr_noise: float = 5e-3, bias_noise: float = 1e-4, acc_noise: float = 0.01,
                 acc_std: float = 0.05, norm_gain: float = 10.0, vel_std: float = 0.3, pos_std: float = 1.0,
                 tau: float = 1.0, zupt_std: float = 0.01, bias_std: float = np.radians(0.5), scale_std: float = 0.0,
                 scale_noise: float = 0.0, bias=None, q0=None,
                 init_window: float = 0.1, smooth: bool = True, return_state: bool = False,
                 max_memory_gb: float = 4.0):
    r"""Offline attitude smoother: error-state (multiplicative) EKF with gyro-bias, gyro-scale,
    velocity and position states, followed by a Rauch–Tung–Striebel backward pass.

    **Nominal state** :math:`x = (q, b, v, p, s)`: attitude (sensor → world, z up), gyro bias
    (rad/s), world-frame velocity (m/s) and position (m) of the sensor, and gyro scale
    errors (gyro model :math:`\omega^{meas} = (1 + s) \circ \omega + b`). With the filters'
    indexing (:math:`\omega_k, a_k` take :math:`k-1 \to k`) and
    :math:`\omega^c_k = (\omega_k - b) \oslash (1 + s)`:

    .. math::
        q_k = q_{k-1} \otimes \mathrm{Exp}\big(\omega^c_k\,\Delta t\big),\quad
        f_k = R(q_k)\,a_k - g\,e_z,\quad
        v_k = v_{k-1} + f_k \Delta t,\quad p_k = p_{k-1} + v_{k-1}\Delta t + \tfrac12 f_k \Delta t^2 .

    **Error state** :math:`\delta x = (\delta\phi, \delta b, \delta v, \delta p, \delta s)`
    (15) with the attitude error in the world frame, :math:`q_{true} = \mathrm{Exp}(\delta\phi)
    \otimes q` (Solà [1]_, §7 "global" error), whose transition is :math:`F = I` plus the
    blocks :math:`F_{\phi b} = -\Delta t R`, :math:`F_{\phi s} = -\Delta t R\,
    \mathrm{diag}(\omega^c_k)`, :math:`F_{v\phi} = -\Delta t [f]_\times`,
    :math:`F_{p\phi} = -\tfrac12\Delta t^2 [f]_\times`, :math:`F_{pv} = \Delta t I`
    (:math:`R = R(q_k)`, :math:`f = R a_k`: a tilt error :math:`\delta\phi` leaks
    :math:`g\,\delta\phi` of gravity into the horizontal acceleration), with process noise
    :math:`Q = \Delta t\,\mathrm{diag}(\sigma_\omega^2 I, \sigma_b^2 I, \sigma_a^2 I,
    \sigma_a^2 \Delta t^2/3\, I, \sigma_s^2 I)`.

    **Measurements** (scalar sequential updates, exact for diagonal noise):

    * velocity pseudo-measurement :math:`0 = v + \nu_v`: a hand-held or head-mounted sensor
      does not drift away; variance :math:`\sigma_v^2 \tau f_s` (an independent
      measurement of standard deviation ``vel_std`` every ``tau`` s) in motion, and a
      zero-velocity update with ``zupt_std²`` per sample during detected rest
      (:func:`rest_gyro_bias`);
    * position pseudo-measurement :math:`0 = p + \nu_p`, variance
      :math:`\sigma_p^2 \tau f_s` (bounded workspace);
    * accelerometer direction :math:`\hat a_k = R(q)^\top e_z + \nu_a`, Jacobian
      :math:`R^\top [e_z]_\times`, variance
      :math:`\sigma_{\hat a}^2 \tau f_s \,\big(1 + (\kappa\,(\|a_k\| - g)/g)^2\big)`,
      down-weighted where the norm departs from gravity (adaptive, ``norm_gain`` = κ).

    After each update the error is injected (:math:`q \leftarrow \mathrm{Exp}(\delta\phi)
    \otimes q`, :math:`(b, v, p, s) \mathrel{+}= \delta`). Integrated acceleration
    constrains tilt far better than the instantaneous direction of :math:`a`: a tilt
    error held for :math:`T` seconds moves the position by :math:`g\,\delta\phi\,T^2/2`.

    **Backward pass** (Rauch, Tung, Striebel [2]_, on the error state): with the forward
    posterior :math:`\hat x_{k|k}, P_{k|k}` and prediction :math:`\hat x_{k+1|k},
    P_{k+1|k} = F P_{k|k} F^\top + Q`,

    .. math::
        G_k = P_{k|k} F^\top P_{k+1|k}^{-1},\qquad
        x^s_k = \hat x_{k|k} \boxplus G_k\,\big(x^s_{k+1} \boxminus \hat x_{k+1|k}\big),

    where :math:`\boxminus` of attitudes is :math:`\mathrm{Log}(q^s \otimes
    \hat q^{-1})`; :math:`G_k` is solved after a symmetric diagonal scaling of
    :math:`P_{k+1|k}`. Memory: one 15 × 15 covariance per sample (1.8 kB). Like ``offlineVQF`` (Laidig & Seel [3]_) it uses past and future
    samples; unlike VQF the bias and the motion acceleration are handled by one
    Gaussian model. 6D only: heading is relative (its error state is unobservable and
    merely carried).

    Parameters
    ----------
    acc : array_like, shape (N, 3)
        Specific force in **m/s²**.
    gyr : array_like, shape (N, 3)
        Angular velocity (rad/s).
    fs : float
        Sampling rate (Hz), mandatory.
    gyr_noise : float
        Angular random walk σ_ω (rad/√s), gyro noise plus unmodelled scale errors.
    bias_noise : float
        Bias random walk σ_b (rad/s/√s).
    acc_noise : float
        Velocity random walk σ_a (m/s/√s).
    acc_std, vel_std, pos_std : float
        Standard deviations of the accelerometer-direction (rad), velocity (m/s) and
        position (m) pseudo-measurements per correlation time ``tau``; ``inf``
        disables one.
    norm_gain : float
        κ of the adaptive accelerometer variance (0: not adaptive).
    tau : float
        Correlation time (s) of the pseudo-measurement errors.
    zupt_std : float
        Per-sample standard deviation (m/s) of the zero-velocity update at rest
        (``inf``: no ZUPT).
    bias_std : float
        Initial standard deviation of the gyro bias (rad/s).
    scale_std, scale_noise : float
        Initial standard deviation (1) and random walk (1/√s) of the gyro scale errors;
        the default 0 switches scale estimation off.
    bias : array_like, shape (3,), optional
        Initial gyro bias (rad/s); default :func:`rest_gyro_bias`.
    q0 : array_like, shape (4,), optional
        Initial orientation; default :func:`initial_orientation` over ``init_window`` s.
    smooth : bool
        Run the backward pass (``False``: forward filter only).
    return_state : bool
        Also return the (smoothed) states :math:`(b, v, p, s)`, shape (N, 12).
    max_memory_gb : float
        Refuse recordings whose stored covariances would exceed this (1.8 kB per sample,
        e.g. 0.65 GB for 20 min at 300 Hz); split longer recordings or raise the limit.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions sensor → world (and the states if ``return_state``).

    References
    ----------
    .. [1] J. Solà, "Quaternion kinematics for the error-state Kalman filter",
       arXiv:1711.02508, 2017.
    .. [2] H. E. Rauch, F. Tung, C. T. Striebel, "Maximum likelihood estimates of linear
       dynamic systems", AIAA Journal 3(8):1445–1450, 1965. doi:10.2514/3.3166
    .. [3] D. Laidig, T. Seel, "VQF: Highly accurate IMU orientation estimation with bias
       estimation and magnetic disturbance rejection", Information Fusion 91:187–204,
       2023. doi:10.1016/j.inffus.2022.10.014
    """
    fs = _check_fs(fs)
    acc = _vec(acc, "acc")
    gyr = _vec(gyr, "gyr", acc.shape[0])
    need_gb = acc.shape[0] * 15 * 15 * 8 / 1e9
    if smooth and need_gb > max_memory_gb:
        raise ValueError(
            f"rts_smoother would store {need_gb:.1f} GB of covariances for {acc.shape[0]} samples "
            f"(limit max_memory_gb={max_memory_gb:g}); split the recording into shorter segments or raise the limit"
        )
    dt = 1.0 / fs
    names = ("gyr_noise", "bias_noise", "acc_noise")
    sig = [_positive(v, nm, allow_zero=True) for v, nm in zip((gyr_noise, bias_noise, acc_noise), names)]
    tau = _positive(tau, "tau")
    std = {nm: _positive(v, nm, allow_inf=True) for nm, v in
           (("acc_std", acc_std), ("vel_std", vel_std), ("pos_std", pos_std), ("zupt_std", zupt_std))}
    norm_gain = _positive(norm_gain, "norm_gain", allow_zero=True)
    bias_std = _positive(bias_std, "bias_std", allow_zero=True)
    b_rest, rest = rest_gyro_bias(acc, gyr, fs)
    b0 = b_rest if bias is None else np.asarray(bias, float).reshape(3)
    an = np.linalg.norm(acc, axis=1)
    grav = float(np.mean(an[rest])) if rest.sum() >= 0.5 * fs else float(np.median(an))
    if not grav > 0:
        raise ValueError("the accelerometer norm vanishes; no gravity can be defined")
    q0 = _q0(q0, acc, None, fs, init_window)
    x0 = np.concatenate([b0, np.zeros(9)])
    scale_std = _positive(scale_std, "scale_std", allow_zero=True)
    scale_noise = _positive(scale_noise, "scale_noise", allow_zero=True)
    P0 = np.diag(np.r_[np.radians(2.0) ** 2, np.radians(2.0) ** 2, 1e-6, [bias_std**2 + 1e-12] * 3,
                       [0.1**2] * 3, [1e-6] * 3, [scale_std**2 + 1e-12] * 3])
    Qd = dt * np.r_[[sig[0] ** 2] * 3, [sig[1] ** 2] * 3, [sig[2] ** 2] * 3, [sig[2] ** 2 * dt * dt / 3.0] * 3,
                    [scale_noise**2] * 3]
    Qd = np.maximum(Qd, 1e-18)
    rate = tau * fs
    out_q = np.empty((acc.shape[0], 4))
    out_x = np.empty((acc.shape[0], 12))
    _rts_kernel(acc, gyr, np.ascontiguousarray(rest), dt, grav, q0, x0, P0, Qd, std["acc_std"] ** 2 * rate,
                norm_gain, std["vel_std"] ** 2 * rate, std["pos_std"] ** 2 * rate, std["zupt_std"] ** 2,
                bool(smooth), out_q, out_x)
    return (out_q, out_x) if return_state else out_q


# ====================================================================== recordings


#: Methods known to :func:`estimate`, with their parameter defaults.
METHODS: dict[str, dict[str, Any]] = {
    "lowpass": {"fc": 1.0, "order": 2},
    "complementary": {"tau_acc": 1.0, "tau_mag": 5.0},
    "madgwick": {"beta": 0.05},
    "mahony": {"kp": 1.0, "ki": 0.3},
    "ekf": {"var_gyr": 0.3**2, "var_acc": 0.5**2, "var_mag": 0.8**2, "dip": None},
    "smoother": {"fc": 0.1, "order": 2},
    "rts_smoother": {"gyr_noise": 5e-3, "bias_noise": 1e-4, "acc_noise": 0.01, "acc_std": 0.05, "norm_gain": 10.0,
                     "vel_std": 0.3, "pos_std": 1.0, "tau": 1.0, "zupt_std": 0.01, "scale_std": 0.0},
    "vqf": {},
    "offline_vqf": {},
    "imufusion": {"gain": 0.5, "acceleration_rejection": 10.0, "rejection_timeout": 5.0},
    "ahrs_madgwick": {"beta": 0.05},
    "ahrs_mahony": {"kp": 1.0, "ki": 0.3},
    "ahrs_ekf": {"var_gyr": 0.3**2, "var_acc": 0.5**2},
}


def _si_arrays(recording: xr.Dataset, use_mag: bool):
    if not isinstance(recording, xr.Dataset):
        raise ValueError(f"recording must be an xarray Dataset (a tiltlab Recording), got {type(recording).__name__}")
    if "fs" not in recording.attrs or recording.attrs["fs"] is None:
        raise ValueError("recording has no 'fs' attribute (sampling rate, Hz); it is mandatory, never defaulted")
    fs = _check_fs(recording.attrs["fs"])
    for name in ("acc", "gyr") + (("mag",) if use_mag else ()):
        if name not in recording:
            raise ValueError(f"recording has no {name!r} variable" + (" (needed for use_mag=True)" if name == "mag" else ""))
        if "units" not in recording[name].attrs:
            raise ValueError(f"{name!r} has no 'units' attribute; units are never assumed")
    acc = _units.convert(recording["acc"].transpose("time", "axis").values, recording["acc"].attrs["units"], "m/s^2")
    gyr = _units.convert(recording["gyr"].transpose("time", "axis").values, recording["gyr"].attrs["units"], "rad/s")
    mag = recording["mag"].transpose("time", "axis").values if use_mag else None
    return np.ascontiguousarray(acc, float), np.ascontiguousarray(gyr, float), (None if mag is None else np.ascontiguousarray(mag, float)), fs


def _vqf_run(acc, gyr, mag, fs, offline: bool, params: dict) -> np.ndarray:
    import vqf

    Ts = 1.0 / fs
    a, g = np.ascontiguousarray(acc), np.ascontiguousarray(gyr)
    m = None if mag is None else np.ascontiguousarray(mag)
    if offline:
        res = vqf.offlineVQF(g, a, m, Ts, dict(params) or None)
    else:
        res = vqf.VQF(Ts, **params).updateBatch(g, a, m)
    return np.asarray(res["quat9D" if m is not None else "quat6D"])


def _imufusion_run(acc, gyr, fs, gain: float, acceleration_rejection: float, rejection_timeout: float) -> np.ndarray:
    """x-io Fusion AHRS (``imufusion``), 6D, NWU world (z up: tilt comparable); gyr rad/s → °/s, acc m/s² → g."""
    import imufusion

    settings = imufusion.AhrsSettings(sample_rate=fs, convention=imufusion.CONVENTION_NWU, gain=float(gain),
                                      gyroscope_range=1e6, acceleration_rejection=float(acceleration_rejection),
                                      magnetic_rejection=0.0, rejection_timeout=int(round(rejection_timeout * fs)))
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


def _ahrs_run(name: str, acc, gyr, fs, params: dict) -> np.ndarray:
    """The pure-Python ``ahrs`` package (6D) with an explicit ``frequency`` and start at
    :func:`initial_orientation` of the first 0.1 s."""
    import ahrs.filters as af

    q0 = initial_orientation(acc[: max(1, int(round(0.1 * fs)))])
    if name == "ahrs_madgwick":
        f = af.Madgwick(gyr=gyr, acc=acc, frequency=fs, gain=float(params["beta"]), q0=q0)
    elif name == "ahrs_mahony":
        # ahrs rejects k_I = 0 (and k_P = 0); the smallest positive float acts as zero
        f = af.Mahony(gyr=gyr, acc=acc, frequency=fs, k_P=max(float(params["kp"]), 5e-324),
                      k_I=max(float(params["ki"]), 5e-324), q0=q0)
    else:
        f = af.EKF(gyr=gyr, acc=acc, frequency=fs, frame="NED", q0=q0,
                   noises=[float(params["var_gyr"]), float(params["var_acc"]), 0.8**2])
    return np.asarray(f.Q, float)


def _run(method: str, acc, gyr, mag, fs, params: dict) -> np.ndarray:
    if method == "lowpass":
        if mag is not None:
            raise ValueError("method 'lowpass' estimates tilt only; use_mag=True is not supported")
        return lowpass_tilt(acc, fs, **params)
    if method == "complementary":
        return complementary(acc, gyr, fs, mag=mag, **params)
    if method == "madgwick":
        return madgwick(acc, gyr, fs, mag=mag, **params)
    if method == "mahony":
        return mahony(acc, gyr, fs, mag=mag, **params)
    if method == "ekf":
        return ekf(acc, gyr, fs, mag=mag, **params)
    if method == "smoother":
        if mag is not None:
            raise ValueError("method 'smoother' is 6D (tilt and relative heading); use_mag=True is not supported")
        return smoother(acc, gyr, fs, **params)
    if method == "rts_smoother":
        if mag is not None:
            raise ValueError("method 'rts_smoother' is 6D (tilt and relative heading); use_mag=True is not supported")
        return rts_smoother(acc, gyr, fs, **params)
    if method in ("vqf", "offline_vqf"):
        return _vqf_run(acc, gyr, mag, fs, method == "offline_vqf", params)
    if method == "imufusion" or method.startswith("ahrs_"):
        if mag is not None:
            raise ValueError(f"method {method!r} is wrapped in 6D only; use_mag=True is not supported")
        if method == "imufusion":
            return _imufusion_run(acc, gyr, fs, **params)
        return _ahrs_run(method, acc, gyr, fs, params)
    raise ValueError(f"unknown method {method!r}; known: {sorted(METHODS)}")


def _attr_value(v):
    if v is None:
        return "none"
    if isinstance(v, (bool, np.bool_)):
        return int(v)
    if isinstance(v, (np.ndarray, list, tuple)):
        return np.asarray(v, float)
    return v


def estimate(recording: xr.Dataset, method: str, *, use_mag: bool = False, **params) -> xr.DataArray:
    """Estimate the orientation of a Recording with one of :data:`METHODS`.

    The wrapper converts the Recording's units (acc g or m/s², gyr deg/s or rad/s, per
    their ``units`` attributes) to SI for the kernels. ``fs`` comes from the
    Recording's attributes; a missing ``fs`` is an error.

    Parameters
    ----------
    recording : xarray.Dataset
        A tiltlab Recording (``acc``, ``gyr``, optional ``mag``; attrs ``fs``).
    method : str
        One of ``lowpass, complementary, madgwick, mahony, ekf, smoother, vqf,
        offline_vqf`` or the comparison adapters ``imufusion, ahrs_madgwick,
        ahrs_mahony, ahrs_ekf``.
    use_mag : bool
        Use the magnetometer (9D, ENU world frame).
    **params
        Method parameters (see the array functions); unspecified ones take the
        defaults in :data:`METHODS`, and all are recorded in the output's attrs.

    Returns
    -------
    xarray.DataArray, dims (time, quat)
        Unit quaternions sensor → world, with attrs ``method``, ``fs``, ``use_mag``,
        ``world_frame`` and every parameter as ``param_<name>``.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; known: {sorted(METHODS)}")
    acc, gyr, mag, fs = _si_arrays(recording, use_mag)
    full = {**METHODS[method], **params}
    q = _run(method, acc, gyr, mag, fs, full)
    attrs = {
        "method": method,
        "fs": fs,
        "use_mag": int(bool(use_mag)),
        "units": "1",
        "frame": "sensor->world",
        "world_frame": "ENU" if use_mag else "z up, heading arbitrary",
        **{f"param_{k}": _attr_value(v) for k, v in full.items()},
    }
    return xr.DataArray(
        q,
        dims=("time", "quat"),
        coords={"time": recording["time"].values, "quat": list("wxyz")},
        name="q",
        attrs=attrs,
    )


def gravity(q) -> xr.DataArray:
    r"""Tilt :math:`g_s = R(q)^\top e_z` (gravity-up direction, sensor frame) as a DataArray (time, axis)."""
    if isinstance(q, xr.DataArray):
        if "quat" not in q.dims:
            raise ValueError(f"q must have a 'quat' dimension, got dims {q.dims}")
        qa = q.transpose(..., "quat")
        g = quat.gravity(qa.values)
        dims = qa.dims[:-1] + ("axis",)
        coords = {d: qa.coords[d] for d in qa.dims[:-1] if d in qa.coords}
        return xr.DataArray(g, dims=dims, coords={**coords, "axis": list("xyz")}, name="gravity",
                            attrs={"units": "1", "frame": "sensor", "long_name": "gravity-up direction (tilt)"})
    g = quat.gravity(np.asarray(q, float))
    if g.ndim != 2:
        raise ValueError("an ndarray q must have shape (N, 4)")
    return xr.DataArray(g, dims=("time", "axis"), coords={"axis": list("xyz")}, name="gravity",
                        attrs={"units": "1", "frame": "sensor", "long_name": "gravity-up direction (tilt)"})


# ====================================================================== evaluation


def _valid_mask(q_est: np.ndarray, rec: xr.Dataset, movement_only: bool) -> np.ndarray:
    q_ref = rec["q_ref"].transpose("time", "quat").values
    mask = np.all(np.isfinite(q_ref), axis=1) & np.all(np.isfinite(q_est), axis=1)
    if movement_only:
        if "movement" not in rec:
            raise ValueError("recording has no 'movement' variable; pass movement_only=False")
        mask &= rec["movement"].values.astype(bool)
    return mask


def broad_errors(q_est, rec: xr.Dataset, *, movement_only: bool = True, remove_heading_offset: bool = False) -> dict[str, float]:
    r"""RMSE (degrees) of inclination (= tilt), heading and total error, BROAD's definition [8]_.

    Error quaternion in the earth frame :math:`e = q_{est} \otimes q_{ref}^{-1}`; total
    :math:`2\arccos|e_w|`, heading :math:`2\arctan|e_z/e_w|`, inclination
    :math:`2\arccos\sqrt{e_w^2+e_z^2}` (:func:`tiltlab.quaternion.tilt_error` etc.).
    RMS over the samples where ``movement`` is true (BROAD's rule) and the reference
    is valid (NaN where optical tracking was lost).

    Parameters
    ----------
    q_est : xarray.DataArray or array_like, shape (N, 4)
    rec : xarray.Dataset
        Recording with ``q_ref`` (and ``movement``).
    remove_heading_offset : bool
        Remove the constant heading offset between the estimate's and the reference's
        world frames first (circular mean over the valid samples). BROAD does not do
        this; use it for 6D methods, whose heading origin is arbitrary. The inclination
        error is unaffected.

    Returns
    -------
    dict
        ``inclination``, ``heading``, ``total`` (degrees) and ``n`` (samples used).
    """
    if "q_ref" not in rec:
        raise ValueError("recording has no 'q_ref' (reference orientation)")
    q = q_est.transpose("time", "quat").values if isinstance(q_est, xr.DataArray) else np.asarray(q_est, float)
    if q.shape != (rec.sizes["time"], 4):
        raise ValueError(f"q_est must have shape ({rec.sizes['time']}, 4), got {q.shape}")
    mask = _valid_mask(q, rec, movement_only)
    if not mask.any():
        raise ValueError("no valid samples (movement with a finite reference)")
    qe, qr = q[mask], rec["q_ref"].transpose("time", "quat").values[mask]
    if remove_heading_offset:
        e = quat.error_quaternion(qe, qr)
        e = np.where(e[:, :1] < 0, -e, e)
        psi = 2.0 * np.arctan2(e[:, 3], e[:, 0])
        off = np.arctan2(np.mean(np.sin(psi)), np.mean(np.cos(psi)))
        qe = quat.mul(np.array([np.cos(off / 2), 0.0, 0.0, -np.sin(off / 2)]), qe)
    err = quat.error_angles(qe, qr)

    def rms(v):
        return float(np.degrees(np.sqrt(np.mean(v * v))))

    return {"inclination": rms(err[:, 2]), "heading": rms(err[:, 1]), "total": rms(err[:, 0]), "n": int(mask.sum())}


def tilt_rmse(q_est, rec: xr.Dataset) -> float:
    """Inclination RMSE (degrees) over BROAD's movement samples: a ``score_fn`` for :func:`grid_search`."""
    return broad_errors(q_est, rec)["inclination"]


def grid_search(recordings: Sequence[xr.Dataset] | Mapping[Any, xr.Dataset], method: str,
                param_grid: Mapping[str, Sequence], score_fn: Callable[[np.ndarray, xr.Dataset], float] = tilt_rmse,
                *, use_mag: bool = False, n_jobs: int | None = None, fixed: Mapping[str, Any] | None = None) -> xr.DataArray:
    """Score a method over a parameter grid and several recordings, in parallel.

    Each (parameter combination, recording) pair runs the numba kernel (which releases
    the GIL) in a thread pool of ``n_jobs`` workers; ``score_fn(q, recording)`` reduces
    each estimate (an (N, 4) array) to a number, so the estimates are never all held in
    memory.

    Parameters
    ----------
    recordings : sequence or mapping of Recordings
        A mapping's keys label the ``recording`` coordinate (else 0, 1, …).
    method : str
        A method of :data:`METHODS`.
    param_grid : mapping
        Parameter name → sequence of values; the grid is their Cartesian product.
    score_fn : callable
        ``score_fn(q, rec) -> float``, or an ``xarray.DataArray`` with the same dims
        and coords for every call (e.g. one score per behavioural ``state``), whose dims
        are appended after ``recording``; default :func:`tilt_rmse`.
    n_jobs : int, optional
        Worker threads, default ``os.cpu_count()``.
    fixed : mapping, optional
        Further parameters held constant.

    Returns
    -------
    xarray.DataArray
        Dims (one per grid parameter…, ``recording``, then the score's own dims),
        attrs ``method``, ``use_mag`` and the fixed parameters.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; known: {sorted(METHODS)}")
    if isinstance(recordings, Mapping):
        labels, recs = list(recordings.keys()), list(recordings.values())
    else:
        recs = list(recordings)
        labels = list(range(len(recs)))
    if not recs:
        raise ValueError("no recordings")
    if not param_grid:
        raise ValueError("param_grid is empty")
    names = list(param_grid)
    values = [list(np.atleast_1d(param_grid[n])) for n in names]
    if any(len(v) == 0 for v in values):
        raise ValueError("every parameter in param_grid needs at least one value")
    fixed = dict(fixed or {})
    base = {**METHODS[method], **fixed}
    data = [_si_arrays(r, use_mag) for r in recs]
    combos = list(itertools.product(*[range(len(v)) for v in values]))
    shape = tuple(len(v) for v in values) + (len(recs),)
    out = np.full(shape, np.nan)

    def job(ci, ri):
        params = {**base, **{n: values[j][idx] for j, (n, idx) in enumerate(zip(names, ci))}}
        acc, gyr, mag, fs = data[ri]
        q = _run(method, acc, gyr, mag, fs, params)
        s = score_fn(q, recs[ri])
        return ci, ri, (s if isinstance(s, xr.DataArray) else float(s))

    n_jobs = n_jobs or os.cpu_count() or 1
    tasks = [(ci, ri) for ci in combos for ri in range(len(recs))]
    if n_jobs == 1:
        results = [job(*t) for t in tasks]
    else:
        with ThreadPoolExecutor(max_workers=n_jobs) as ex:
            results = list(ex.map(lambda t: job(*t), tasks))
    extra_dims: tuple = ()
    extra_coords: dict = {}
    first = results[0][2]
    if isinstance(first, xr.DataArray):
        extra_dims = first.dims
        extra_coords = {d: first.coords[d].values for d in first.dims if d in first.coords}
        out = np.full(shape + first.shape, np.nan)
    for ci, ri, s in results:
        if extra_dims:
            if not isinstance(s, xr.DataArray) or s.dims != extra_dims or s.shape != first.shape:
                raise ValueError("score_fn must return DataArrays of identical dims and shape for every call")
            s = s.values
        out[ci + (ri,)] = s
    coords = {n: np.asarray(v) if np.asarray(v).dtype != object else list(map(str, v)) for n, v in zip(names, values)}
    coords["recording"] = labels
    coords.update(extra_coords)
    return xr.DataArray(out, dims=tuple(names) + ("recording",) + tuple(extra_dims), coords=coords, name="score",
                        attrs={"method": method, "use_mag": int(bool(use_mag)),
                               **{f"param_{k}": _attr_value(v) for k, v in fixed.items()}})
