r"""Accelerometer calibration from static poses, and tumble-test design.

Accelerometer calibration from static poses: offset-only sphere fit, ellipsoid fit,
known-direction linear fit, and tumble-test design (Fibonacci lattice, stage angles).

Sensor model
------------
A static accelerometer reads :math:`y = T\,g + o + n`, with :math:`g` the unit
gravity-up direction in the sensor frame (1 g), :math:`o` the offsets, :math:`T` a
scale/misalignment matrix (:math:`T = I` for a perfect sensor) and :math:`n` noise.
The correction is :math:`\hat g = C (y - o)` with :math:`C = T^{-1}`.

* **Offsets only** (Fayat et al. 2021 [1]_ §2.5): :math:`T = I`,
  :math:`\hat o = \arg\min_o \frac1P\sum_p (1 - \|a_p - o\|)^2` over the static means
  :math:`a_p`. Three non-collinear directions determine it; it cannot absorb scale or
  misalignment, which leave a residual floor (their §3.1: 0.0070 g).
* **Ellipsoid** (9 parameters): the norm constraint :math:`\|C(y-o)\| = 1` only sees
  :math:`C^\top C`; any rotation :math:`QC` fits equally well. We fix the gauge with an
  upper-triangular :math:`C` (sensor x axis defines the corrected x axis, the xy plane
  the corrected xy plane) or a symmetric :math:`C` (the usual choice for magnetometer
  soft iron). Solved by a normalised algebraic quadric fit (linear, SVD) then a
  Gauss–Newton/Levenberg–Marquardt refinement of the geometric residuals
  :math:`\|C(y_p-o)\| - r`, whose Jacobian gives parameter standard errors.
* **Known directions** (12 parameters): if the stage directions :math:`g_p` are known,
  :math:`y_p = T g_p + o` is linear in the 12 unknowns (ordinary least squares per
  axis). The recovered :math:`T` includes the mounting rotation of the sensor on the
  stage.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
.. [2] J. F. Vasconcelos et al., "Geometric approach to strapdown magnetometer
   calibration in sensor frame", IEEE Trans. Aerosp. Electron. Syst. 47(2):1293–1306,
   2011. doi:10.1109/TAES.2011.5751259
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.optimize import least_squares

from ..frames import fibonacci_lattice, stage_angles, stage_quaternion
from .. import _validate as _v
from ._util import CalibrationError, mat3, vec3

__all__ = [
    "norm_error",
    "OffsetFit",
    "fit_offsets",
    "fit_offsets_batch",
    "EllipsoidFit",
    "fit_ellipsoid",
    "LinearFit",
    "fit_known_directions",
    "identifiable_matrix",
    "fibonacci_lattice",
    "stage_angles",
    "stage_quaternion",
]


def _points(
    points, radius, name="points", min_n=1, max_norm_deviation=0.25
) -> np.ndarray:
    p = vec3(points, name, ndim=2)
    radius = _v.positive(radius, "radius")
    max_norm_deviation = _v.positive(
        max_norm_deviation, "max_norm_deviation", allow_inf=True
    )
    if p.shape[0] < min_n:
        raise CalibrationError(
            f"{p.shape[0]} static poses given, at least {min_n} are needed for this fit"
        )
    nrm = np.linalg.norm(p, axis=1)
    bad = np.abs(nrm / radius - 1.0) > max_norm_deviation
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        raise CalibrationError(
            f"static pose {k} has norm {nrm[k]:.4g}, more than {100 * max_norm_deviation:.0f} % "
            f"away from {radius:g}: saturated, moving, or wrong units"
        )
    return p


def _sem(sem, p: np.ndarray) -> np.ndarray | None:
    # standard errors of the points, checked against their shape (None passes)
    if sem is None:
        return None
    se = vec3(sem, "sem", ndim=2)
    if se.shape != p.shape:
        raise ValueError("sem must have the same shape as points")
    return se


def norm_error(points, offset=None, matrix=None, radius: float = 1.0) -> np.ndarray:
    r"""Signed norm error :math:`\|C(a - o)\| - r` of (corrected) static readings.

    Parameters
    ----------
    points : array_like, shape (..., 3)
        Static readings (e.g. accelerometer means, in g).
    offset : array_like, shape (3,), optional
        Offset :math:`o` subtracted first (units of ``points``); default none.
    matrix : array_like, shape (3, 3), optional
        Correction matrix :math:`C` applied after the offset; default identity.
    radius : float
        Expected norm :math:`r` (units of ``points``; 1 for g).

    Returns
    -------
    numpy.ndarray, shape (...)
        Norm error per reading (units of ``points``).
    """
    p = vec3(points, "points")
    d = p - (0.0 if offset is None else vec3(offset, "offset", ndim=1))
    if matrix is not None:
        d = d @ mat3(matrix, "matrix").T
    return np.linalg.norm(d, axis=-1) - _v.positive(radius, "radius")


def _condition_or_raise(J, what, max_condition):
    s = np.linalg.svd(J, compute_uv=False)
    cond = np.inf if s[-1] <= 0 else s[0] / s[-1]
    if not np.isfinite(cond) or cond > max_condition:
        raise CalibrationError(
            f"the static orientations do not determine the {what} (condition number {cond:.3g} > "
            f"{max_condition:g}): orientations are collinear/coplanar or too few"
        )
    return cond


class OffsetFit(NamedTuple):
    """Result of :func:`fit_offsets`.

    Offset-only fit: ``offset`` (3,), ``stderr`` (3,), ``cov`` (3, 3), ``residuals``
    (P,) signed norm errors at the solution, ``mean_abs_error`` (mean of |1 − ‖a − o‖|),
    ``condition`` (Jacobian condition number) and ``n`` (poses).
    """

    offset: np.ndarray
    stderr: np.ndarray
    cov: np.ndarray
    residuals: np.ndarray
    mean_abs_error: float
    condition: float
    n: int


def fit_offsets(
    points,
    *,
    sem=None,
    radius: float = 1.0,
    x0=None,
    max_condition: float = 1e3,
    max_norm_deviation: float = 0.25,
) -> OffsetFit:
    r"""Accelerometer offsets by Fayat's criterion, :math:`\arg\min_o \frac1P\sum_p(r - \|a_p - o\|)^2`.

    Parameters
    ----------
    points : array_like (P, 3)
        Static mean readings :math:`a_p` (g), P ≥ 3 in non-collinear directions.
    sem : array_like (P, 3), optional
        Standard errors of the means; used to weight the residuals and to propagate
        uncertainty when P = 3 (no residual degrees of freedom).
    radius : float
        Expected norm (1 g).
    x0 : array_like (3,), optional
        Starting offset (default zero).
    max_condition : float
        Largest accepted condition number of the Jacobian (unit directions); above it
        the orientations cannot determine the offsets and :class:`CalibrationError` is
        raised.
    max_norm_deviation : float
        Largest accepted relative deviation of a pose's norm from ``radius`` (0.25:
        25 %); a larger one (saturated, moving, wrong units) raises
        :class:`CalibrationError`.

    Returns
    -------
    OffsetFit

    Notes
    -----
    The residual is linearised as :math:`\partial (\|a_p-o\|)/\partial o = -u_p^\top`
    with :math:`u_p` the unit direction, so the covariance is
    :math:`(J^\top W J)^{-1}` with :math:`W = \mathrm{diag}(1/\sigma_p^2)`,
    :math:`\sigma_p^2 = u_p^\top \Sigma_p u_p`, when ``sem`` is given, and
    :math:`s^2 (J^\top J)^{-1}` with the residual variance :math:`s^2` otherwise.
    """
    p = _points(points, radius, min_n=3, max_norm_deviation=max_norm_deviation)
    max_condition = _v.positive(max_condition, "max_condition")
    x0 = np.zeros(3) if x0 is None else vec3(x0, "x0", ndim=1)
    w = np.ones(p.shape[0])
    se = _sem(sem, p)

    def resid(o):
        return (np.linalg.norm(p - o, axis=1) - radius) * w

    sol = least_squares(
        resid, x0, method="lm" if p.shape[0] >= 3 else "trf", xtol=1e-14, ftol=1e-14
    )
    o = sol.x
    u = (p - o) / np.linalg.norm(p - o, axis=1, keepdims=True)
    J = -u
    cond = _condition_or_raise(J, "offsets", max_condition)
    r = np.linalg.norm(p - o, axis=1) - radius
    if sem is not None:
        var = np.einsum("pi,pi->p", u * u, se * se)
        cov = np.linalg.inv(J.T @ (J / var[:, None]))
    elif p.shape[0] > 3:
        s2 = float(r @ r) / (p.shape[0] - 3)
        cov = s2 * np.linalg.inv(J.T @ J)
    else:
        cov = np.full((3, 3), np.nan)
    return OffsetFit(
        o,
        np.sqrt(np.diag(cov)),
        cov,
        r,
        float(np.mean(np.abs(r))),
        float(cond),
        p.shape[0],
    )


def fit_offsets_batch(
    points, *, radius: float = 1.0, iterations: int = 30, damping: float = 1e-9
) -> np.ndarray:
    r"""Fayat offset fits for many small sets of poses at once (vectorised Gauss–Newton).

    Parameters
    ----------
    points : array_like (B, k, 3)
        B sets of k static means each (k ≥ 2; k = 2 is underdetermined and the damped
        iteration started at zero returns the solution closest to zero along its path).
    radius : float
        Expected norm (1 g).
    iterations : int
        Largest number of Gauss–Newton steps.
    damping : float
        Levenberg damping, relative to the trace of :math:`J^\top J`.

    Returns
    -------
    ndarray (B, 3)
        Offsets; used for subset studies (Fayat Fig. 1c) where thousands of fits are needed.
    """
    p = vec3(points, "points", ndim=3)
    radius = _v.positive(radius, "radius")
    iterations = _v.integer(iterations, "iterations", minimum=1)
    damping = _v.nonnegative(damping, "damping")
    o = np.zeros((p.shape[0], 3))
    eye = np.eye(3)
    for _ in range(iterations):
        d = p - o[:, None, :]
        nd = np.linalg.norm(d, axis=2)
        r = nd - radius
        J = -d / nd[..., None]
        JtJ = np.einsum("bki,bkj->bij", J, J)
        Jtr = np.einsum("bki,bk->bi", J, r)
        lam = damping * np.trace(JtJ, axis1=1, axis2=2)[:, None, None] + 1e-12
        step = np.linalg.solve(JtJ + lam * eye, -Jtr[..., None])[..., 0]
        o = o + step
        if np.max(np.abs(step)) < 1e-13:
            break
    return o


def identifiable_matrix(matrix) -> np.ndarray:
    r"""Upper-triangular factor :math:`R` (positive diagonal) of :math:`C = QR`.

    Norm-based fits determine only :math:`C^\top C = R^\top R`; compare a fitted
    triangular :math:`C` with the truth through ``identifiable_matrix(C_true)``.

    Parameters
    ----------
    matrix : array_like, shape (3, 3)
        An invertible correction matrix :math:`C`.

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        Upper-triangular :math:`R` with a positive diagonal.

    Raises
    ------
    ValueError
        If ``matrix`` is singular.
    """
    C = mat3(matrix, "matrix")
    if np.linalg.matrix_rank(C) < 3:
        raise ValueError("matrix is singular: a correction matrix must be invertible")
    _, R = np.linalg.qr(C)
    return np.diag(np.sign(np.diag(R))) @ R


class EllipsoidFit(NamedTuple):
    """Result of :func:`fit_ellipsoid`.

    Ellipsoid fit: ``offset`` (3,), ``matrix`` C (3, 3) with ‖C(y − o)‖ ≈ r,
    ``params``/``stderr`` (9,) [o (3), then the free entries of C: upper triangle row-major
    for "triangular", (xx, xy, xz, yy, yz, zz) for "symmetric"], ``offset_stderr`` (3,),
    ``matrix_stderr`` (3, 3), ``cov`` (9, 9), ``residuals`` (P,), ``mean_abs_error``,
    ``condition``, ``structure``, ``n``.
    """

    offset: np.ndarray
    matrix: np.ndarray
    params: np.ndarray
    stderr: np.ndarray
    offset_stderr: np.ndarray
    matrix_stderr: np.ndarray
    cov: np.ndarray
    residuals: np.ndarray
    mean_abs_error: float
    condition: float
    structure: str
    n: int


_TRI = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]


def _c_from(v, structure):
    C = np.zeros((3, 3))
    for val, (i, j) in zip(v, _TRI):
        C[i, j] = val
        if structure == "symmetric":
            C[j, i] = val
    return C


def _algebraic_quadric(p):
    # normalise for conditioning: y = (p - m) / s
    m = p.mean(axis=0)
    s = np.sqrt(np.mean(np.sum((p - m) ** 2, axis=1)))
    y = (p - m) / s
    x, yy, z = y.T
    D = np.column_stack(
        [
            x * x,
            yy * yy,
            z * z,
            2 * x * yy,
            2 * x * z,
            2 * yy * z,
            2 * x,
            2 * yy,
            2 * z,
            np.ones_like(x),
        ]
    )
    _, sv, Vt = np.linalg.svd(D, full_matrices=False)
    v = Vt[-1]
    A = np.array([[v[0], v[3], v[4]], [v[3], v[1], v[5]], [v[4], v[5], v[2]]])
    b = 2 * v[6:9]
    c = v[9]
    return A, b, c, m, s, sv


def _ellipsoid_start(p, radius, structure, max_condition) -> np.ndarray:
    # the algebraic (linear) fit: starting parameters [o, free entries of C]
    A, b, c, m, s, sv = _algebraic_quadric(p)
    # second-smallest singular value small -> the quadric is not unique (poses too few/degenerate)
    if sv.size < 10 or sv[-2] / sv[0] < 1.0 / max_condition:
        raise CalibrationError(
            "the static orientations do not determine a 9-parameter ellipsoid: "
            "they are too few or lie on a plane/cone (use fit_offsets instead)"
        )
    try:
        o_n = -0.5 * np.linalg.solve(A, b)
    except np.linalg.LinAlgError as e:
        raise CalibrationError(
            "degenerate quadric: orientations do not determine an ellipsoid"
        ) from e
    k = o_n @ A @ o_n - c
    M = A / k
    ev = np.linalg.eigvalsh(M)
    if np.any(ev <= 0):
        raise CalibrationError(
            "the fitted quadric is not an ellipsoid (orientations too poorly spread)"
        )
    M = M / s**2  # back to original units
    o = m + s * o_n
    if structure == "triangular":
        C0 = np.linalg.cholesky(M).T
    else:
        w, V = np.linalg.eigh(M)
        C0 = (V * np.sqrt(w)) @ V.T
    C0 = C0 * radius
    return np.concatenate([o, [C0[i, j] for i, j in _TRI]])


def _ellipsoid_resid(v, p, radius, structure):
    # geometric residuals ||C (p - o)|| - r
    return np.linalg.norm((p - v[:3]) @ _c_from(v[3:], structure).T, axis=1) - radius


def _ellipsoid_jac(v, p, structure):
    # Jacobian of _ellipsoid_resid with respect to v (P, 9)
    o_, C = v[:3], _c_from(v[3:], structure)
    d = p - o_
    x = d @ C.T
    nx = np.linalg.norm(x, axis=1, keepdims=True)
    u = x / nx  # d r / d x
    J = np.empty((p.shape[0], 9))
    J[:, :3] = -(u @ C)
    for col, (i, j) in enumerate(_TRI):
        g = u[:, i] * d[:, j]
        if structure == "symmetric" and i != j:
            g = g + u[:, j] * d[:, i]
        J[:, 3 + col] = g
    return J


def _ellipsoid_refine(p, radius, structure, v0, se) -> tuple[np.ndarray, np.ndarray]:
    # least-squares refinement of the geometric residuals; with standard errors ``se``
    # a first unweighted pass gives the weights of the second. Returns (v, weights).
    def resid(v):
        return _ellipsoid_resid(v, p, radius, structure)

    def jac(v):
        return _ellipsoid_jac(v, p, structure)

    if se is None:
        sol = least_squares(resid, v0, jac=jac, method="lm", xtol=1e-15, ftol=1e-15)
        return sol.x, np.ones(p.shape[0])
    sol0 = least_squares(resid, v0, jac=jac, method="lm", xtol=1e-15, ftol=1e-15)
    u0 = (p - sol0.x[:3]) @ _c_from(sol0.x[3:], structure).T
    u0 /= np.linalg.norm(u0, axis=1, keepdims=True)
    Cs = _c_from(sol0.x[3:], structure)
    gp = u0 @ Cs  # d r_p / d y_p
    var = np.sum(gp * gp * se * se, axis=1)
    wts = 1.0 / np.sqrt(var)
    sol = least_squares(
        lambda v: resid(v) * wts,
        sol0.x,
        jac=lambda v: jac(v) * wts[:, None],
        method="lm",
        xtol=1e-15,
        ftol=1e-15,
    )
    return sol.x, wts


def fit_ellipsoid(
    points,
    *,
    radius: float = 1.0,
    sem=None,
    structure: str = "triangular",
    max_condition: float = 1e4,
    max_norm_deviation: float = 0.25,
) -> EllipsoidFit:
    r"""Nine-parameter ellipsoid fit :math:`\|C(y_p - o)\| = r` (offsets, scales, misalignment).

    Parameters
    ----------
    points : array_like (P, 3)
        Static readings (P ≥ 9, well spread over the sphere; 10 or more give residual
        degrees of freedom for uncertainties without ``sem``).
    radius : float
        Norm of the true vector (1 for an accelerometer in g; the field strength for a
        magnetometer).
    sem : array_like (P, 3), optional
        Standard errors of the points; weights and uncertainty propagation.
    structure : {"triangular", "symmetric"}
        Gauge of C (see module notes).
    max_condition : float
        Largest accepted condition number of the (normalised) Jacobian.
    max_norm_deviation : float
        Largest accepted relative deviation of a pose's norm from ``radius``, as in
        :func:`fit_offsets`.

    Returns
    -------
    EllipsoidFit

    Notes
    -----
    Linear step: the algebraic quadric :math:`y^\top A y + b^\top y + c = 0` is the
    right-singular vector of the smallest singular value of the design matrix built
    from the centred, scaled points; :math:`o = -A^{-1}b/2`, :math:`M = A/(o^\top A o - c)`,
    :math:`C = \mathrm{chol}(M)^\top` (or :math:`M^{1/2}`), times r. Then
    :func:`scipy.optimize.least_squares` (LM) minimises the geometric residuals.
    """
    if structure not in ("triangular", "symmetric"):
        raise ValueError(
            f"structure must be 'triangular' or 'symmetric', got {structure!r}"
        )
    p = _points(points, radius, min_n=9, max_norm_deviation=max_norm_deviation)
    max_condition = _v.positive(max_condition, "max_condition")
    v0 = _ellipsoid_start(p, radius, structure, max_condition)
    se = _sem(sem, p)
    v, wts = _ellipsoid_refine(p, radius, structure, v0, se)
    J = _ellipsoid_jac(v, p, structure) * wts[:, None]
    Jn = J / np.linalg.norm(J, axis=0)
    cond = _condition_or_raise(Jn, "9-parameter ellipsoid", max_condition)
    r = _ellipsoid_resid(v, p, radius, structure)
    JtJi = np.linalg.inv(J.T @ J)
    if sem is not None:
        cov = JtJi
    elif p.shape[0] > 9:
        cov = JtJi * float(r @ r) / (p.shape[0] - 9)
    else:
        cov = np.full((9, 9), np.nan)
    se_v = np.sqrt(np.diag(cov))
    C = _c_from(v[3:], structure)
    Cse = _c_from(se_v[3:], structure)
    if structure == "triangular":
        Cse = np.triu(Cse)
    return EllipsoidFit(
        v[:3].copy(),
        C,
        v,
        se_v,
        se_v[:3],
        Cse,
        cov,
        r,
        float(np.mean(np.abs(r))),
        float(cond),
        structure,
        p.shape[0],
    )


class LinearFit(NamedTuple):
    """Result of :func:`fit_known_directions`.

    Known-direction fit :math:`y = T g + o`: ``offset`` (3,), ``sensor_matrix`` T,
    ``matrix`` C = T⁻¹, ``offset_stderr`` (3,), ``sensor_matrix_stderr`` (3, 3),
    ``residuals`` (P, 3), ``n``.
    """

    offset: np.ndarray
    sensor_matrix: np.ndarray
    matrix: np.ndarray
    offset_stderr: np.ndarray
    sensor_matrix_stderr: np.ndarray
    residuals: np.ndarray
    n: int


def fit_known_directions(
    points, directions, *, max_condition: float = 1e3
) -> LinearFit:
    r"""Twelve-parameter calibration :math:`y_p = T g_p + o` when the true unit directions are known.

    Each axis i is an ordinary least-squares regression of :math:`y_{p,i}` on
    :math:`(g_p^\top, 1)`; needs P ≥ 4 non-coplanar directions (P ≥ 5 for standard
    errors). T includes the mounting rotation of the sensor in the stage frame.

    Parameters
    ----------
    points : array_like, shape (P, 3)
        Static readings :math:`y_p` (e.g. accelerometer means, in g).
    directions : array_like, shape (P, 3)
        True unit directions :math:`g_p` of gravity in the stage frame, one per pose.
    max_condition : float
        Largest accepted condition number of the design matrix; beyond it the poses
        are too close to coplanar.

    Returns
    -------
    LinearFit
        ``offset`` (3,), ``sensor_matrix`` T (3, 3), ``matrix`` :math:`C = T^{-1}`,
        their standard errors (NaN for P = 4), ``residuals`` (P, 3) and ``n`` = P.

    Raises
    ------
    CalibrationError
        Fewer than 4 poses, or an ill-conditioned design.
    """
    y = vec3(points, "points", ndim=2)
    g = vec3(directions, "directions", ndim=2)
    max_condition = _v.positive(max_condition, "max_condition")
    if g.shape != y.shape:
        raise ValueError("points and directions must have the same shape")
    if y.shape[0] < 4:
        raise CalibrationError(
            f"{y.shape[0]} poses given, at least 4 non-coplanar ones are needed for 12 parameters"
        )
    X = np.column_stack([g, np.ones(y.shape[0])])
    _condition_or_raise(X, "12-parameter linear model", max_condition)
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)  # (4, 3): rows gx, gy, gz, 1
    T, o = beta[:3].T, beta[3]
    res = y - X @ beta
    dof = y.shape[0] - 4
    if dof > 0:
        s2 = np.sum(res**2, axis=0) / dof
        XtXi = np.linalg.inv(X.T @ X)
        se = np.sqrt(np.outer(s2, np.diag(XtXi)))  # (3 axes, 4 coefs)
        T_se, o_se = se[:, :3], se[:, 3]
    else:
        T_se, o_se = np.full((3, 3), np.nan), np.full(3, np.nan)
    return LinearFit(o, T, np.linalg.inv(T), o_se, T_se, res, y.shape[0])


# ---------------------------------------------------------------------------- design


# The lattice and the stage geometry are implemented once, in tiltlab.frames
# (Fayat App. A.1); calibration re-exports them under the names used in its chapter.
