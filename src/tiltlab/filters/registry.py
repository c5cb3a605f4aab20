"""The one registry of orientation methods.

Each :class:`Method` names its function; everything else is read from that function's
signature with :mod:`inspect`, so that a default value is written in exactly one place
(the signature):

* ``defaults`` — the keyword-only parameters with a scalar default (``beta``,
  ``tau_acc_s``, …): the tunable parameters, recorded in :func:`estimate`'s attrs;
* ``options`` — the array-valued initial-state arguments that :func:`estimate` passes
  through (``q0``, ``gyr_offset``, ``P0``); a parameter's former name (see
  :func:`tiltlab._deprecate.renamed`) is accepted with a FutureWarning;
* ``supports_mag`` — the function has a ``mag`` argument (9D possible), unless the
  entry is marked ``six_d`` (an adapter that keeps ``mag=None`` only for the uniform
  signature: RIANN);
* ``uses_gyr`` — the function has a ``gyr`` argument (``lowpass`` and ``davenport``
  have not);
* ``needs`` — the Recording variables the method cannot run without: ``acc`` always,
  ``gyr`` when ``uses_gyr``, ``mag`` for an entry marked ``requires_mag``
  (``davenport``). :func:`methods` selects by them (``methods(needs="acc")``: the
  methods that run on an accelerometer alone, as on most bio-logging tags), and
  :func:`tiltlab.filters.estimate` refuses a method whose variable is missing, naming
  the methods that would run.

Adapters to the ``vqf`` package also accept that package's own parameters
(``extra_params``).
"""

from __future__ import annotations

import inspect
import warnings
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from .._stack import user_stacklevel
from .. import _validate as _v
from .. import dsp
import tiltlab.filters.adapters as adapters
from ._common import unlabel
from .complementary import complementary
from .ekf import ekf
from .eskf import eskf
from .lowpass import lowpass_tilt
from .learned_gain import learned_gain
from .madgwick import madgwick
from .mahony import mahony
from .rts import rts_smoother
from .smoothers import smoother
from .vectors import davenport, magnetic_dip
from ._docs import shared_docs

__all__ = [
    "Method",
    "METHODS",
    "PARAMETER_UNITS",
    "SENSORS",
    "methods",
    "get_method",
    "defaults",
    "missing_sensor_message",
]

#: the sensor variables a method can need, in the order they are listed
SENSORS = ("acc", "gyr", "mag")

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
        "dip": "rad",
    }
)

#: keyword arguments that are never parameters of :func:`estimate`
_NOT_PARAMS = frozenset({"mag", "return_bias", "return_state"})
#: array-valued keyword arguments (initial state): passed through, not tunable
_OPTIONS = frozenset({"q0", "gyr_offset", "P0"})
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
    requires_mag : bool
        The method cannot run without a magnetometer (a vector-observation method):
        :func:`~tiltlab.filters.estimate` then reads ``mag`` whatever ``use_mag``.
    """

    name: str
    function: Callable[..., Any]
    kind: str
    description: str
    extra_params: Callable[[], Collection[str]] | None = None
    six_d: bool = False
    requires_mag: bool = False

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

    @property
    def needs(self) -> tuple[str, ...]:
        """The Recording variables the method cannot run without.

        ``acc`` always, ``gyr`` when it integrates the gyroscope, ``mag`` when it
        requires one.
        """
        return (
            ("acc",)
            + (("gyr",) if self.uses_gyr else ())
            + (("mag",) if self.requires_mag else ())
        )

    def resolve(self, params: Mapping[str, Any]) -> dict[str, Any]:
        """Return ``defaults`` updated with ``params``; an unknown name is a ValueError.

        A parameter's former name (``b0`` for ``gyr_offset``) is translated, with a
        FutureWarning.

        Parameters
        ----------
        params : mapping
            Parameter values by name.

        Returns
        -------
        dict
            Every parameter of the method with its value.
        """
        params = _current_names(self.function, params)
        known = set(self.defaults) | set(self.options)
        extra = set(self.extra_params()) if self.extra_params else set()
        unknown, hint = _v.unknown_keys(
            params,
            known | extra,
            hints={"mag": " (pass use_mag=True to use the magnetometer)"},
        )
        if unknown:
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
        if mag is None and self.requires_mag:
            raise ValueError(missing_sensor_message(self, "mag", ("acc",)))
        kw = dict(params)
        if mag is not None:
            kw["mag"] = mag
        if self.uses_gyr:
            if gyr is None:
                have = ("acc", "mag") if mag is not None else ("acc",)
                raise ValueError(missing_sensor_message(self, "gyr", have))
            return self.function(acc, gyr, fs, **kw)
        return self.function(acc, fs, **kw)


def _current_names(function: Callable[..., Any], params: Mapping[str, Any]) -> dict:
    """Translate the former names of renamed parameters, with a FutureWarning."""
    old_to_new = getattr(function, "__renamed__", {})
    out = {}
    for k, v in params.items():
        if k in old_to_new:
            new = old_to_new[k]
            if new in params:
                raise TypeError(f"pass {new!r} only ({k!r} is its old name)")
            warnings.warn(
                f"{function.__name__}: {k!r} was renamed {new!r}; the old name goes "
                "in the next release",
                FutureWarning,
                stacklevel=user_stacklevel(),
            )
            k = new
        out[k] = v
    return out


@shared_docs
def vector_observation(
    acc,
    fs: float | None = None,
    *,
    mag,
    dip: float | None = None,
    cutoff_hz: float | None = None,
):
    r"""Estimate the orientation from the accelerometer and magnetometer alone.

    Sample by sample (Davenport's q-method, :func:`tiltlab.filters.davenport`); no
    gyroscope.

    The gravity-up observation is the specific force and the north observation the
    magnetic field; :math:`q_k` maximises Wahba's gain
    :math:`\sum_i a_i\, b_{i,k}^\top A(q_k)\, r_i` for the two of them (Davenport 1968;
    Markley & Crassidis 2014, §5.5). With ``cutoff_hz`` both series are first low-passed
    (zero phase, :func:`tiltlab.dsp.lowpass`), so that the body's own accelerations
    average out as in the ``lowpass`` method; without it every sample is used raw.

    Parameters
    ----------
    acc : array_like or xarray.DataArray, shape (N, 3)
        Specific force (any unit; only its direction is used).
    %(fs)s
    mag : array_like or xarray.DataArray, shape (N, 3)
        Magnetic field (any unit; only its direction is used). Required. Labelled
        inputs are read as in the filters (:mod:`tiltlab.filters`, "Labelled
        inputs").
    dip : float, optional
        Magnetic dip (rad, positive downwards); default: measured from the recording,
        the mean of :func:`tiltlab.filters.magnetic_dip` over its samples.
    cutoff_hz : float, optional
        Low-pass cut-off (Hz, ``0 < cutoff_hz < fs/2``) applied to ``acc`` and ``mag``
        before the q-method; ``None`` (default): raw samples.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions sensor → world (ENU: x east, y magnetic north, z up).

    Examples
    --------
    >>> import numpy as np
    >>> acc = np.tile([0.0, 0.0, 9.81], (50, 1))
    >>> mag = np.tile([0.0, 20.0, -40.0], (50, 1))
    >>> q = vector_observation(acc, 50.0, mag=mag)
    >>> np.allclose(q, [1.0, 0.0, 0.0, 0.0])
    True

    References
    ----------
    .. [1] P. B. Davenport, "A vector approach to the algebra of rotations with
       applications", NASA TN D-4696, 1968.
    .. [2] F. L. Markley and J. L. Crassidis, *Fundamentals of Spacecraft Attitude
       Determination and Control*, Springer, 2014, §5.5.
       doi:10.1007/978-1-4939-0802-8
    """
    fs, acc, _, mag = unlabel(fs, acc=acc, mag=mag)
    a = _v.vectors(acc, "acc", width=3, ndim=2)
    m = _v.vectors(mag, "mag", width=3, ndim=2)
    if a.shape != m.shape:
        raise ValueError(
            f"acc and mag must have the same number of samples, got {a.shape[0]} and "
            f"{m.shape[0]}"
        )
    if cutoff_hz is not None:
        a = dsp.lowpass(a, fs, cutoff_hz, name="acc")
        m = dsp.lowpass(m, fs, cutoff_hz, name="mag")
    if a.shape[0] == 0:
        return np.zeros((0, 4))
    d = magnetic_dip(a, m) if dip is None else _v.finite(dip, "dip")
    return davenport(a, m, dip=d)


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
        "davenport",
        vector_observation,
        "offline",
        "accelerometer + magnetometer, no gyroscope: Davenport's q-method per sample "
        "(optionally low-passed first)",
        requires_mag=True,
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
    Method(
        "learned_gain",
        learned_gain,
        "causal",
        "Mahony (6D) with gains scheduled by a learned model (pass weights=path)",
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


def _available(needs: Any) -> frozenset[str]:
    """Return the sensor variables named by ``needs`` (a name, names, or a Recording)."""
    if isinstance(needs, Mapping) or hasattr(needs, "data_vars"):
        return frozenset(v for v in SENSORS if v in needs)
    names = (needs,) if isinstance(needs, str) else tuple(needs)
    out = set()
    for name in names:
        parts = [p.strip() for p in str(name).replace("+", ",").split(",")]
        out.update(p for p in parts if p)
    unknown = sorted(out - set(SENSORS))
    if unknown:
        raise ValueError(
            f"needs: unknown sensor variable(s) {unknown}; use names of {SENSORS}, "
            'e.g. needs="acc" or needs=("acc", "mag"), or pass a Recording'
        )
    return frozenset(out)


def methods(kind: str | None = None, *, needs: Any = None) -> tuple[str, ...]:
    """List the registered methods, optionally of one ``kind`` and runnable on sensors.

    Parameters
    ----------
    kind : {"causal", "offline", "adapter"}, optional
        Keep only the methods of this kind.
    needs : str, sequence of str or xarray.Dataset, optional
        The sensor variables available (``"acc"``, ``("acc", "mag")``, ``"acc+mag"``),
        or a Recording (its ``acc``, ``gyr``, ``mag``): keep only the methods that need
        nothing more (:attr:`Method.needs`).

    Returns
    -------
    tuple of str
        Method names, in registry order.

    Examples
    --------
    >>> methods(needs="acc")
    ('lowpass',)
    >>> methods(needs="acc+mag")
    ('lowpass', 'davenport')
    """
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    have = None if needs is None else _available(needs)
    return tuple(
        n
        for n, m in METHODS.items()
        if (kind is None or m.kind == kind) and (have is None or set(m.needs) <= have)
    )


def missing_sensor_message(
    method: Method | str, missing: str, have: Collection[str] = ("acc",)
) -> str:
    """Write the message refusing ``method`` on data without the variable ``missing``.

    It names the method and the sensor it needs, and lists the methods that run on the
    variables ``have`` (and those that would with a magnetometer too).

    Parameters
    ----------
    method : Method or str
        The refused method (or its name).
    missing : str
        The variable the data lack: ``"acc"``, ``"gyr"`` or ``"mag"``.
    have : collection of str
        The variables the data have (default accelerometer only).

    Returns
    -------
    str
        The error message.
    """
    m = get_method(method) if isinstance(method, str) else method
    what = {"gyr": "a gyroscope", "mag": "a magnetometer", "acc": "an accelerometer"}
    have = set(have) - {missing}
    ok = methods(needs=sorted(have)) if have else ()
    alt = ", ".join(repr(n) for n in ok) or "none"
    if "mag" not in have and missing != "mag":
        more = [n for n in methods(needs=sorted(have | {"mag"})) if n not in ok]
        if more:
            alt += "; with a magnetometer also " + ", ".join(repr(n) for n in more)
    hint = " (it reads the Recording's 'mag' variable)" if missing == "mag" else ""
    return (
        f"method {m.name!r} needs {what.get(missing, repr(missing))} ({missing!r}) and "
        f"the data have none{hint}; methods that run on {', '.join(sorted(have))}: "
        f"{alt}"
    )


def get_method(name: str) -> Method:
    """Return the registry entry of ``name``.

    An unknown name is a ValueError listing the valid ones.

    Parameters
    ----------
    name : str
        A registered method name (a key of ``METHODS``).

    Returns
    -------
    Method
        The registry entry.
    """
    try:
        return METHODS[name]
    except (KeyError, TypeError):
        raise ValueError(
            f"unknown method {name!r}; known: {', '.join(METHODS)}"
        ) from None


def defaults(name: str) -> dict[str, Any]:
    """Parameter defaults of method ``name`` (read from its function's signature).

    Parameters
    ----------
    name : str
        A registered method name.

    Returns
    -------
    dict
        Parameter name → default value.
    """
    return get_method(name).defaults
