"""Device axes: mapping a device's axes and sign conventions into the sensor frame.

Layer 1 (beside :mod:`tiltlab.schema`, which applies it in
:func:`tiltlab.schema.make_recording`). A Recording's vectors are expressed in a
right-handed sensor frame whose accelerometer reads the specific force (``+1 g`` along
the axis pointing up when still). Devices differ: a phone's axes point right, to the top
of the screen and out of it; a tag-tools file is written in a left-handed
[forward, right, up] frame; some loggers report gravity instead of specific force, or
have one axis of one sensor flipped. An *axes* specification says, for each sensor axis,
which device axis (with its sign) it is::

    ["x", "-y", "z"]              # the same for every vector variable
    {"acc": ["-x", "-y", "-z"], "gyr": ["-x", "y", "z"]}   # per variable

A *preset* names a device convention (:data:`PRESETS`): its axes, the sign of the
accelerometer, the handedness of the device frame and the labels of the resulting axes
(``attrs['axis_labels']``, which the figure recipes use). A left-handed device frame is
refused unless the axes turn it right-handed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Preset", "PRESETS", "parse_axes", "remap", "check_labels", "axis_labels"]

_VARS = ("acc", "gyr", "mag")


@dataclass(frozen=True)
class Preset:
    """A named device convention.

    Attributes
    ----------
    description : str
        What the device's axes are.
    axes : tuple of str
        The sensor axes as signed device axes (``("x", "-y", "z")``).
    labels : tuple of str
        What the resulting sensor axes point to.
    handedness : {"right", "left"}
        Handedness of the device frame before mapping.
    acc_sign : float
        ``-1`` for devices that report gravity instead of specific force.
    units : dict
        The units the device documents (a suggestion shown in messages; never assumed).
    """

    description: str
    axes: tuple[str, str, str] = ("x", "y", "z")
    labels: tuple[str, str, str] = ("x", "y", "z")
    handedness: str = "right"
    acc_sign: float = 1.0
    units: dict[str, str] = field(default_factory=dict)


#: Named device conventions (see the module docstring).
PRESETS: dict[str, Preset] = {
    "sensor": Preset("the sensor's own right-handed axes, unlabelled"),
    "animal": Preset(
        "an animal-borne sensor with x forward, y left, z up (right-handed)",
        labels=("forward", "left", "up"),
    ),
    "rat_head": Preset(
        "a head-mounted rodent IMU (Fayat et al. 2021): x to the nose, y left, z dorsal",
        labels=("forward (nose)", "left", "up (dorsal)"),
    ),
    "android": Preset(
        "Android sensor coordinates: x to the right of the screen, y to its top, z out "
        "of the screen (right-handed; acceleration is specific force, +9.81 m/s² on z "
        "lying face up)",
        labels=("right", "top", "out of screen"),
        units={"acc": "m/s^2", "gyr": "rad/s", "mag": "uT"},
    ),
    "ios": Preset(
        "iOS Core Motion device axes: x right, y top, z out of the screen "
        "(right-handed); the raw accelerometer reports gravity, −1 g on z lying face "
        "up, so its sign is reversed",
        labels=("right", "top", "out of screen"),
        acc_sign=-1.0,
        units={"acc": "g", "gyr": "rad/s", "mag": "uT"},
    ),
    "tagtools": Preset(
        "tag-tools (animaltags) tag frame: [forward, right, up], left-handed; y is "
        "reversed to give forward, left, up",
        axes=("x", "-y", "z"),
        labels=("forward", "left", "up"),
        handedness="left",
    ),
}


def parse_axes(spec: Sequence[str], where: str = "axes") -> np.ndarray:
    """Build a signed permutation matrix ``P`` from an axes specification.

    ``sensor = P @ device``: row ``i`` of ``P`` picks (with its sign) the device axis
    that sensor axis ``i`` is.

    Parameters
    ----------
    spec : sequence of 3 str
        Signed device axes, e.g. ``["x", "-y", "z"]`` or ``["-z", "x", "-y"]``.
    where : str
        Name used in messages.

    Returns
    -------
    numpy.ndarray, shape (3, 3)

    Examples
    --------
    >>> parse_axes(["x", "-y", "z"]).astype(int).tolist()
    [[1, 0, 0], [0, -1, 0], [0, 0, 1]]
    """
    if isinstance(spec, str) or not isinstance(spec, Sequence) or len(spec) != 3:
        raise ValueError(
            f"{where} must list three signed device axes, e.g. ['x', '-y', 'z'], "
            f"got {spec!r}"
        )
    out = np.zeros((3, 3))
    used = []
    for i, item in enumerate(spec):
        token = str(item).strip().lower().replace(" ", "")
        sign = 1.0
        if token[:1] in "+-":
            sign = -1.0 if token[0] == "-" else 1.0
            token = token[1:]
        if token not in ("x", "y", "z"):
            raise ValueError(
                f"{where}[{i}] = {item!r} is not a device axis: use 'x', 'y', 'z' with "
                "an optional sign, e.g. '-y'"
            )
        if token in used:
            raise ValueError(
                f"{where} uses device axis {token!r} twice: {list(spec)!r}"
            )
        used.append(token)
        out[i, "xyz".index(token)] = sign
    return out


def check_labels(labels: Sequence[str], where: str = "axis_labels") -> list[str]:
    """Three axis labels as a list of str.

    Parameters
    ----------
    labels : sequence of 3 str
        Names of the x, y and z axes, e.g. ``["forward", "left", "up"]``.
    where : str
        Name used in messages.

    Returns
    -------
    list of str
        The three labels, converted to str.

    Raises
    ------
    ValueError
        If ``labels`` is not a sequence of three items.
    """
    if isinstance(labels, str) or not isinstance(labels, Sequence) or len(labels) != 3:
        raise ValueError(
            f"{where} must be three names, e.g. ['forward', 'left', 'up'], got {labels!r}"
        )
    return [str(label) for label in labels]


def _preset(name: str) -> Preset:
    key = str(name).strip().lower().replace("-", "").replace(" ", "")
    aliases = {"tag-tools": "tagtools", "animaltags": "tagtools", "iphone": "ios"}
    key = aliases.get(key, key)
    if key not in PRESETS:
        raise ValueError(
            f"unknown preset {name!r}; known presets: {', '.join(PRESETS)}"
        )
    return PRESETS[key]


def remap(
    vectors: Mapping[str, np.ndarray],
    axes: Sequence[str] | Mapping[str, Sequence[str]] | None = None,
    *,
    preset: str | None = None,
    handedness: str | None = None,
) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """Express device vectors in the right-handed sensor frame.

    Parameters
    ----------
    vectors : mapping
        ``"acc"``, ``"gyr"``, ``"mag"`` → arrays of shape (N, 3) in device axes.
    axes : sequence of 3 str or mapping, optional
        Signed device axes for every variable, or per variable (``{"acc": [...],
        "gyr": [...]}``; a variable not named there takes ``"*"`` or the preset's).
        Given with a preset, it replaces the preset's axes.
    preset : str, optional
        A key of :data:`PRESETS`.
    handedness : {"right", "left"}, optional
        Handedness of the device frame; default the preset's, else right.

    Returns
    -------
    vectors : dict
        New arrays (the inputs are never modified).
    attrs : dict
        ``axis_labels``, ``frame_preset`` (if any) and ``axes_map`` (what was done).

    Raises
    ------
    ValueError
        For an unknown preset or axis, or a left-handed device frame left left-handed.

    Examples
    --------
    >>> import numpy as np
    >>> v, a = remap({"acc": np.array([[0.0, 1.0, 0.0]])}, preset="tagtools")
    >>> v["acc"].tolist(), a["axis_labels"]
    ([[0.0, -1.0, 0.0]], ['forward', 'left', 'up'])
    """
    p = _preset(preset) if preset is not None else PRESETS["sensor"]
    hand = handedness or p.handedness
    if hand not in ("right", "left"):
        raise ValueError(f"handedness must be 'right' or 'left', got {handedness!r}")
    per_var: dict[str, Sequence[str]] = {}
    common: Sequence[str] = p.axes
    if isinstance(axes, Mapping):
        unknown = [k for k in axes if k not in (*_VARS, "*")]
        if unknown:
            raise ValueError(
                f"axes: unknown variable(s) {unknown}; give axes for acc, gyr, mag or '*'"
            )
        common = axes.get("*", common)
        per_var = {k: v for k, v in axes.items() if k != "*"}
    elif axes is not None:
        common = axes
    base = parse_axes(common, "axes")
    if hand == "left" and np.linalg.det(base) > 0:
        raise ValueError(
            f"the device frame is left-handed ({p.description if preset else 'as stated'})"
            f" and axes {list(common)!r} keep it left-handed; reverse one axis, e.g. "
            "axes=['x', '-y', 'z']"
        )
    if hand == "right" and np.linalg.det(base) < 0:
        raise ValueError(
            f"axes {list(common)!r} turn the right-handed device frame left-handed; "
            "reverse one more axis (or state that the device frame is left-handed)"
        )
    out: dict[str, np.ndarray] = {}
    done = []
    for name, v in vectors.items():
        if name not in _VARS:
            raise ValueError(f"remap takes acc, gyr and mag, got {name!r}")
        m = parse_axes(per_var[name], f"axes[{name!r}]") if name in per_var else base
        if name == "acc" and p.acc_sign < 0:
            m = -m
        arr = np.asarray(v, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 3:
            raise ValueError(f"{name} must have shape (N, 3), got {arr.shape}")
        out[name] = arr @ m.T
        if not np.array_equal(m, np.eye(3)):
            done.append(f"{name} = {_describe(m)}")
    attrs: dict[str, Any] = {"axis_labels": list(p.labels)}
    if preset is not None:
        attrs["frame_preset"] = str(preset)
    if done:
        attrs["axes_map"] = "; ".join(done) + " (device axes)"
    return out, attrs


def _describe(m: np.ndarray) -> str:
    parts = []
    for row in m:
        j = int(np.argmax(np.abs(row)))
        parts.append(("-" if row[j] < 0 else "") + "xyz"[j])
    return "[" + ", ".join(parts) + "]"


def axis_labels(obj: Any) -> list[str]:
    """Return the axis labels of a Recording or labelled DataArray.

    These are ``attrs['axis_labels']``, or ``["x", "y", "z"]`` when none are recorded.

    Parameters
    ----------
    obj : object
        A Recording (xarray.Dataset), a DataArray or anything with ``attrs``.

    Returns
    -------
    list of str
        Three labels (x, y, z axes).
    """
    attrs = getattr(obj, "attrs", {}) or {}
    labels = attrs.get("axis_labels")
    if labels is None or len(labels) != 3:
        return ["x", "y", "z"]
    return [str(label) for label in labels]
