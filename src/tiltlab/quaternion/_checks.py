"""Input checks shared by the wrappers of :mod:`tiltlab.quaternion`."""

from __future__ import annotations

import numpy as np

# ---------------------------------------------------------------- wrappers


def _real(a, name: str) -> np.ndarray:
    """Return ``a`` as a float array; refuse complex input by name (never cut to real)."""
    raw = np.asarray(a)
    if raw.dtype.kind == "c":
        raise ValueError(
            f"{name} holds complex numbers (dtype {raw.dtype}); quaternions and vectors "
            f"are real: pass {name}.real explicitly if that is what you mean"
        )
    return np.asarray(raw, float)


def _as2d(a: np.ndarray, width: int) -> np.ndarray:
    return np.ascontiguousarray(a.reshape(-1, width), dtype=np.float64)


def _check_last(a: np.ndarray, width: int, name: str) -> None:
    if a.ndim == 0 or a.shape[-1] != width:
        raise ValueError(
            f"{name} must have last dimension {width}, got shape {a.shape}"
        )


def _broadcast(*named) -> list[np.ndarray]:
    """``np.broadcast_arrays`` of ``(name, array)`` pairs; a mismatch names them."""
    try:
        return np.broadcast_arrays(*(a for _, a in named))
    except ValueError:
        shapes = " and ".join(f"{n} {a.shape}" for n, a in named)
        raise ValueError(
            f"{' and '.join(n for n, _ in named)} have incompatible shapes: {shapes}"
        ) from None


def _no_inf(a: np.ndarray, name: str) -> np.ndarray:
    """Return ``a`` unchanged; raise on infinite values (NaN, a missing sample, passes)."""
    if np.any(np.isinf(a)):
        raise ValueError(f"{name} has {int(np.sum(np.isinf(a)))} infinite values")
    return a


def _no_zero(q: np.ndarray, name: str) -> np.ndarray:
    """``q`` unchanged; a zero quaternion, which is no rotation, raises."""
    if np.any(np.sum(q * q, axis=-1) == 0):
        raise ValueError(f"{name} has zero quaternions, which are not rotations")
    return q


def _finite(a, width: int, name: str) -> np.ndarray:
    """Return ``a`` as a real float array (..., ``width``) without ±inf; else raise naming it."""
    a = _real(a, name)
    _check_last(a, width, name)
    return _no_inf(a, name)


def _rotations(q, name: str) -> np.ndarray:
    """Return ``q`` as real quaternions (..., 4) that can be rotations: no ±inf, no zero."""
    return _no_zero(_finite(q, 4, name), name)


def check_unit(q: np.ndarray, name: str = "q", atol: float = 1e-6) -> None:
    """Raise unless every finite quaternion of ``q`` (…, 4) has norm 1 within ``atol``.

    NaN quaternions (missing samples) pass; infinities do not.

    Parameters
    ----------
    q : numpy.ndarray, shape (..., 4)
        The quaternions.
    name : str, optional
        Argument name used in the error message (default ``"q"``).
    atol : float, optional
        Tolerance on the norm (default 1e-6).

    Raises
    ------
    ValueError
        If a quaternion holds ±inf or has a norm other than 1 (zero included).
    """
    if np.any(np.isinf(q)):
        raise ValueError(f"{name} has infinite values")
    n = np.linalg.norm(q, axis=-1)
    bad = np.abs(n - 1.0) > atol  # NaN compares False
    if np.any(bad):
        k = int(np.argmax(bad.ravel()))
        raise ValueError(
            f"{name} must hold unit quaternions: {int(bad.sum())} have a norm other than "
            f"1 (first: {float(n.ravel()[k]):.6g}); normalise them first "
            "(a zero quaternion is not a rotation)"
        )


def check_rotation(m: np.ndarray, name: str = "m", atol: float = 1e-6) -> None:
    r"""Raise unless every finite (3, 3) matrix of ``m`` is a proper rotation.

    Proper: orthonormal within ``atol``, determinant +1. NaN matrices (missing samples)
    pass; infinities do not.

    Parameters
    ----------
    m : numpy.ndarray, shape (..., 3, 3)
        The matrices.
    name : str, optional
        Argument name used in the error message (default ``"m"``).
    atol : float, optional
        Tolerance on :math:`\max|M^\top M - I|` (default 1e-6).

    Raises
    ------
    ValueError
        If a matrix holds ±inf, is not orthonormal or is a reflection (det −1).
    """
    if np.any(np.isinf(m)):
        raise ValueError(f"{name} has infinite values")
    M = m[np.all(np.isfinite(m), axis=(-2, -1))]
    if M.size == 0:
        return
    err = np.abs(np.swapaxes(M, -1, -2) @ M - np.eye(3)).max(axis=(-2, -1))
    if np.any(err > atol):
        raise ValueError(
            f"{name} must hold rotation matrices (orthonormal, det +1): "
            f"max |MᵀM − I| = {float(err.max()):.3g}"
        )
    det = np.linalg.det(M)
    if np.any(det < 0):
        raise ValueError(
            f"{name} must hold rotation matrices (det +1), got {int(np.sum(det < 0))} "
            "reflection(s) (det −1)"
        )
