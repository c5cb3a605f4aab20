r"""Residence time and number of visits on the sphere (Benhamou 2023, App. C).

For a centre :math:`\mu` and an angular radius :math:`r` the trajectory enters and leaves
the cap :math:`\{x: \mu\cdot x \ge \cos r\}`. Each passage time is interpolated along the
orthodromic arc between the inside sample :math:`I` and the outside sample :math:`O`:
writing the arc from :math:`I` as :math:`p(\theta)=I\cos\theta+\tau\sin\theta` (τ the
unit tangent at I toward O), :math:`\mu\cdot p(\theta)=\cos r` reads
:math:`a\cos\theta+b\sin\theta=\cos r` with :math:`a=\mu\cdot I`, :math:`b=\mu\cdot\tau`,
whose root on the arc is

.. math::
    \omega_{IP} = \operatorname{atan2}(b, a) + \arccos\frac{\cos r}{\sqrt{a^2+b^2}},
    \qquad t_P = t_I + (t_O-t_I)\,\frac{\omega_{IP}}{\omega_{IO}},

Benhamou's App. C formula written with vectors (``tiltlab.trig.cap_passage`` is the
longitude/latitude form; the tests check they agree).

Successive inside intervals separated by an excursion no longer than :math:`T_{out}`
belong to the same *visit*. The **number of visits** NV is the number of such groups
over the whole series; the **residence time** of a visit is the time spent inside the
cap during it (excursions excluded). For the location of sample :math:`i` itself
(App. C), RT(i) is the residence time of the visit that contains :math:`t_i`
(:math:`F_1-B_1` plus the re-entries forward and backward while the time outside stays
≤ :math:`T_{out}`) and NV(i) = 1 + NF(i) + NB(i).

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023, §7 and App. C. doi:10.48550/arXiv.2310.05820
.. [2] F. Barraquand, S. Benhamou, "Animal movements in heterogeneous landscapes:
   identifying profitable places and homogeneous movement bouts", Ecology 89:3336–3348,
   2008. doi:10.1890/08-0162.1
.. [3] S. Benhamou, J. Riotte-Lambert, "Beyond the utilization distribution: identifying
   home range areas that are intensively exploited or repeatedly visited", Ecol. Model.
   227:112–116, 2012. doi:10.1016/j.ecolmodel.2011.12.015
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange

from .. import _validate
from .mesh import _series, as_unit_vectors

__all__ = ["Residence", "passage_times", "residence", "residence_series"]


class Residence(NamedTuple):
    """Residence per centre: time inside, visits, mean and current residence.

    ``total`` time inside the cap (s), ``n_visits``, ``mean_residence`` (total /
    n_visits, NaN when never visited) and ``residence`` (residence time of the visit
    containing the reference time; NaN when none given or not inside then).
    """

    total: np.ndarray
    n_visits: np.ndarray
    mean_residence: np.ndarray
    residence: np.ndarray


@njit(cache=True, inline="always")
def _crossing(x, t, i_in, i_out, c0, c1, c2, cos_r):
    """Passage time on the arc from inside sample i_in to outside sample i_out."""
    I0, I1, I2 = x[i_in, 0], x[i_in, 1], x[i_in, 2]
    O0, O1, O2 = x[i_out, 0], x[i_out, 1], x[i_out, 2]
    d = I0 * O0 + I1 * O1 + I2 * O2
    u0, u1, u2 = O0 - d * I0, O1 - d * I1, O2 - d * I2
    un = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    w = np.arctan2(un, d)
    if un <= 0.0 or w <= 0.0:
        return t[i_in]
    a = c0 * I0 + c1 * I1 + c2 * I2
    b = (c0 * u0 + c1 * u1 + c2 * u2) / un
    rr = np.sqrt(a * a + b * b)
    q = cos_r / rr
    q = min(max(q, -1.0), 1.0)
    th = np.arctan2(b, a) + np.arccos(q)
    th = min(max(th, 0.0), w)
    return t[i_in] + (t[i_out] - t[i_in]) * th / w


@njit(cache=True, parallel=True)
def _residence_kernel(x, t, centres, cos_r, t_out, tref, total, nvis, rt):
    n = x.shape[0]
    for m in prange(centres.shape[0]):
        c0, c1, c2 = centres[m, 0], centres[m, 1], centres[m, 2]
        ref = tref[m]
        tot = 0.0
        nv = 0
        clus = 0.0
        clus_start = 0.0
        last_exit = -np.inf
        enter = 0.0
        res = np.nan
        prev_in = (x[0, 0] * c0 + x[0, 1] * c1 + x[0, 2] * c2) >= cos_r
        if prev_in:
            nv = 1
            clus_start = t[0]
            enter = t[0]
        for k in range(1, n + 1):
            if k < n:
                now_in = (x[k, 0] * c0 + x[k, 1] * c1 + x[k, 2] * c2) >= cos_r
            else:
                now_in = False
            if now_in == prev_in:
                continue
            if now_in:  # entry between k-1 (out) and k (in)
                tc = _crossing(x, t, k, k - 1, c0, c1, c2, cos_r)
                if nv == 0 or tc - last_exit > t_out:
                    if nv > 0 and clus_start <= ref <= last_exit:
                        res = clus
                    nv += 1
                    clus = 0.0
                    clus_start = tc
                enter = tc
            else:  # exit between k-1 (in) and k (out), or end of the series
                tc = (
                    t[n - 1] if k == n else _crossing(x, t, k - 1, k, c0, c1, c2, cos_r)
                )
                tot += tc - enter
                clus += tc - enter
                last_exit = tc
            prev_in = now_in
        if nv > 0 and clus_start <= ref <= last_exit:
            res = clus
        total[m] = tot
        nvis[m] = nv
        rt[m] = res


def _check(radius, t_out) -> tuple[float, float]:
    radius = _validate.finite(radius, "radius")
    if not 0 < radius < np.pi / 2:
        raise ValueError(f"radius must be in (0, π/2) rad, got {radius!r}")
    t_out = _validate.positive(t_out, "t_out", allow_zero=True, allow_inf=True)
    return radius, t_out


def residence(
    vectors,
    centres,
    radius: float,
    t_out: float,
    *,
    fs: float | None = None,
    times=None,
    ref_times=None,
) -> Residence:
    """Measure time inside, visits and mean residence per visit in caps around ``centres``.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Time-ordered directions: a labelled (time, axis) series with ``attrs["fs"]``
        (e.g. :func:`tiltlab.filters.gravity`), a Recording with a ``gravity`` variable,
        or a plain array with ``fs`` or ``times``.
    centres : array_like, shape (M, 3)
        Cap centres (e.g. a grid's or a mesh's vertices, for maps).
    radius : float
        Angular radius of the caps (rad), in (0, π/2).
    t_out : float
        Excursions outside a cap no longer than this (s) do not end a visit.
    fs, times : float or array_like (N,), optional
        Sampling rate (Hz) or sample times (s) of a plain array. Labelled data use
        their ``time`` coordinate (else ``i / fs``); an ``fs`` contradicting
        ``attrs["fs"]`` is an error.
    ref_times : array_like (M,), optional
        A time per centre (on the data's clock); ``residence`` is then the residence time
        of the visit containing it (NaN where a time is NaN).

    Returns
    -------
    Residence
        Per centre: ``total`` time inside (s), ``n_visits``, ``mean_residence`` (s) and
        ``residence`` at ``ref_times``.
    """
    radius, t_out = _check(radius, t_out)
    x, t, _ = _series(vectors, fs, times)
    c = as_unit_vectors(centres, "centres")
    ref = (
        np.full(c.shape[0], np.nan)
        if ref_times is None
        else _validate.vectors(
            ref_times, "ref_times", width=None, ndim=1, allow_nan=True
        )
    )
    if ref.shape != (c.shape[0],):
        raise ValueError(
            f"ref_times must have shape ({c.shape[0]},) (one per centre), got {ref.shape}"
        )
    total, rt = np.empty(c.shape[0]), np.empty(c.shape[0])
    nv = np.empty(c.shape[0], np.int64)
    _residence_kernel(x, t, c, float(np.cos(radius)), float(t_out), ref, total, nv, rt)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(nv > 0, total / np.maximum(nv, 1), np.nan)
    return Residence(total, nv, mean, rt)


def residence_series(
    vectors,
    radius: float,
    t_out: float,
    *,
    fs: float | None = None,
    times=None,
    stride: int = 1,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """App. C at the recorded locations: RT(i) and NV(i) for every ``stride``-th sample.

    ``vectors``, ``fs`` and ``times`` as in :func:`residence`. Returns ``(index, RT, NV)``.
    Cost O(N²/stride).

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Time-ordered directions (see :func:`residence`).
    radius : float
        Angular radius of the caps (rad), in (0, π/2).
    t_out : float
        Excursions outside a cap no longer than this (s) do not end a visit.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    times : array_like, shape (N,), optional
        Sample times (s) of a plain array.
    stride : int
        Evaluate every ``stride``-th sample (≥ 1).

    Returns
    -------
    index : ndarray of int, shape (ceil(N/stride),)
        Sample indices evaluated.
    residence : ndarray
        Residence time RT(i) (s) of the visit containing each sample.
    n_visits : ndarray
        Number of visits NV(i) to the cap around each sample.
    """
    radius, t_out = _check(radius, t_out)
    stride = _validate.integer(stride, "stride", minimum=1)
    x, t, _ = _series(vectors, fs, times)
    idx = np.arange(0, x.shape[0], stride)
    r = residence(x, x[idx], radius, t_out, times=t, ref_times=t[idx])
    return idx, r.residence, r.n_visits


def passage_times(
    vectors, centre, radius: float, *, fs: float | None = None, times=None
) -> tuple[np.ndarray, np.ndarray]:
    """Entry and exit times (s) of the trajectory through the cap of angular ``radius`` around ``centre``.

    ``vectors``, ``fs`` and ``times`` as in :func:`residence`; times are on the data's
    clock (its ``time`` coordinate when labelled). Interpolated along the arcs (App. C).
    A series that starts (ends) inside enters at its first (leaves at its last) sample time.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Time-ordered directions (see :func:`residence`).
    centre : array_like, shape (3,)
        Cap centre (normalised here).
    radius : float
        Angular radius of the cap (rad), in (0, π/2).
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    times : array_like, shape (N,), optional
        Sample times (s) of a plain array.

    Returns
    -------
    enters : ndarray
        Entry times (s).
    exits : ndarray
        Exit times (s).
    """
    radius, _ = _check(radius, 0.0)
    x, t, _ = _series(vectors, fs, times)
    if np.shape(centre) != (3,):
        raise ValueError(f"centre must be one 3-vector, got shape {np.shape(centre)}")
    c = as_unit_vectors(centre, "centre")[0]
    inside = x @ c >= np.cos(radius)
    change = np.flatnonzero(np.diff(inside.astype(np.int8)))
    cos_r = float(np.cos(radius))
    enters, exits = [], []
    if inside[0]:
        enters.append(t[0])
    for k in change:  # loop over crossings only (few), not samples
        if inside[k + 1]:
            enters.append(_crossing(x, t, k + 1, k, c[0], c[1], c[2], cos_r))
        else:
            exits.append(_crossing(x, t, k, k + 1, c[0], c[1], c[2], cos_r))
    if inside[-1]:
        exits.append(t[-1])
    return np.asarray(enters), np.asarray(exits)
