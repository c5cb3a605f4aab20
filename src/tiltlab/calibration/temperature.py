r"""Temperature dependence of sensor offsets.

Fayat et al. (2021) [1]_ (Fig. 1d) found accelerometer and gyroscope offsets sensitive
to sensor temperature and described the dependence with cubic polynomial regressions.
:func:`fit_temperature_model` fits, per axis, :math:`o_i(T) = \sum_k c_{ik} (T - T_0)^k`
(centred on :math:`T_0`, the mean calibration temperature, for conditioning) and
:func:`compensate_temperature` subtracts :math:`o(T_t)` sample by sample.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from .. import _validate as _v
from .. import units as _units
from ._util import CalibrationError, read_temp_degc, vec3, window_count

__all__ = [
    "TemperatureModel",
    "fit_temperature_model",
    "compensate_temperature",
    "offsets_vs_temperature",
]


@dataclass(frozen=True)
class TemperatureModel:
    r"""Per-axis polynomial offsets :math:`o_i(T) = \sum_k c_{ik}(T - T_0)^k`.

    Attributes
    ----------
    coef : tuple of 3 tuples
        Coefficients per axis, highest power first (numpy ``polyval`` order).
    t0 : float
        Centring temperature (°C).
    t_range : tuple (min, max)
        Temperatures covered by the fit; :meth:`__call__` refuses to extrapolate beyond
        ``extrapolate_degc`` °C outside it.
    units : str
        Units of the offsets (``"g"`` or ``"deg/s"``).
    """

    coef: tuple
    t0: float
    t_range: tuple
    units: str

    def __call__(self, temp, *, extrapolate_degc: float = 2.0) -> np.ndarray:
        """Offsets (N, 3) at temperatures ``temp`` (°C; or a labelled ``temp`` in K).

        Temperatures more than ``extrapolate_degc`` (°C) outside the calibrated range
        raise :class:`CalibrationError`.
        """
        if isinstance(temp, xr.DataArray):
            t = read_temp_degc(temp)
        else:
            t = np.asarray(temp, dtype=float)
            if not np.all(np.isfinite(t)):
                raise ValueError("temp contains NaN or infinite values")
        extrapolate_degc = _v.nonnegative(extrapolate_degc, "extrapolate_degc")
        lo, hi = self.t_range
        if t.size and (
            t.min() < lo - extrapolate_degc or t.max() > hi + extrapolate_degc
        ):
            raise CalibrationError(
                f"temperatures {t.min():.2f}…{t.max():.2f} °C lie outside the calibrated "
                f"range {lo:.2f}…{hi:.2f} °C (± extrapolate_degc = {extrapolate_degc} °C)"
            )
        x = t - self.t0
        return np.stack([np.polyval(np.asarray(c), x) for c in self.coef], axis=-1)

    def to_dict(self) -> dict:
        """Return the model as a JSON-serialisable dict."""
        return {
            "coef": [list(map(float, c)) for c in self.coef],
            "t0": float(self.t0),
            "t_range": [float(v) for v in self.t_range],
            "units": self.units,
        }

    @classmethod
    def from_dict(cls, d: dict) -> "TemperatureModel":
        """Rebuild a model from :meth:`to_dict` output."""
        return cls(
            tuple(tuple(c) for c in d["coef"]),
            float(d["t0"]),
            tuple(d["t_range"]),
            str(d["units"]),
        )


def fit_temperature_model(
    temp, offsets, *, degree: int = 3, units: str = "g"
) -> TemperatureModel:
    """Fit per-axis polynomial offsets against temperature (cubic by default, Fayat Fig. 1d).

    Parameters
    ----------
    temp : array_like (K,)
        Sensor temperatures (°C) of K calibrations.
    offsets : array_like (K, 3)
        Offsets measured at those temperatures.
    degree : int
        Polynomial degree; needs at least ``degree + 2`` calibrations at distinct
        temperatures (one spare degree of freedom).
    units : str
        Units of the offsets.

    Returns
    -------
    TemperatureModel
        Per-axis polynomial coefficients, reference temperature and fitted range.
    """
    o = vec3(offsets, "offsets", ndim=2)
    t = read_temp_degc(temp, o.shape[0])
    degree = _v.integer(degree, "degree", minimum=0)
    units = _units.normalise_unit(units)
    if np.unique(np.round(t, 6)).size < degree + 2:
        raise CalibrationError(
            f"a degree-{degree} temperature model needs calibrations at >= {degree + 2} distinct "
            f"temperatures, got {np.unique(np.round(t, 6)).size}"
        )
    t0 = float(t.mean())
    coef = tuple(tuple(np.polyfit(t - t0, o[:, i], degree)) for i in range(3))
    return TemperatureModel(coef, t0, (float(t.min()), float(t.max())), units)


def compensate_temperature(x, temp, model: TemperatureModel):
    """Subtract temperature-dependent offsets: ``x - model(temp)`` (new array).

    Parameters
    ----------
    x : DataArray or array_like (N, 3)
        Readings; labelled input in any units convertible from the model's (the offsets
        are converted), a plain array in the model's units.
    temp : DataArray or array_like (N,)
        Sensor temperature (°C; or a labelled one in K).
    model : TemperatureModel
        Offsets versus temperature (:func:`fit_temperature_model`).

    Returns
    -------
    ndarray or DataArray (N, 3)
    """
    if not isinstance(model, TemperatureModel):
        raise TypeError(f"model must be a TemperatureModel, got {type(model).__name__}")
    s = _v.signal(x, "x", need_fs=False)
    factor = 1.0 if s.units is None else _units.conversion_factor(model.units, s.units)
    t = read_temp_degc(temp, s.values.shape[0])
    return _v.labelled(s.values - model(t) * factor, s, "x", units=s.units)


def offsets_vs_temperature(
    x, temp=None, fs: float | None = None, *, var: str = "gyr", window_s: float = 10.0
) -> tuple[np.ndarray, np.ndarray]:
    """Offsets of a *static* record in consecutive windows, with the mean temperature of each.

    For a gyroscope at rest (true rate 0) the window medians are the offsets; use this on
    a warm-up record to collect (temperature, offset) pairs for
    :func:`fit_temperature_model`.

    Parameters
    ----------
    x : Recording, DataArray or array_like (N, 3)
        The static record (for a Recording, its variable ``var``).
    temp : DataArray or array_like (N,), optional
        Sensor temperature (°C, or labelled in K); default the Recording's ``temp``.
    fs : float, optional
        Sampling rate (Hz); read from the attrs of labelled input, mandatory for a
        plain array.
    var : str
        Variable read from a Recording.
    window_s : float
        Window length (s).

    Returns
    -------
    temps : ndarray (K,)
        Mean temperature (°C) of each window.
    offsets : ndarray (K, 3)
        Median of each window, in the units of ``x``.
    """
    s = _v.signal(x, "x", var=var, fs=fs)
    a = s.values
    if temp is None:
        if not isinstance(x, xr.Dataset):
            raise ValueError("temp (the sensor temperature) is needed")
        if "temp" not in x:
            raise _v.RecordingError(
                "the Recording has no variable 'temp' (needed for temp)"
            )
        temp = x["temp"]
    t = read_temp_degc(temp, a.shape[0])
    window_s = _v.positive(window_s, "window_s")
    w, k = window_count(a.shape[0], window_s, s.fs, 1, ("record", ""))
    temps = t[: k * w].reshape(k, w).mean(axis=1)
    return temps, np.median(a[: k * w].reshape(k, w, 3), axis=1)
