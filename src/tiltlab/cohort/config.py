r"""The feature configuration: every choice that turns a session into its features.

A :class:`FeatureConfig` is frozen, validated on construction and serialisable
(:meth:`~FeatureConfig.to_dict`, :meth:`~FeatureConfig.from_dict`,
:meth:`~FeatureConfig.to_json`); :meth:`~FeatureConfig.hash` is the SHA-256 of its
canonical JSON, which keys the per-session cache of :func:`tiltlab.cohort.run_cohort`
and is stored, with the JSON itself, in the attrs of every feature table.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from .. import _validate as _v
from .. import filters as _filters

__all__ = ["FeatureConfig"]


def _plain(v):
    """Copy a parameter value JSON-friendly (numpy → Python, tuples → lists)."""
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, (np.ndarray, list, tuple)):
        return [_plain(x) for x in np.asarray(v, dtype=object).tolist()]
    if isinstance(v, dict):
        return {str(k): _plain(x) for k, x in v.items()}
    return v


#: sampling rate (Hz) of the synthetic input of :func:`_dry_run`: high, so that limits
#: that scale with fs (a cut-off below Nyquist) do not refuse values valid on real data
_DRY_FS = 1e5


def _dry_run(method, params: dict, use_mag: bool, where: str = "method_params") -> None:
    """Try ``method`` on a short synthetic static input to refuse bad parameters early.

    Run ``method`` on a short synthetic static input, so that an out-of-domain
    parameter (a negative cut-off, a NaN gain) is refused when the configuration is
    built, not once per session. Only errors naming a parameter count (the synthetic
    input is valid); the adapters to other packages are not run.
    """
    if method.kind == "adapter":
        return
    n = 32
    acc = np.tile([0.0, 0.0, 9.80665], (n, 1))
    gyr = np.zeros((n, 3))
    mag = np.tile([0.0, 20.0, -40.0], (n, 1)) if use_mag else None
    try:
        method(acc, gyr, _DRY_FS, mag, **params)
    except ValueError as exc:
        msg = str(exc)
        if any(re.search(rf"\b{re.escape(k)}\b", msg) for k in params):
            raise ValueError(f"FeatureConfig.{where}: {msg}") from None
    except Exception:  # noqa: BLE001 - anything else is for the real run to report
        pass


def _resolved(method: Any, params: Any, where: str):
    """Complete and type the parameters of ``method`` with its registry defaults.

    The registry entry of ``method`` and its parameters completed with the defaults,
    typed (a numeric parameter is a finite float) and JSON-serialisable.
    """
    name = f"FeatureConfig.{where}"
    pname = f"FeatureConfig.{where}_params"
    if not isinstance(method, str):
        raise ValueError(f"{name} must be a string, got {method!r}")
    try:
        m = _filters.get_method(method)
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None
    if not isinstance(params, dict):
        raise ValueError(f"{pname} must be a dict, got {params!r}")
    try:
        resolved = m.resolve(dict(params))
    except ValueError as exc:
        raise ValueError(f"{pname}: {exc}") from None
    defaults = m.defaults

    def typed(k, v):
        # a numeric parameter must be a finite number; 2 and 2.0 are the same
        # cut-off: one spelling, one hash
        d = defaults.get(k)
        if isinstance(d, (int, float)) and not isinstance(d, bool):
            x = _v.finite(v, f"{pname}[{k!r}]")
            return float(x) if isinstance(d, float) else _plain(v)
        return _plain(v)

    resolved = {k: typed(k, resolved[k]) for k in sorted(resolved)}
    try:
        json.dumps(resolved, allow_nan=False)
    except (TypeError, ValueError):
        raise ValueError(
            f"{pname} must hold JSON-serialisable values, got {params!r}"
        ) from None
    return m, resolved


@dataclass(frozen=True)
class FeatureConfig:
    r"""How a session's features are computed (Fayat et al. 2021, §2.5–2.10).

    Parameters
    ----------
    method : str
        Orientation method of :func:`tiltlab.filters.estimate` (any name of
        :func:`tiltlab.filters.methods`). Default ``"smoother"``: the offline tilt
        smoother, following the filter benchmark chapter (offline methods are the most
        accurate on BROAD and the right tool for post-hoc analysis). Fayat et al.'s
        cohort features use Madgwick's filter with their optimal gain β = 0.1 (their
        Fig. 4b and Table 1): :meth:`fayat2021` sets it with their other definitions.
    method_params : dict
        Parameters of the method; completed with the registry's defaults on
        construction, so that the stored configuration names every value used.
    use_mag : bool
        Use the magnetometer (9D) where the method supports it.
    no_gyro_method : str
        Orientation method for a session whose Recording lacks a sensor that ``method``
        needs (a bio-logging tag with no gyroscope): one of
        ``tilt``-capable methods that need no gyroscope
        (``tiltlab.filters.methods(needs=("acc", "mag"))``). Default ``"lowpass"``, the
        static-acceleration tilt.
    no_gyro_method_params : dict
        Its parameters, completed with the registry's defaults like ``method_params``.
    calibration_model : {"offsets", "ellipsoid"}
        Accelerometer model fitted to a tumble test
        (:func:`tiltlab.calibration.tumble_calibration`): Fayat's offsets, or offsets
        with scale and misalignment.
    calibration_gyro : bool
        Also apply the tumble test's gyroscope offsets (the session's own offset is
        then estimated on top of them when ``gyr_offset="auto"``).
    gyr_offset : {"auto", "none"}
        Remove the session's gyroscope offset estimated from its quietest windows
        (:func:`tiltlab.calibration.robust_gyro_offset`) before everything else.
    threshold_deg_s, merge_gap_s, min_duration_s : float
        Immobility rules (Fayat §2.9: 12 °/s, 0.1 s, 0.5 s); the last two serve the
        accelerometer rule too.
    acc_threshold_g, acc_window_s, acc_smooth_s : float
        Immobility of a session without a gyroscope
        (:func:`tiltlab.behavior.acc_immobility`): VeDBA threshold (g), static window
        (s) and running mean (s).
    auto_threshold : bool
        Also compute immobility with the threshold at the valley of the angular-speed
        distribution (:func:`tiltlab.behavior.valley_threshold`).
    mesh_n : int
        Vertices of the Fibonacci sphere mesh for the visited fraction (Fayat: 5000).
    visited_min_count : int
        Samples a facet needs to count as visited.
    visited_by : {"area", "count"}
        Fraction of the sphere visited as the visited facets' area over 4π
        (``"area"``) or as their number over the number of facets (``"count"``, Fayat
        et al.'s facet counting; the facets' areas differ by a few per cent).
    tilt_mean : {"samples", "map"}
        vMF mean tilt during immobility from the samples themselves (``"samples"``) or,
        as Fayat et al. §2.8, from the facet centroids of the immobility tilt map
        weighted by their sample counts (``"map"``; equal to within a facet's size).
    sagittal : {"signed", "unsigned"}
        ``tilt_immobile_sagittal_deg`` as the signed angle to the sagittal plane
        (positive toward ``lesion_side``) or as Fayat et al.'s angular distance to it
        (its absolute value, Fig. 4c and Tables A5–A6). The one-sided test of the
        unsigned distance asks whether the head is tilted at all, not toward which
        side.
    tilt_thresholds_deg : tuple of float
        Angles (deg) between the tilt and +z beyond which the head counts as tilted.
    speed_quantiles : tuple of float
        Quantiles of the angular speed while moving.
    dba_window_s : float
        Window (s) of the static acceleration for DBA and ODBA.
    lesion_side : {"left", "right"}
        Side that makes the sagittal angle positive (Fayat §2.8, §3.3).
    """

    method: str = "smoother"
    method_params: dict = field(default_factory=dict)
    use_mag: bool = False
    no_gyro_method: str = "lowpass"
    no_gyro_method_params: dict = field(default_factory=dict)
    calibration_model: str = "offsets"
    calibration_gyro: bool = False
    gyr_offset: str = "auto"
    threshold_deg_s: float = 12.0
    merge_gap_s: float = 0.1
    min_duration_s: float = 0.5
    acc_threshold_g: float = 0.03
    acc_window_s: float = 0.5
    acc_smooth_s: float = 0.2
    auto_threshold: bool = True
    mesh_n: int = 5000
    visited_min_count: int = 1
    visited_by: str = "area"
    tilt_mean: str = "samples"
    sagittal: str = "signed"
    tilt_thresholds_deg: tuple = (20.0, 40.0)
    speed_quantiles: tuple = (0.5, 0.9)
    dba_window_s: float = 2.0
    lesion_side: str = "left"

    def __post_init__(self):
        """Check every field and store the method parameters completed and typed."""

        def put(name, value):
            object.__setattr__(self, name, value)

        def name(f):
            return f"FeatureConfig.{f}"

        m, resolved = _resolved(self.method, self.method_params, "method")
        put("method_params", resolved)
        nm, nresolved = _resolved(
            self.no_gyro_method, self.no_gyro_method_params, "no_gyro_method"
        )
        if nm.uses_gyr:
            raise ValueError(
                f"{name('no_gyro_method')}: method {nm.name!r} needs a gyroscope; "
                "choose one of "
                f"{', '.join(_filters.methods(needs=('acc', 'mag')))}"
            )
        put("no_gyro_method_params", nresolved)
        _dry_run(nm, nresolved, nm.requires_mag, "no_gyro_method_params")
        for f in ("use_mag", "calibration_gyro", "auto_threshold"):
            v = getattr(self, f)
            if not isinstance(v, (bool, np.bool_)):
                raise ValueError(f"{name(f)} must be True or False, got {v!r}")
            put(f, bool(v))
        if self.use_mag and not m.supports_mag:
            raise ValueError(
                f"{name('use_mag')}: method {self.method!r} does not use a magnetometer"
            )
        _dry_run(m, resolved, self.use_mag or m.requires_mag)
        choices = {
            "calibration_model": ("offsets", "ellipsoid"),
            "gyr_offset": ("auto", "none"),
            "lesion_side": ("left", "right"),
            "visited_by": ("area", "count"),
            "tilt_mean": ("samples", "map"),
            "sagittal": ("signed", "unsigned"),
        }
        for f, allowed in choices.items():
            if getattr(self, f) not in allowed:
                raise ValueError(
                    f"{name(f)} must be one of {allowed}, got {getattr(self, f)!r}"
                )
        put(
            "threshold_deg_s",
            _v.positive(self.threshold_deg_s, name("threshold_deg_s")),
        )
        put("merge_gap_s", _v.nonnegative(self.merge_gap_s, name("merge_gap_s")))
        put(
            "min_duration_s",
            _v.nonnegative(self.min_duration_s, name("min_duration_s")),
        )
        put("mesh_n", _v.integer(self.mesh_n, name("mesh_n"), minimum=12))
        put(
            "visited_min_count",
            _v.integer(self.visited_min_count, name("visited_min_count"), minimum=1),
        )
        put("dba_window_s", _v.positive(self.dba_window_s, name("dba_window_s")))
        for f in ("acc_threshold_g", "acc_window_s"):
            put(f, _v.positive(getattr(self, f), name(f)))
        put("acc_smooth_s", _v.nonnegative(self.acc_smooth_s, name("acc_smooth_s")))
        thr = self._floats("tilt_thresholds_deg")
        if any(not 0 < t < 180 for t in thr):
            raise ValueError(
                f"{name('tilt_thresholds_deg')} must be angles in (0, 180) deg, got "
                f"{self.tilt_thresholds_deg!r}"
            )
        put("tilt_thresholds_deg", thr)
        qs = self._floats("speed_quantiles")
        for q in qs:
            _v.fraction(q, name("speed_quantiles"))
        put("speed_quantiles", qs)

    def _floats(self, f: str) -> tuple[float, ...]:
        v = getattr(self, f)
        vals = (v,) if np.isscalar(v) else tuple(v)
        out = tuple(_v.finite(x, f"FeatureConfig.{f}") for x in vals)
        if len(set(out)) != len(out):
            raise ValueError(f"FeatureConfig.{f} has repeated values: {v!r}")
        return tuple(sorted(out))

    @classmethod
    def fayat2021(cls, **changes: Any) -> "FeatureConfig":
        """Return the configuration of Fayat et al. (2021)'s cohort features.

        Madgwick's filter with their optimal gain β = 0.1 (their Table 1; the
        fraction of the sphere visited of Fig. 4b is a "Madgwick estimate"), facets
        counted on their 5000-vertex Fibonacci triangulation (§2.7), the vMF mean
        tilt of the immobility tilt map from facet centroids weighted by counts
        (§2.8), its unsigned angular distance to the sagittal plane (Fig. 4c), and
        their immobility rules (12 °/s, 0.1 s, 0.5 s; §2.9). Everything else is the
        default.

        Parameters
        ----------
        **changes
            Fields to set differently (e.g. ``lesion_side="right"``).

        Returns
        -------
        FeatureConfig
            The preset, validated like any configuration.

        Examples
        --------
        >>> from tiltlab.cohort import FeatureConfig
        >>> c = FeatureConfig.fayat2021()
        >>> c.method, c.method_params["beta"], c.visited_by, c.sagittal
        ('madgwick', 0.1, 'count', 'unsigned')

        References
        ----------
        .. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents:
           Principles and Applications to Vestibular Research", Sensors 21(18):6318,
           2021. doi:10.3390/s21186318
        """
        preset: dict[str, Any] = {
            "method": "madgwick",
            "method_params": {"beta": 0.1},
            "mesh_n": 5000,
            "visited_by": "count",
            "tilt_mean": "map",
            "sagittal": "unsigned",
            "threshold_deg_s": 12.0,
            "merge_gap_s": 0.1,
            "min_duration_s": 0.5,
        }
        return cls(**(preset | changes))

    # ------------------------------------------------------------ serialisation

    def to_dict(self) -> dict[str, Any]:
        """Every field as JSON-compatible values (round trip with :meth:`from_dict`)."""
        return {f.name: _plain(getattr(self, f.name)) for f in fields(self)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "FeatureConfig":
        """Build a configuration from :meth:`to_dict` output (unknown key: ValueError)."""
        if not isinstance(d, dict):
            raise ValueError(f"expected a dict, got {type(d).__name__}")
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise ValueError(
                f"unknown FeatureConfig field(s) {unknown}; known: {sorted(names)}"
            )
        kw = dict(d)
        for f in ("tilt_thresholds_deg", "speed_quantiles"):
            if f in kw and isinstance(kw[f], list):
                kw[f] = tuple(kw[f])
        return cls(**kw)

    def to_json(self) -> str:
        """Canonical JSON (sorted keys, no whitespace): the input of :meth:`hash`."""
        return json.dumps(
            self.to_dict(), sort_keys=True, separators=(",", ":"), allow_nan=False
        )

    @classmethod
    def from_json(cls, text: str) -> "FeatureConfig":
        """Inverse of :meth:`to_json`."""
        return cls.from_dict(json.loads(text))

    def hash(self) -> str:
        """SHA-256 (hex) of :meth:`to_json`: equal configurations, equal hashes."""
        return hashlib.sha256(self.to_json().encode()).hexdigest()

    def __hash__(self) -> int:
        """Hash by the configuration's content (:meth:`hash`)."""
        return int(self.hash()[:16], 16)
