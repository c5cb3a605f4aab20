"""The one registry of orientation methods.

Each :class:`Method` names its function; everything else is read from that function's
signature with :mod:`inspect`, so that a default value is written in exactly one place
(the signature):

* ``defaults`` — the keyword-only parameters with a scalar default (``beta``,
  ``tau_acc_s``, …): the tunable parameters, recorded in :func:`estimate`'s attrs;
* ``options`` — the array-valued initial-state arguments that :func:`estimate` passes
  through (``q0``, ``b0``, ``P0``, ``bias``);
* ``supports_mag`` — the function has a ``mag`` argument (9D possible), unless the
  entry is marked ``six_d`` (an adapter that keeps ``mag=None`` only for the uniform
  signature: RIANN);
* ``uses_gyr`` — the function has a ``gyr`` argument (``lowpass`` has not).

Adapters to the ``vqf`` package also accept that package's own parameters
(``extra_params``).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from . import adapters
from .complementary import complementary
from .ekf import ekf
from .eskf import eskf
from .lowpass import lowpass_tilt
from .madgwick import madgwick
from .mahony import mahony
from .rts import rts_smoother
from .smoothers import smoother

__all__ = [
    "Method",
    "METHODS",
    "PARAMETER_UNITS",
    "methods",
    "get_method",
    "defaults",
]

#: units of the tunable parameters, as the filters' docstrings state them ("1": unitless);
#: figure recipes label parameter axes with them
PARAMETER_UNITS: Mapping[str, str] = MappingProxyType(
    {
        "beta": "rad/s",
        "kp": "rad/s",
        "ki": "rad/s²",
        "var_gyr": "(rad/s)²",
        "var_acc": "1",
        "var_mag": "1",
        "cutoff_hz": "Hz",
        "tau_acc_s": "s",
        "gyr_noise": "rad/√s",
        "acc_noise": "m/s/√s",
    }
)

#: keyword arguments that are never parameters of :func:`estimate`
_NOT_PARAMS = frozenset({"mag", "return_bias", "return_state"})
#: array-valued keyword arguments (initial state): passed through, not tunable
_OPTIONS = frozenset({"q0", "b0", "P0", "bias"})
#: kinds of method
KINDS = ("causal", "offline", "adapter")


@dataclass(frozen=True)
class Method:
    """One orientation method of the registry.

    Attributes
    ----------
    name : str
        The name used by :func:`tiltlab.filters.estimate`.
    function : callable
        ``function(acc, gyr, fs, *, mag=None, **params)`` (``function(acc, fs, ...)``
        when it uses no gyroscope), SI inputs, returning (N, 4) quaternions.
    kind : str
        ``"causal"`` (a real-time filter), ``"offline"`` (uses future samples) or
        ``"adapter"`` (a reference implementation from another package).
    description : str
        One line.
    extra_params : callable, optional
        Returns the names of further parameters the function accepts through
        ``**kwargs`` (the ``vqf`` adapters).
    six_d : bool
        The method is 6D only although its function has a ``mag`` argument (kept, as
        ``mag=None``, for the adapters' uniform signature): ``supports_mag`` is False,
        so ``use_mag=True`` is refused before any data are read.
    """

    name: str
    function: Callable[..., Any]
    kind: str
    description: str
    extra_params: Callable[[], Collection[str]] | None = None
    six_d: bool = False

    def _signature(self) -> Mapping[str, inspect.Parameter]:
        return inspect.signature(self.function).parameters

    def _keywords(self) -> list[inspect.Parameter]:
        return [
            p
            for p in self._signature().values()
            if p.kind is inspect.Parameter.KEYWORD_ONLY and p.name not in _NOT_PARAMS
        ]

    @property
    def defaults(self) -> dict[str, Any]:
        """Tunable parameters and their defaults (from the function's signature)."""
        return {
            p.name: p.default
            for p in self._keywords()
            if p.name not in _OPTIONS and p.default is not inspect.Parameter.empty
        }

    @property
    def options(self) -> tuple[str, ...]:
        """Further keyword arguments (arrays such as ``q0``) that are passed through."""
        return tuple(p.name for p in self._keywords() if p.name in _OPTIONS)

    @property
    def supports_mag(self) -> bool:
        """Whether the method can use a magnetometer (9D)."""
        return not self.six_d and "mag" in self._signature()

    @property
    def uses_gyr(self) -> bool:
        """Whether the method uses the gyroscope."""
        return "gyr" in self._signature()

    def resolve(self, params: Mapping[str, Any]) -> dict[str, Any]:
        """``defaults`` updated with ``params``; an unknown name is a ValueError."""
        known = set(self.defaults) | set(self.options)
        extra = set(self.extra_params()) if self.extra_params else set()
        unknown = [k for k in params if k not in known and k not in extra]
        if unknown:
            hint = (
                " (pass use_mag=True to use the magnetometer)"
                if "mag" in unknown
                else ""
            )
            valid = sorted(known) + (["<vqf parameters>"] if extra else [])
            raise ValueError(
                f"unknown parameter(s) {unknown} for method {self.name!r}{hint}; "
                f"valid: {valid}"
            )
        return {**self.defaults, **params}

    def __call__(self, acc, gyr, fs, mag=None, **params):
        """Run on SI arrays (``acc`` m/s², ``gyr`` rad/s) with resolved parameters."""
        if mag is not None and not self.supports_mag:
            raise ValueError(
                f"method {self.name!r} does not use a magnetometer; "
                "use_mag=True is not supported"
            )
        kw = dict(params)
        if mag is not None:
            kw["mag"] = mag
        if self.uses_gyr:
            return self.function(acc, gyr, fs, **kw)
        return self.function(acc, fs, **kw)


def _registry(*entries: Method) -> Mapping[str, Method]:
    for m in entries:
        if m.kind not in KINDS:
            raise ValueError(f"method {m.name!r}: kind must be one of {KINDS}")
    return MappingProxyType({m.name: m for m in entries})


#: The methods known to :func:`tiltlab.filters.estimate`, by name (read-only).
METHODS: Mapping[str, Method] = _registry(
    Method(
        "lowpass",
        lowpass_tilt,
        "offline",
        "tilt from the zero-phase low-passed accelerometer (heading zero)",
    ),
    Method(
        "complementary",
        complementary,
        "causal",
        "geometric complementary filter with time constants",
    ),
    Method("madgwick", madgwick, "causal", "Madgwick's gradient-descent filter"),
    Method(
        "mahony",
        mahony,
        "causal",
        "Mahony's explicit complementary filter with gyro-bias integral",
    ),
    Method("ekf", ekf, "causal", "quaternion-state EKF (ahrs formulation)"),
    Method(
        "eskf",
        eskf,
        "causal",
        "error-state Kalman filter (attitude, gyro bias; adaptive accelerometer "
        "variance, heading-only magnetometer update)",
    ),
    Method(
        "smoother",
        smoother,
        "offline",
        "rest gyro bias, strapdown integration, zero-phase low-pass of the "
        "specific force in the integrated frame",
    ),
    Method(
        "rts_smoother",
        rts_smoother,
        "offline",
        "error-state EKF (attitude, gyro bias/scale, velocity, position) with a "
        "Rauch-Tung-Striebel backward pass",
    ),
    Method(
        "vqf",
        adapters.run_vqf,
        "adapter",
        "VQF (vqf package)",
        adapters.vqf_parameter_names,
    ),
    Method(
        "offline_vqf",
        adapters.run_offline_vqf,
        "adapter",
        "offlineVQF (vqf package)",
        adapters.vqf_parameter_names,
    ),
    Method(
        "imufusion",
        adapters.run_imufusion,
        "adapter",
        "x-io Fusion AHRS (imufusion package)",
    ),
    Method(
        "riann",
        adapters.run_riann,
        "adapter",
        "RIANN, a published recurrent network (riann package, 6D)",
        six_d=True,
    ),
    Method(
        "ahrs_madgwick",
        adapters.run_ahrs_madgwick,
        "adapter",
        "Madgwick of the ahrs package",
    ),
    Method(
        "ahrs_mahony", adapters.run_ahrs_mahony, "adapter", "Mahony of the ahrs package"
    ),
    Method("ahrs_ekf", adapters.run_ahrs_ekf, "adapter", "EKF of the ahrs package"),
)


def methods(kind: str | None = None) -> tuple[str, ...]:
    """Names of the registered methods (of one ``kind`` if given)."""
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    return tuple(n for n, m in METHODS.items() if kind is None or m.kind == kind)


def get_method(name: str) -> Method:
    """The registry entry of ``name``; an unknown name is a ValueError listing the
    valid ones."""
    try:
        return METHODS[name]
    except (KeyError, TypeError):
        raise ValueError(
            f"unknown method {name!r}; known: {', '.join(METHODS)}"
        ) from None


def defaults(name: str) -> dict[str, Any]:
    """Parameter defaults of method ``name`` (read from its function's signature)."""
    return get_method(name).defaults
