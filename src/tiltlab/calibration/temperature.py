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

from ._util import CalibrationError, vec3

__all__ = ["TemperatureModel", "fit_temperature_model", "compensate_temperature", "offsets_vs_temperature"]


@dataclass(frozen=True)
class TemperatureModel:
    """Per-axis polynomial offsets :math:`o_i(T) = \\sum_k c_{ik}(T - T_0)^k`.

    Attributes
    ----------
    coef : tuple of 3 tuples
        Coefficients per axis, highest power first (numpy ``polyval`` order).
    t0 : float
        Centring temperature (°C).
    t_range : tuple (min, max)
        Temperatures covered by the fit; :meth:`__call__` refuses to extrapolate beyond
        ``extrapolate`` °C outside it.
    units : str
        Units of the offsets (``"g"`` or ``"deg/s"``).
    """

    coef: tuple
    t0: float
    t_range: tuple
    units: str

    def __call__(self, temp, *, extrapolate: float = 2.0) -> np.ndarray:
        """Offsets (N, 3) at temperatures ``temp`` (°C)."""
        t = np.asarray(temp, dtype=float)
        if not np.all(np.isfinite(t)):
            raise ValueError("temperature contains NaN or infinite values")
        lo, hi = self.t_range
        if t.size and (t.min() < lo - extrapolate or t.max() > hi + extrapolate):
            raise CalibrationError(f"temperatures {t.min():.2f}…{t.max():.2f} °C lie outside the calibrated range "
                                   f"{lo:.2f}…{hi:.2f} °C (± {extrapolate} °C)")
        x = t - self.t0
        return np.stack([np.polyval(np.asarray(c), x) for c in self.coef], axis=-1)

    def to_dict(self) -> dict:
        return {"coef": [list(map(float, c)) for c in self.coef], "t0": float(self.t0),
                "t_range": [float(v) for v in self.t_range], "units": self.units}

    @classmethod
    def from_dict(cls, d: dict) -> "TemperatureModel":
        return cls(tuple(tuple(c) for c in d["coef"]), float(d["t0"]), tuple(d["t_range"]), str(d["units"]))


def fit_temperature_model(temp, offsets, *, degree: int = 3, units: str = "g") -> TemperatureModel:
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
    """
    t = np.asarray(temp, dtype=float)
    o = vec3(offsets, "offsets", ndim=2)
    if t.shape != (o.shape[0],):
        raise ValueError(f"temp must have shape ({o.shape[0]},), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ValueError("temp contains NaN or infinite values")
    if degree < 0:
        raise ValueError("degree must be >= 0")
    if np.unique(np.round(t, 6)).size < degree + 2:
        raise CalibrationError(f"a degree-{degree} temperature model needs calibrations at >= {degree + 2} distinct "
                               f"temperatures, got {np.unique(np.round(t, 6)).size}")
    t0 = float(t.mean())
    coef = tuple(tuple(np.polyfit(t - t0, o[:, i], degree)) for i in range(3))
    return TemperatureModel(coef, t0, (float(t.min()), float(t.max())), units)


def compensate_temperature(x, temp, model: TemperatureModel) -> np.ndarray:
    """Subtract temperature-dependent offsets: ``x - model(temp)`` (new array)."""
    a = vec3(x, "x", ndim=2)
    t = np.asarray(temp, dtype=float)
    if t.shape != (a.shape[0],):
        raise ValueError(f"temp must have shape ({a.shape[0]},), got {t.shape}")
    return a - model(t)


def offsets_vs_temperature(x, temp, fs: float, *, window_s: float = 10.0) -> tuple[np.ndarray, np.ndarray]:
    """Offsets of a *static* record in consecutive windows, with the mean temperature of each.

    For a gyroscope at rest (true rate 0) the window medians are the offsets; use this on
    a warm-up record to collect (temperature, offset) pairs for :func:`fit_temperature_model`.

    Returns
    -------
    temps : ndarray (K,)
    offsets : ndarray (K, 3)
    """
    a = vec3(x, "x", ndim=2)
    t = np.asarray(temp, dtype=float)
    if t.shape != (a.shape[0],):
        raise ValueError("temp must have one value per sample")
    w = int(round(window_s * float(fs)))
    k = a.shape[0] // w
    if k < 1:
        raise CalibrationError("record shorter than one window")
    return t[: k * w].reshape(k, w).mean(axis=1), np.median(a[: k * w].reshape(k, w, 3), axis=1)
