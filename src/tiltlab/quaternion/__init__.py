r"""Quaternion kernels (numba) over arrays of unit quaternions.

Conventions (the book's conventions page states them once):

* scalar first: ``q = (w, x, y, z)``;
* a quaternion rotates **sensor → world**: a vector with sensor coordinates
  :math:`v_s` has world coordinates :math:`v_w = R(q)\,v_s = q \otimes v_s \otimes q^*`;
* world z points up, so the tilt (gravity-up direction in the sensor frame) is
  :math:`g_s = R(q)^\top e_z`;
* angular velocity is expressed in the sensor frame, so orientation propagates as
  :math:`\dot q = \tfrac12\, q \otimes (0, \omega)`.

Every public function accepts arrays with any leading shape (``(..., 4)`` for
quaternions, ``(..., 3)`` for vectors, ``(..., 3, 3)`` for matrices), broadcasts
its arguments, never modifies its inputs and returns new arrays. The loops run in
``@njit(cache=True)`` kernels.

Inputs are checked before the kernels run (:class:`ValueError` naming the argument):
NaN marks a missing sample and propagates, but a complex value (never cut to its real
part), an infinite value, a zero quaternion or
vector (no rotation, no direction), a non-unit quaternion where a rotation matrix or
angle is derived from it (:func:`to_matrix`, :func:`to_rotvec`, tolerance 1e-6) and a
matrix that is not a rotation (:func:`from_matrix`: orthonormal within 1e-6, det +1)
are errors, never silently wrong or NaN output.

References
----------
.. [1] J. Solà, "Quaternion kinematics for the error-state Kalman filter",
   arXiv:1711.02508, 2017.
.. [2] S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance and Control
   1(3):223–224, 1978. doi:10.2514/3.55767b
.. [3] D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust
   Inertial Orientation Estimation", Data 6(7):72, 2021. doi:10.3390/data6070072
"""

from __future__ import annotations

from ._kernels import (
    qmul_scalar as qmul_scalar,
    rotvec_to_quat_scalar as rotvec_to_quat_scalar,
    zoh_step_scalar as zoh_step_scalar,
    rotmat_scalar as rotmat_scalar,
    rotate_scalar as rotate_scalar,
    _mul_kernel as _mul_kernel,
    _rotate_kernel as _rotate_kernel,
    _to_matrix_kernel as _to_matrix_kernel,
    _from_matrix_kernel as _from_matrix_kernel,
    _to_rotvec_kernel as _to_rotvec_kernel,
    _from_rotvec_kernel as _from_rotvec_kernel,
    _gravity_kernel as _gravity_kernel,
    _error_angles_kernel as _error_angles_kernel,
    _angle_between_kernel as _angle_between_kernel,
    _integrate_kernel as _integrate_kernel,
)
from ._checks import (
    _real as _real,
    _as2d as _as2d,
    _check_last as _check_last,
    _broadcast as _broadcast,
    _no_inf as _no_inf,
    _no_zero as _no_zero,
    check_unit as check_unit,
    check_rotation as check_rotation,
)
from ._algebra import (
    identity,
    mul,
    conj,
    inv,
    norm,
    normalize,
    canonical,
    rotate,
    rotate_inverse,
    _rotate as _rotate,
    to_matrix,
    from_matrix,
    to_rotvec,
    from_rotvec,
    exp,
    log,
)
from ._errors import (
    gravity,
    angle_between,
    error_quaternion,
    error_angles,
    total_error,
    heading_error,
    tilt_error,
)
from ._convert import (
    integrate_gyro,
    slerp,
    from_scipy,
    to_scipy,
    random_quaternions,
)

__all__ = [
    "identity",
    "mul",
    "conj",
    "inv",
    "norm",
    "normalize",
    "canonical",
    "rotate",
    "rotate_inverse",
    "to_matrix",
    "from_matrix",
    "to_rotvec",
    "from_rotvec",
    "exp",
    "log",
    "gravity",
    "angle_between",
    "error_quaternion",
    "error_angles",
    "tilt_error",
    "heading_error",
    "total_error",
    "integrate_gyro",
    "slerp",
    "from_scipy",
    "to_scipy",
    "random_quaternions",
]
