r"""Motion-capture marker gaps: find them and fill the short ones by quadratic interpolation.

Fayat et al. 2021 [1]_ §2.6.3 fill "occasional gaps (i.e., missing marker coordinates
for one or two frames) ... using quadratic interpolation"; longer gaps stay missing.
The paper does not say which frames the quadratic goes through; here it is fixed as
follows.

A *gap* of one marker is a maximal run of frames :math:`s, \dots, e - 1` where the
marker is missing (any coordinate NaN). It is filled when

* it is at most ``max_gap`` frames long (:math:`e - s \le` ``max_gap``);
* it is interior: a valid frame precedes it (:math:`s - 1`) and one follows it
  (:math:`e`) — an interpolation never extrapolates past the ends of a recording;
* at least three of the *support frames* :math:`S = \{s - 2, s - 1, e, e + 1\}`
  (the two nearest frames on each side) exist and hold the marker (frames
  :math:`s - 1` and :math:`e` always do, so one of :math:`s - 2`, :math:`e + 1` is
  enough).

Each coordinate is then fitted, by least squares over the support frames, with

.. math::

    p(n) = c_0 + c_1 (n - \bar n) + c_2 (n - \bar n)^2, \qquad
    \hat c = \arg\min_c \sum_{k \in S} \big(p(k) - x_k\big)^2,

where :math:`n` is the frame index and :math:`\bar n = (s - 1 + e)/2` the centre of
the gap, and the missing frames get :math:`p(s), \dots, p(e - 1)`. With three support
frames this is the quadratic through them; with four it is the least-squares parabola,
symmetric about the gap. Either way a trajectory that is itself a quadratic in time is
filled exactly. Support frames are taken from the recorded data only, never from values
filled in a neighbouring gap, so the result does not depend on the order of the gaps.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import pandas as pd
import xarray as xr

__all__ = ["MarkerGapFill", "fill_marker_gaps", "marker_gaps"]


class MarkerGapFill(NamedTuple):
    """Result of :func:`fill_marker_gaps`.

    ``markers``: a filled copy of the input (same type, shape and dims); ``filled``:
    bool, the marker-frames that were filled; ``missing``: bool, those still missing.
    Both masks have the input's shape without its coordinate axis.
    """

    markers: Any
    filled: Any
    missing: Any


def _as_points(markers, dim: str):
    """Return (values (N, P, C), frame labels, rebuild function) for any input."""
    if isinstance(markers, xr.DataArray):
        if dim not in markers.dims:
            raise ValueError(
                f"markers: has no dimension {dim!r} (dims {markers.dims}); pass dim"
            )
        coord_dim = "axis" if "axis" in markers.dims and dim != "axis" else None
        order = [dim, *(d for d in markers.dims if d not in (dim, coord_dim))]
        order += [coord_dim] if coord_dim else []
        da = markers.transpose(*order)
        vals = np.asarray(da.values, dtype=np.float64)
        n = vals.shape[0]
        flat = vals.reshape(n, -1, vals.shape[-1] if coord_dim else 1)
        mask_dims = order[:-1] if coord_dim else order

        def rebuild(x, filled, missing):
            out = da.copy(data=x.reshape(vals.shape)).transpose(*markers.dims)
            masks = [
                xr.DataArray(
                    m.reshape(vals.shape[: len(mask_dims)]),
                    dims=mask_dims,
                    coords={d: da.coords[d] for d in mask_dims if d in da.coords},
                    attrs={"long_name": name, "units": "1"},
                ).transpose(*(d for d in markers.dims if d in mask_dims))
                for m, name in ((filled, "gap filled"), (missing, "still missing"))
            ]
            return MarkerGapFill(out, *masks)

        labels = np.asarray(da[dim].values) if dim in da.coords else np.arange(n)
        middle = order[1:-1] if coord_dim else order[1:]
        names = (
            [str(v) for v in da[middle[0]].values]
            if len(middle) == 1 and middle[0] in da.coords
            else None
        )
        return flat, labels, names, rebuild
    try:
        vals = np.array(markers, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(
            f"markers must be numeric (frames first), got {type(markers).__name__}"
        ) from None
    if vals.ndim == 0:
        raise ValueError("markers must have a frame axis first, got a scalar")
    shape = vals.shape
    n = shape[0]
    flat = vals.reshape(n, -1, shape[-1] if vals.ndim >= 2 else 1)

    def rebuild(x, filled, missing):
        mshape = shape[:-1] if vals.ndim >= 2 else shape
        return MarkerGapFill(
            x.reshape(shape), filled.reshape(mshape), missing.reshape(mshape)
        )

    return flat, np.arange(n), None, rebuild


def _check_max_gap(max_gap) -> int:
    if isinstance(max_gap, (bool, np.bool_)) or not isinstance(
        max_gap, (int, np.integer)
    ):
        raise ValueError(f"max_gap must be a whole number of frames, got {max_gap!r}")
    if max_gap < 0:
        raise ValueError(f"max_gap must be >= 0 frames, got {max_gap}")
    return int(max_gap)


def _runs(missing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Start and stop (exclusive) frame indices of the runs of True in a 1-D mask."""
    edges = np.diff(np.concatenate(([0], missing.astype(np.int8), [0])))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def _support(missing: np.ndarray, s: int, e: int, max_gap: int) -> np.ndarray | None:
    """Support frames of the gap [s, e), or None when the gap is not filled."""
    n = missing.size
    if e - s > max_gap or s == 0 or e == n:
        return None
    cand = np.array([s - 2, s - 1, e, e + 1])
    cand = cand[(cand >= 0) & (cand < n)]
    cand = cand[~missing[cand]]
    return cand if cand.size >= 3 else None


def fill_marker_gaps(markers, max_gap: int = 2, *, dim: str = "frame") -> MarkerGapFill:
    r"""Fill marker gaps of at most ``max_gap`` frames by quadratic interpolation.

    Fayat et al. 2021 §2.6.3 fill gaps of one or two frames this way and leave longer
    ones missing. Each gap is filled by the least-squares quadratic in the frame index
    through its support frames :math:`\{s-2, s-1, e, e+1\}` (those that hold the
    marker; at least three) — see the module notes for the rule and the equation.
    Gaps at the start or end of the recording stay missing (no extrapolation). The
    input is not modified.

    Parameters
    ----------
    markers : xarray.DataArray or array_like
        Marker positions with the frames first: a DataArray with dimension ``dim``
        (the coordinates along ``axis`` when it has one, e.g. the ``markers``
        variable of :func:`tiltlab.io.read_c3d` or :func:`tiltlab.simulate.mocap_markers`),
        or an array of shape (N,), (N, 3) or (N, M, 3) whose last axis (when there
        are two or more) holds a point's coordinates. NaN marks a missing marker; a
        marker-frame with any coordinate NaN counts as missing. Frames are assumed
        evenly spaced.
    max_gap : int
        Longest gap filled, in frames (default 2, as in Fayat et al.; 0 fills
        nothing).
    dim : str
        The frame dimension of a DataArray (default ``"frame"``).

    Returns
    -------
    MarkerGapFill
        ``markers`` (a filled copy, same type and dims as the input, attrs kept),
        ``filled`` and ``missing`` (bool masks over frames × markers: filled here,
        still missing).

    Raises
    ------
    ValueError
        ``markers`` not numeric or without the frame dimension; ``max_gap`` not a
        whole number ≥ 0.

    Examples
    --------
    A marker moving along a parabola, missing for two frames:

    >>> import numpy as np
    >>> x = (np.arange(8.0) ** 2)[:, None] * [1.0, 0.0, 0.0]
    >>> x[3:5] = np.nan
    >>> res = fill_marker_gaps(x)
    >>> res.markers[3:5, 0], res.filled.sum()
    (array([ 9., 16.]), np.int64(2))
    """
    max_gap = _check_max_gap(max_gap)
    flat, _, _, rebuild = _as_points(markers, dim)
    out = flat.copy()
    missing = np.isnan(flat).any(axis=-1)
    filled = np.zeros_like(missing)
    for p in range(flat.shape[1]):
        col = missing[:, p]
        for s, e in zip(*_runs(col)):
            sup = _support(col, int(s), int(e), max_gap)
            if sup is None:
                continue
            centre = (s - 1 + e) / 2.0
            tau = sup - centre
            design = np.stack([np.ones_like(tau), tau, tau**2], axis=1)
            coef = np.linalg.lstsq(design, flat[sup, p, :], rcond=None)[0]
            t_gap = np.arange(s, e) - centre
            out[s:e, p, :] = np.stack([np.ones_like(t_gap), t_gap, t_gap**2], 1) @ coef
            filled[s:e, p] = True
    return rebuild(out, filled, missing & ~filled)


def marker_gaps(markers, max_gap: int = 2, *, dim: str = "frame") -> pd.DataFrame:
    """List the gaps of each marker, and whether :func:`fill_marker_gaps` fills them.

    Parameters
    ----------
    markers : xarray.DataArray or array_like
        Marker positions, frames first, as :func:`fill_marker_gaps` takes them.
    max_gap : int
        Longest gap that counts as fillable, in frames (default 2).
    dim : str
        The frame dimension of a DataArray (default ``"frame"``).

    Returns
    -------
    pandas.DataFrame
        One row per gap: ``marker`` (its label, or column number), ``first_frame``
        (the frame label of the gap's first frame: the ``dim`` coordinate, else the
        index), ``length`` (frames), ``filled`` (bool). Column units and long names
        are in ``attrs``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.zeros((10, 3))
    >>> x[2] = np.nan
    >>> x[5:8] = np.nan
    >>> marker_gaps(x)[["first_frame", "length", "filled"]].values.tolist()
    [[2, 1, True], [5, 3, False]]
    """
    max_gap = _check_max_gap(max_gap)
    flat, labels, names, _ = _as_points(markers, dim)
    missing = np.isnan(flat).any(axis=-1)
    rows = []
    for p in range(flat.shape[1]):
        for s, e in zip(*_runs(missing[:, p])):
            rows.append(
                {
                    "marker": names[p] if names else p,
                    "first_frame": labels[s].item(),
                    "length": int(e - s),
                    "filled": _support(missing[:, p], int(s), int(e), max_gap)
                    is not None,
                }
            )
    df = pd.DataFrame(rows, columns=["marker", "first_frame", "length", "filled"])
    df.attrs = {
        "title": "marker gaps",
        "units": {
            "marker": "",
            "first_frame": "frame",
            "length": "frames",
            "filled": "1",
        },
        "long_name": {
            "marker": "marker",
            "first_frame": "first missing frame",
            "length": "gap length",
            "filled": f"filled (gap of at most {max_gap} frames, interior, 3 support frames)",
        },
    }
    return df
