r"""Dead reckoning between GNSS anchors (Benhamou 2023 §8, Eqs. 17, 19).

Per-step inputs (speed proxy, azimuth, elevation in radians) are arrays; positions
are in metres in a local ENU frame (:func:`lonlat_to_local`). Simulated tracks for
demonstrations are in :func:`tiltlab.simulate.simulate_track`.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._stack import user_stacklevel
import tiltlab._validate as _v
from ..frames import _vec3, unit_vector, wrap_angle

__all__ = [
    "EARTH_RADIUS",
    "lonlat_to_local",
    "local_to_lonlat",
    "velocity_components",
    "dead_reckon",
    "dead_reckon_2d",
    "anchored_errors",
]

EARTH_RADIUS = 6_371_000.0
"""Mean Earth radius (m) used by Benhamou (2023) §8."""


def lonlat_to_local(
    lon0, lat0, lon1, lat1, *, radius: float = EARTH_RADIUS
) -> tuple[np.ndarray, np.ndarray]:
    r"""§8 local flat-Earth step between two fixes (radians): :math:`X=R(\Xi_1-\Xi_0)\cos((\Psi_0+\Psi_1)/2)`, :math:`Y=R(\Psi_1-\Psi_0)` (m).

    The longitude difference is wrapped to (−π, π].

    Parameters
    ----------
    lon0, lat0 : float or array_like
        Longitude Ξ0 and latitude Ψ0 (rad) of the first fix.
    lon1, lat1 : float or array_like
        Longitude Ξ1 and latitude Ψ1 (rad) of the second fix.
    radius : float
        Earth radius R (m), > 0; default :data:`EARTH_RADIUS`.

    Returns
    -------
    x : ndarray
        Eastward displacement X (m).
    y : ndarray
        Northward displacement Y (m).
    """
    radius = _v.positive(radius, "radius")
    lat0, lat1 = np.asarray(lat0, float), np.asarray(lat1, float)
    dlon = wrap_angle(np.asarray(lon1, float) - lon0)
    return radius * dlon * np.cos((lat0 + lat1) / 2), radius * (lat1 - lat0)


def local_to_lonlat(
    x, y, lon0, lat0, lat1, *, radius: float = EARTH_RADIUS
) -> tuple[np.ndarray, np.ndarray]:
    r"""Inverse of :func:`lonlat_to_local` for in-between points: :math:`\xi=\Xi_0+x/(R\cos((\Psi_0+\Psi_1)/2))`, :math:`\psi=\Psi_0+y/R`.

    A step centred on a pole (cos of the mean latitude 0) has no longitude: NaN, with a
    :class:`RuntimeWarning`.

    Parameters
    ----------
    x, y : float or array_like
        Eastward and northward displacement (m) from the first fix.
    lon0, lat0 : float or array_like
        Longitude Ξ0 and latitude Ψ0 (rad) of the first fix.
    lat1 : float or array_like
        Latitude Ψ1 (rad) of the second fix (sets the mean latitude of the step).
    radius : float
        Earth radius R (m), > 0; default :data:`EARTH_RADIUS`.

    Returns
    -------
    lon : ndarray
        Longitude ξ (rad), wrapped to (−π, π]; NaN for a step centred on a pole.
    lat : ndarray
        Latitude ψ (rad).
    """
    radius = _v.positive(radius, "radius")
    c = np.cos((np.asarray(lat0, float) + np.asarray(lat1, float)) / 2)
    pole = np.abs(c) < 1e-12
    if np.any(pole):
        warnings.warn(
            f"local_to_lonlat: {int(np.sum(pole))} step(s) centred on a pole, where "
            "the longitude is undefined; set to NaN",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        lon = np.asarray(lon0, float) + np.asarray(x, float) / (radius * c)
    return wrap_angle(np.where(pole, np.nan, lon)), np.asarray(
        lat0, float
    ) + np.asarray(y, float) / radius


def velocity_components(speed, az, el=None) -> np.ndarray:
    r"""Velocity (proxy) vectors :math:`\tilde v_i[\theta_i\bullet\phi_i]`, shape (N, 3) (elevation 0 if ``el`` is None).

    Parameters
    ----------
    speed : array_like, shape (N,)
        Speed proxy ṽ_i (any positive scale, e.g. m/s).
    az : array_like, shape (N,)
        Azimuth θ_i (rad, ccw from East).
    el : array_like, shape (N,), optional
        Elevation φ_i (rad); None for a horizontal path.

    Returns
    -------
    ndarray, shape (N, 3)
        (East, North, Up) velocity components, in the units of ``speed``.
    """
    el = np.zeros_like(np.asarray(az, float)) if el is None else el
    return np.asarray(speed, float)[..., None] * unit_vector(az, el)


def _steps(**named) -> list[np.ndarray]:
    """Check per-step inputs: finite 1-D arrays of one length.

    NaN/inf or a mismatch is an error naming the argument (a NaN step would corrupt its
    whole anchor interval).
    """
    out = [_v.vectors(a, k, width=None, ndim=1) for k, a in named.items()]
    n = out[0].shape[0]
    for k, a in zip(named, out, strict=True):
        if a.shape[0] != n:
            raise ValueError(
                f"{k} must have one value per step ({n}, like speed), got {a.shape[0]}"
            )
    return out


def _check_anchors(anchors, anchor_steps, n, dim):
    X = _v.vectors(anchors, "anchors", width=dim, ndim=2)
    idx = np.asarray(anchor_steps)
    if idx.shape != (X.shape[0],) or X.shape[0] < 2:
        raise ValueError(
            "anchor_steps must have one index per anchor and at least two anchors"
        )
    if (
        not np.issubdtype(idx.dtype, np.integer)
        or idx[0] != 0
        or idx[-1] != n
        or np.any(np.diff(idx) <= 0)
    ):
        raise ValueError(
            f"anchor_steps must be strictly increasing integers from 0 to the number of steps ({n})"
        )
    return X, idx


def dead_reckon(
    speed,
    az,
    el,
    anchors,
    anchor_steps,
    *,
    dt_s: float | None = None,
    current=None,
    return_water: bool = False,
) -> np.ndarray:
    r"""3-D dead reckoning between GNSS anchors with rotation and rescaling, Eq. 17.

    For each interval I (steps ``anchor_steps[I-1]`` … ``anchor_steps[I]``), the
    dead-reckoned vector :math:`\sum_i\tilde{\mathbf v}_i` (azimuth :math:`\hat\Theta`,
    elevation :math:`\hat\Phi`, norm :math:`\tilde V`) is rotated onto the ground-truth
    step (L, Θ, Φ) by :math:`R_3(\Theta)R_2(\Phi-\hat\Phi)R_3(-\hat\Theta)` and rescaled by
    :math:`L/\tilde V`; each step uses Eqs. 17a–c with the intermediate p, q, r.

    Parameters
    ----------
    speed, az, el : array_like, shape (N,)
        Speed proxy ṽ_i (any positive scale), azimuth and elevation of each step.
    anchors : array_like, shape (M, 3)
        Anchor positions (m, local ENU) at step indices ``anchor_steps``.
    anchor_steps : array_like of int, shape (M,)
        Strictly increasing, from 0 to N.
    dt_s : float, optional
        Step duration (s); needed only with ``current``.
    current : array_like, shape (M-1, 2), optional
        Mean (East, North) current velocity (m/s) over each interval: the swimming
        path is reconstructed with :math:`\Delta X-\Delta T E`, :math:`\Delta Y-\Delta T N`
        and drifted back, :math:`x^g_i=x_i+i\Delta t E` (§8).
    return_water : bool
        With ``current``, return the water-relative path instead of the geographic one.

    Returns
    -------
    ndarray, shape (N+1, 3)
        Positions; row ``anchor_steps[I]`` equals ``anchors[I]`` up to rounding.

    Notes
    -----
    Fallbacks: if :math:`\tilde V=0` over an interval (no movement in the proxy), the
    interval is filled by constant-velocity straight-line interpolation; if L = 0,
    the reconstructed bout collapses on the anchor (scale 0).
    """
    v = velocity_components(*_steps(speed=speed, az=az, el=el))
    n = v.shape[0]
    X, idx = _check_anchors(anchors, anchor_steps, n, 3)
    dX = np.diff(X, axis=0)
    nI = np.diff(idx)
    if current is not None:
        if dt_s is None:
            raise ValueError("dt_s (step duration, s) is required with current")
        dt_s = _v.positive(dt_s, "dt_s")
        cur = _v.vectors(current, "current", width=None, ndim=None)
        if cur.shape != (X.shape[0] - 1, 2):
            raise ValueError(
                f"current must have shape ({X.shape[0] - 1}, 2), got {cur.shape}"
            )
        drift = np.column_stack([cur * (nI * dt_s)[:, None], np.zeros(len(nI))])
        dX = dX - drift
    L = np.linalg.norm(dX, axis=1)
    Th = np.arctan2(dX[:, 1], dX[:, 0])
    Ph = np.arctan2(dX[:, 2], np.hypot(dX[:, 0], dX[:, 1]))
    S = np.add.reduceat(v, idx[:-1], axis=0)
    Vt = np.linalg.norm(S, axis=1)
    Thh = np.arctan2(S[:, 1], S[:, 0])
    Phh = np.arctan2(S[:, 2], np.hypot(S[:, 0], S[:, 1]))
    seg = np.repeat(np.arange(len(nI)), nI)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(Vt > 0, L / np.where(Vt > 0, Vt, 1.0), 0.0)
    ct, st = np.cos(Thh[seg]), np.sin(Thh[seg])
    cd, sd = np.cos(Ph[seg] - Phh[seg]), np.sin(Ph[seg] - Phh[seg])
    cT, sT = np.cos(Th[seg]), np.sin(Th[seg])
    p = v[:, 0] * ct + v[:, 1] * st
    q = v[:, 1] * ct - v[:, 0] * st
    r = p * cd - v[:, 2] * sd
    k = scale[seg]
    inc = np.column_stack(
        [(r * cT - q * sT) * k, (q * cT + r * sT) * k, (v[:, 2] * cd + p * sd) * k]
    )
    still = (Vt == 0)[seg]
    if np.any(still):
        inc[still] = (dX / nI[:, None])[seg[still]]
    if current is not None and not return_water:
        inc = inc + np.column_stack([cur[seg] * dt_s, np.zeros(n)])
    out = np.empty((n + 1, 3))
    out[idx[:-1]] = X[:-1]
    # cumulative sum restarted at each anchor
    cs = np.cumsum(inc, axis=0)
    start = np.concatenate([np.zeros((1, 3)), cs])[idx[:-1]]
    out[1:] = X[:-1][seg] + cs - start[seg]
    return out


def dead_reckon_2d(speed, az, anchors, anchor_steps) -> np.ndarray:
    r"""2-D dead reckoning for collar-mounted loggers, Eq. 19 (trigonometry-free form).

    .. math::
        x_i &= x_{i-1}+\big((\Delta X\Sigma\tilde v_x+\Delta Y\Sigma\tilde v_y)\tilde v_{xi}-(\Delta Y\Sigma\tilde v_x-\Delta X\Sigma\tilde v_y)\tilde v_{yi}\big)/\big((\Sigma\tilde v_x)^2+(\Sigma\tilde v_y)^2\big)\\
        y_i &= y_{i-1}+\big((\Delta X\Sigma\tilde v_x+\Delta Y\Sigma\tilde v_y)\tilde v_{yi}+(\Delta Y\Sigma\tilde v_x-\Delta X\Sigma\tilde v_y)\tilde v_{xi}\big)/\big((\Sigma\tilde v_x)^2+(\Sigma\tilde v_y)^2\big)

    Equal to :func:`dead_reckon` with zero elevations. ``anchors`` shape (M, 2);
    returns (N+1, 2). Same fallback for a null proxy sum.

    Parameters
    ----------
    speed : array_like, shape (N,)
        Speed proxy ṽ_i of each step (any positive scale).
    az : array_like, shape (N,)
        Azimuth θ_i (rad, ccw from East) of each step.
    anchors : array_like, shape (M, 2)
        Anchor positions (East, North; m) at step indices ``anchor_steps``.
    anchor_steps : array_like of int, shape (M,)
        Strictly increasing, from 0 to N.

    Returns
    -------
    ndarray, shape (N+1, 2)
        Positions (m); row ``anchor_steps[I]`` equals ``anchors[I]`` up to rounding.
    """
    v = velocity_components(*_steps(speed=speed, az=az))[:, :2]
    n = v.shape[0]
    X, idx = _check_anchors(anchors, anchor_steps, n, 2)
    dX = np.diff(X, axis=0)
    nI = np.diff(idx)
    S = np.add.reduceat(v, idx[:-1], axis=0)
    den = (S**2).sum(axis=1)
    seg = np.repeat(np.arange(len(nI)), nI)
    c = dX[:, 0] * S[:, 0] + dX[:, 1] * S[:, 1]
    s = dX[:, 1] * S[:, 0] - dX[:, 0] * S[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(den > 0, c / np.where(den > 0, den, 1.0), 0.0)
        s = np.where(den > 0, s / np.where(den > 0, den, 1.0), 0.0)
    inc = np.column_stack(
        [c[seg] * v[:, 0] - s[seg] * v[:, 1], c[seg] * v[:, 1] + s[seg] * v[:, 0]]
    )
    still = (den == 0)[seg]
    if np.any(still):
        inc[still] = (dX / nI[:, None])[seg[still]]
    cs = np.cumsum(inc, axis=0)
    start = np.concatenate([np.zeros((1, 2)), cs])[idx[:-1]]
    out = np.empty((n + 1, 2))
    out[0] = X[0]
    out[1:] = X[:-1][seg] + cs - start[seg]
    return out


def anchored_errors(truth, speed, az, el, intervals) -> tuple[np.ndarray, np.ndarray]:
    """Mean and max position error of :func:`dead_reckon` against true positions, for several anchor intervals.

    ``truth`` (N+1, 3) gives both the anchors (every ``interval`` steps, plus the
    last position) and the reference; ``speed``, ``az``, ``el`` are the (noisy)
    per-step inputs. Returns two arrays (mean, max) with one value per interval (m).

    Parameters
    ----------
    truth : array_like, shape (N+1, 3)
        True positions (m, local ENU).
    speed, az, el : array_like, shape (N,)
        Speed proxy and azimuth and elevation (rad) of each step.
    intervals : iterable of int
        Anchor spacings (number of steps, ≥ 1) to evaluate.

    Returns
    -------
    mean : ndarray, shape (len(intervals),)
        Mean position error (m) for each interval.
    max : ndarray, shape (len(intervals),)
        Maximum position error (m) for each interval.
    """
    truth = _vec3(truth, "truth")
    n = truth.shape[0] - 1
    means, maxs = [], []
    for every in intervals:  # one vectorised reconstruction per interval
        every = _v.integer(every, "intervals", minimum=1)
        idx = np.unique(np.r_[np.arange(0, n, every), n])
        e = np.linalg.norm(dead_reckon(speed, az, el, truth[idx], idx) - truth, axis=1)
        means.append(e.mean())
        maxs.append(e.max())
    return np.array(means), np.array(maxs)
