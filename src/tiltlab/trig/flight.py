r"""Flight behaviour from heave oscillations and elevation (Benhamou 2023, §9).

Benhamou reports thresholds for kestrels on two read-outs per time window: the
coefficient of variation (CV) of the delays between successive crossings of the heave
acceleration through its balance level, with the period :math:`T = 2\bar d`
(:func:`tiltlab.trig.oscillation_stats`), and the elevation angle :math:`\phi`. Kestrels
"could be said to hover (CV<0.5, T<150 ms), perform flapped (φ≈0, CV<0.5,
T∈[150, 220] ms) or glided (φ≈0, CV>0.5) fly, or to be perched (φ≫0, CV>0.5)" [1]_
(§9, attributed there to unpublished results of D. García Silveira). Per window:

=========  ===========================================  ==========================
class      rule                                          parameters (defaults)
=========  ===========================================  ==========================
hover      CV < c and T < T_h                            c = 0.5, T_h = 0.150 s
flap       |φ| ≤ φ_tol, CV < c, T_f1 ≤ T ≤ T_f2          T_f = (0.150, 0.220) s
glide      |φ| ≤ φ_tol, CV > c
perched    φ > φ_tol, CV > c
none       anything else (incl. no statistic)
=========  ===========================================  ==========================

The paper gives no number for "φ ≈ 0" and "φ ≫ 0"; one tolerance φ_tol separates
them here. Its default, 20°, is a round value above the error of a window-mean
elevation from the static acceleration (a few degrees once the window spans several
wing beats; chapter 7 measures it against optical ground truth) and below the steep
body axis of an upright perched posture; it is a parameter, to be set from data of the
species. The rules are the paper's, so classes are exclusive (hover and flap split at
T_h = T_f1); windows matching none are ``"none"``.

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023, §9. doi:10.48550/arXiv.2310.05820
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

import tiltlab._validate as _v
from ..dsp import window_samples
from ._common import read_input
from .oscillations import oscillation_stats

__all__ = ["FLIGHT_CLASSES", "classify_flight", "flight_time_budget"]

#: the behaviour classes, in the order of the table above
FLIGHT_CLASSES = ("hover", "flap", "glide", "perched", "none")


def _window_mean(x: np.ndarray, k: int, nb: int) -> np.ndarray:
    v = x[: nb * k].reshape(nb, k)
    with np.errstate(invalid="ignore"):
        n = np.isfinite(v).sum(axis=1)
        s = np.where(np.isfinite(v), v, 0.0).sum(axis=1)
        return np.where(n > 0, s / np.maximum(n, 1), np.nan)


def classify_flight(
    heave,
    elevation,
    fs: float | None = None,
    *,
    level: float,
    window_s: float,
    cv_max: float = 0.5,
    hover_max_s: float = 0.150,
    flap_range_s=(0.150, 0.220),
    level_tol_deg: float = 20.0,
    smooth_s: float | None = None,
) -> xr.Dataset:
    """Classify windows as hover, flap, glide or perched with Benhamou's thresholds.

    See the module notes for the rules and the defaults' sources.

    Parameters
    ----------
    heave : xarray.DataArray or array_like (N,)
        Heave specific force (tiltlab sign: +1 g at rest, level).
    elevation : xarray.DataArray or array_like (N,)
        Elevation angle φ per sample (rad), e.g. ``trig.posture(...).elevation``; its
        window means are compared with ``level_tol_deg``.
    fs : float, optional
        Sampling rate (Hz) of plain arrays (a DataArray carries it).
    level : float
        Balance level of ``heave`` in its units (1 g; Benhamou's −g in his sign).
    window_s : float
        Window duration Δt (s).
    cv_max : float
        CV threshold c (paper: 0.5).
    hover_max_s : float
        Longest hovering period T_h (s; paper: 150 ms).
    flap_range_s : (float, float)
        Range of flapping periods (s; paper: 150–220 ms).
    level_tol_deg : float
        Largest |φ| (°) counted as "φ ≈ 0"; φ above it is "φ ≫ 0" (not in the paper:
        default 20°, see the module notes).
    smooth_s : float, optional
        Moving average before the crossings (:func:`oscillation_stats`).

    Returns
    -------
    xarray.Dataset
        Over the window centres ``time`` (s): ``cv``, ``period`` (s), ``elevation``
        (window mean, rad) and ``behavior`` (one of :data:`FLIGHT_CLASSES`); attrs
        ``window_s`` and the thresholds.

    Raises
    ------
    ValueError
        When ``heave`` and ``elevation`` differ in length, or a threshold is out of its
        domain (``cv_max`` ≤ 0, decreasing ``flap_range_s``, ``level_tol_deg`` not in
        [0, 90)).

    Examples
    --------
    >>> from tiltlab import simulate, trig
    >>> heave = simulate.simulate_heave(10.0, 100.0, period_s=0.18, rng=0)
    >>> c = trig.classify_flight(heave, 0.0 * heave, level=1.0, window_s=1.0)
    >>> c.behavior.values[[0, -1]].tolist()
    ['flap', 'glide']
    """
    cv_max = _v.positive(cv_max, "cv_max")
    hover_max_s = _v.positive(hover_max_s, "hover_max_s")
    f_lo, f_hi = (_v.positive(v, "flap_range_s") for v in flap_range_s)
    if not f_lo <= f_hi:
        raise ValueError(f"flap_range_s must be increasing, got {flap_range_s!r}")
    level_tol_deg = _v.nonnegative(level_tol_deg, "level_tol_deg")
    if not level_tol_deg < 90:
        raise ValueError(f"level_tol_deg must be in [0, 90), got {level_tol_deg!r}")
    h = read_input(heave, "heave", fs=fs, need_fs=True, width=None, ndim=1)
    e = read_input(elevation, "elevation", fs=h.fs, width=None, ndim=1)
    if e.values.shape != h.values.shape:
        raise ValueError(
            f"elevation must have one value per heave sample ({h.values.shape[0]}), "
            f"got {e.values.shape[0]}"
        )
    osc = oscillation_stats(
        h.values, h.fs, level=level, window_s=window_s, smooth_s=smooth_s
    )
    k = window_samples(window_s, h.fs)
    nb = osc.cv.shape[0]
    phi = _window_mean(np.asarray(e.values, float), k, nb)
    cv, per = np.asarray(osc.cv), np.asarray(osc.period)
    tol = np.radians(level_tol_deg)
    with np.errstate(invalid="ignore"):
        flat = np.abs(phi) <= tol
        regular, irregular = cv < cv_max, cv > cv_max
        rules = [
            regular & (per < hover_max_s),
            flat & regular & (per >= f_lo) & (per <= f_hi),
            flat & irregular,
            (phi > tol) & irregular,
        ]
    beh = np.select(rules, list(FLIGHT_CLASSES[:4]), default="none")
    t0 = float(h.time[0]) if h.time is not None else 0.0
    t = xr.DataArray(
        t0 + np.asarray(osc.time),
        dims="time",
        attrs={"units": "s", "long_name": "time"},
    )

    def var(v, units, name):
        return ("time", v, {"units": units, "long_name": name})

    return xr.Dataset(
        {
            "cv": var(cv, "1", "CV of the crossing delays"),
            "period": var(per, "s", "period T = 2 d̄"),
            "elevation": var(phi, "rad", "window-mean elevation φ"),
            "behavior": var(beh, "", "flight behaviour (Benhamou 2023 §9)"),
        },
        coords={"time": t},
        attrs={
            "window_s": k / h.fs,
            "fs": h.fs / k,
            "cv_max": cv_max,
            "hover_max_s": hover_max_s,
            "flap_range_s": (f_lo, f_hi),
            "level_tol_deg": level_tol_deg,
        },
    )


def flight_time_budget(classes: xr.Dataset) -> pd.DataFrame:
    """Tabulate the time spent in each flight class.

    Parameters
    ----------
    classes : xarray.Dataset
        From :func:`classify_flight`.

    Returns
    -------
    pandas.DataFrame
        Index :data:`FLIGHT_CLASSES`; columns ``windows``, ``duration (s)`` and
        ``fraction``, with ``units`` and ``long_name`` in ``attrs``.

    Examples
    --------
    >>> from tiltlab import simulate, trig
    >>> heave = simulate.simulate_heave(10.0, 100.0, period_s=0.18, rng=0)
    >>> c = trig.classify_flight(heave, 0.0 * heave, level=1.0, window_s=1.0)
    >>> float(trig.flight_time_budget(c)["duration (s)"].sum())
    10.0
    """
    if not isinstance(classes, xr.Dataset) or "behavior" not in classes:
        raise ValueError("classes must be the Dataset returned by classify_flight")
    lab = pd.Series(np.asarray(classes.behavior.values, str))
    n = lab.value_counts().reindex(list(FLIGHT_CLASSES), fill_value=0)
    w = float(classes.attrs["window_s"])
    tab = pd.DataFrame(
        {"windows": n, "duration (s)": n * w, "fraction": n / max(int(n.sum()), 1)}
    )
    tab.index.name = "behavior"
    tab.attrs = {
        "units": {"windows": "1", "duration (s)": "s", "fraction": "1"},
        "long_name": "time budget of the flight classes (Benhamou 2023 §9)",
    }
    return tab
