r"""Estimate orientations from vector observations, sample by sample (Davenport).

Davenport's q-method is the optimum that QUEST approximates.

Wahba's problem: find the rotation :math:`A` (world → sensor) minimising
:math:`\tfrac12 \sum_i a_i \lVert b_i - A r_i \rVert^2` for unit observations
:math:`b_i` (sensor frame) of known unit reference directions :math:`r_i` (world
frame). With :math:`B = \sum_i a_i b_i r_i^\top`, :math:`S = B + B^\top`,
:math:`\sigma = \operatorname{tr} B` and
:math:`z = (B_{23} - B_{32},\ B_{31} - B_{13},\ B_{12} - B_{21})^\top`, the optimal
quaternion is the eigenvector of Davenport's matrix

.. math::
    K = \begin{pmatrix} \sigma & z^\top \\ z & S - \sigma I_3 \end{pmatrix}

with the largest eigenvalue. QUEST (Shuster & Oh 1981) finds the same eigenvector by a
Newton iteration on the characteristic polynomial; with numpy's batched symmetric
eigensolver the exact solution is as cheap, so it is computed directly.

Here the observations are the specific force (gravity up, world :math:`e_z`) and the
magnetic field (world direction :math:`(0, \cos\delta, -\sin\delta)` in ENU for a
dip :math:`\delta`, positive downwards).

References
----------
.. [1] P. B. Davenport, "A vector approach to the algebra of rotations with applications",
   NASA TN D-4696, 1968.
.. [2] M. D. Shuster and S. D. Oh, "Three-axis attitude determination from vector
   observations", J. Guid. Control 4:70–77, 1981. doi:10.2514/3.19717
.. [3] F. L. Markley and J. L. Crassidis, *Fundamentals of Spacecraft Attitude
   Determination and Control*, Springer, 2014, §5.5. doi:10.1007/978-1-4939-0802-8
"""

from __future__ import annotations

import numpy as np

from .. import _validate as _v
from ._common import unlabel

__all__ = ["davenport", "magnetic_dip"]


def _unit_rows(v, name: str) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    if v.ndim == 1:
        v = v[None, :]
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3) or (3,), got {v.shape}")
    n = np.linalg.norm(v, axis=1, keepdims=True)
    if not np.all(np.isfinite(n)) or np.any(n == 0):
        raise ValueError(f"{name} contains zero or non-finite vectors")
    return v / n


def _unit_pairs(acc, mag) -> tuple[np.ndarray, np.ndarray]:
    """Read labelled or plain ``acc`` and ``mag`` as unit rows of the same shape."""
    _, acc, _, mag = unlabel(None, acc=acc, mag=mag, need_fs=False)
    a = _unit_rows(acc, "acc")
    m = _unit_rows(mag, "mag")
    if a.shape != m.shape:
        raise ValueError(
            f"acc and mag must have the same shape, got {a.shape}, {m.shape}"
        )
    return a, m


def magnetic_dip(acc, mag) -> float:
    r"""Measure the magnetic dip angle :math:`\delta` from specific force and field samples.

    The dip is positive (rad) when the field points below the horizon: the mean of
    :math:`\arcsin(\hat m \cdot (-\hat a))` over the sensor-frame samples.

    Parameters
    ----------
    acc, mag : array_like or xarray.DataArray, shape (N, 3) or (3,)
        Accelerometer and magnetometer samples (any units), quasi-static. Labelled
        DataArrays must agree on ``fs`` and ``time``; a ``units`` attribute must be
        an acceleration (``acc``) or magnetic-field (``mag``) unit (see
        :mod:`tiltlab.filters`, "Labelled inputs").

    Returns
    -------
    float
        The dip (rad).
    """
    a, m = _unit_pairs(acc, mag)
    return float(np.mean(np.arcsin(np.clip(-np.sum(a * m, axis=1), -1.0, 1.0))))


def davenport(acc, mag, *, dip: float, weights: tuple[float, float] = (1.0, 1.0)):
    r"""Estimate each sample's orientation from its acc and mag vectors (Davenport).

    Sensor → world, ENU, by Davenport's q-method.

    Parameters
    ----------
    acc : array_like or xarray.DataArray, shape (N, 3) or (3,)
        Specific force (any unit; only its direction is used): gravity up when static.
    mag : array_like or xarray.DataArray, shape (N, 3) or (3,)
        Magnetic field (any unit; only its direction is used). Labelled DataArrays
        must agree on ``fs`` and ``time``; a ``units`` attribute must be an
        acceleration (``acc``) or magnetic-field (``mag``) unit (see
        :mod:`tiltlab.filters`, "Labelled inputs").
    dip : float
        Magnetic dip (rad, positive downwards), e.g. :func:`magnetic_dip` of a still
        period.
    weights : (float, float)
        Weights :math:`a_i` of the accelerometer and magnetometer observations
        (positive).

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions (w, x, y, z) with :math:`w \ge 0`.

    Notes
    -----
    With two observations the q-method's optimum depends on the weights only through
    how the angle mismatch between :math:`\angle(b_1, b_2)` and :math:`\angle(r_1, r_2)`
    is shared; with a dominant accelerometer weight it tends to TRIAD with gravity as
    the primary vector.
    """
    a, m = _unit_pairs(acc, mag)
    dip = _v.finite(dip, "dip")
    w_a = _v.positive(weights[0], "weights[0]")
    w_m = _v.positive(weights[1], "weights[1]")
    r_a = np.array([0.0, 0.0, 1.0])
    r_m = np.array([0.0, np.cos(dip), -np.sin(dip)])
    B = (
        w_a * a[:, :, None] * r_a[None, None, :]
        + w_m * m[:, :, None] * r_m[None, None, :]
    )
    S = B + np.transpose(B, (0, 2, 1))
    sigma = np.trace(B, axis1=1, axis2=2)
    z = np.stack(
        [B[:, 1, 2] - B[:, 2, 1], B[:, 2, 0] - B[:, 0, 2], B[:, 0, 1] - B[:, 1, 0]],
        axis=1,
    )
    K = np.empty((a.shape[0], 4, 4))
    K[:, 0, 0] = sigma
    K[:, 0, 1:] = z
    K[:, 1:, 0] = z
    K[:, 1:, 1:] = S - sigma[:, None, None] * np.eye(3)
    _, vecs = np.linalg.eigh(K)
    # With z defined as above and the scalar first, the eigenvector is the quaternion
    # of A^T (sensor → world) in tiltlab's convention (checked by a round trip in the
    # tests).
    q = vecs[:, :, -1]
    q = np.where(q[:, :1] < 0, -q, q)
    return q / np.linalg.norm(q, axis=1, keepdims=True)
