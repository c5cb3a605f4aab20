r"""C3D motion-capture exports: marker trajectories as a labelled Dataset.

A C3D file (the exchange format of Vicon, Qualisys and most optical motion-capture
systems) holds a header, a parameter section (groups such as ``POINT``, ``ANALOG``,
``TRIAL``, ``EVENT``) and, per video frame, every 3-D point followed by the analog
samples of that frame. The file is parsed with the pure-Python ``c3d`` package; this
module only turns it into the layout the rest of the package uses for motion capture
(the one of :func:`tiltlab.simulate.mocap_markers`): ``markers`` with dims
``frame``, ``marker``, ``axis``, in the file's length unit.

What a real export needs, and what :func:`read_c3d` does about it:

* **more than 255 points**: a label parameter holds at most 255 entries, so the labels
  continue in ``POINT:LABELS2``, ``POINT:LABELS3``, …; all are read, in order;
* **first frame**: a trimmed export starts at the frame of the original capture where
  the trim began (``TRIAL:ACTUAL_START_FIELD`` or the header); the frame numbers are
  kept as the ``frame`` coordinate and ``attrs["first_frame"]``, and the time of
  frame :math:`n` is :math:`(n - 1)/f_s` (C3D numbers frames from 1), the clock on
  which ``EVENT:TIMES`` count;
* **missing points**: a negative residual word marks a point the cameras did not
  reconstruct in that frame; its coordinates become NaN (the stored ones are zeros);
* **computed channels stored as points**: Vicon's Plug-in Gait writes joint angles,
  forces, moments and powers as 3-D "points"; they are listed in the ``POINT`` groups
  named by ``POINT:TYPE_GROUPS`` (``ANGLES``, ``FORCES``, ``MOMENTS``, ``POWERS``,
  ``SCALARS``; the default list when that parameter is absent), have their own units
  (``POINT:ANGLE_UNITS``, …) and are kept out of ``markers``. Modelled (virtual)
  markers (``POINT:MODELED_MARKERS``) are positions and stay markers.

No processing beyond this: gaps are left as NaN (fill short ones with
:func:`tiltlab.calibration.fill_marker_gaps`); analog channels are described in the
attrs (labels, units, rate) but not read.
"""

from __future__ import annotations

import difflib
import os
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import xarray as xr

from .._stack import user_stacklevel
from ._common import PathLike, ReadError, file_head, no_file

__all__ = ["read_c3d", "c3d_path", "C3D_COMPUTED_GROUPS", "ACC_UNITS"]

#: ``POINT`` groups holding computed (non-position) channels, with the prefix of their
#: units parameter, used when the file has no ``POINT:TYPE_GROUPS``.
C3D_COMPUTED_GROUPS = {
    "ANGLES": "ANGLE",
    "FORCES": "FORCE",
    "MOMENTS": "MOMENT",
    "POWERS": "POWER",
    "SCALARS": "SCALAR",
}

#: Unit labels that mark an analog channel as an accelerometer.
ACC_UNITS = ("g", "m/s^2", "m/s2", "m/s²", "mm/s^2", "mm/s2")

_FOREIGN = "foreign:"
_C3D_PARAMETER_ID = 0x50  # second byte of every C3D file


def c3d_path(source: str | os.PathLike) -> Path | None:
    """Resolve a C3D source: a file path, or ``"foreign:REL"`` in the data mirror.

    ``"foreign:REL"`` names the file ``REL`` of the ``foreign`` folder of the local
    data mirror given by the environment variable ``TILTLAB_DATA_DIR`` (the
    recordings from other labs the book uses). Existence is not checked.

    Parameters
    ----------
    source : str or path-like
        A path, or ``"foreign:"`` followed by a path relative to the mirror's
        ``foreign`` folder.

    Returns
    -------
    pathlib.Path or None
        The path; None for a ``"foreign:"`` source when ``TILTLAB_DATA_DIR`` is not
        set.

    Examples
    --------
    >>> c3d_path("/data/lab/walk01.c3d").name
    'walk01.c3d'
    """
    if not isinstance(source, (str, os.PathLike)):
        raise ValueError(f"source must be a path or 'foreign:REL', got {source!r}")
    text = os.fspath(source)
    if isinstance(text, str) and text.startswith(_FOREIGN):
        mirror = os.environ.get("TILTLAB_DATA_DIR")
        if not mirror:
            return None
        return Path(mirror).expanduser().resolve() / "foreign" / text[len(_FOREIGN) :]
    return Path(text)


def _strings(reader, key: str) -> list[str]:
    """Return a string parameter (``GROUP:NAME``) as a flat list of stripped strings."""
    p = reader.get(key)
    if p is None:
        return []
    arr = np.atleast_1d(p.string_array)
    return [str(s).strip() for s in arr.reshape(-1)]


def _labels(reader, n: int, path: Path) -> list[str]:
    """Return the point labels over ``POINT:LABELS``, ``LABELS2``, …, made unique."""
    labels = _strings(reader, "POINT:LABELS")
    k = 2
    while len(labels) < n and reader.get(f"POINT:LABELS{k}") is not None:
        labels += _strings(reader, f"POINT:LABELS{k}")
        k += 1
    labels = labels[:n]
    if len(labels) < n:
        warnings.warn(
            f"{path.name}: {n} points but {len(labels)} labels; the others are named "
            f"POINT{len(labels) + 1}…POINT{n}",
            stacklevel=user_stacklevel(),
        )
        labels += [f"POINT{i + 1}" for i in range(len(labels), n)]
    seen: dict[str, int] = {}
    out = []
    for i, lab in enumerate(labels):
        lab = lab or f"POINT{i + 1}"
        seen[lab] = seen.get(lab, 0) + 1
        out.append(lab if seen[lab] == 1 else f"{lab}#{seen[lab]}")
    dup = sorted(lab for lab, c in seen.items() if c > 1)
    if dup:
        warnings.warn(
            f"{path.name}: repeated point labels {dup}; later ones get '#2', '#3'…",
            stacklevel=user_stacklevel(),
        )
    return out


def _computed(reader) -> dict[str, tuple[str, str]]:
    """Map each computed channel named in the ``POINT`` groups to (kind, units)."""
    groups = dict(C3D_COMPUTED_GROUPS)
    tg = reader.get("POINT:TYPE_GROUPS")
    if tg is not None:
        pairs = np.asarray(tg.string_array, dtype=object).reshape(-1, 2)
        groups = {
            str(g).strip(): str(u).strip()
            for g, u in pairs
            if "MARKER" not in str(g).upper()
        }
    out: dict[str, tuple[str, str]] = {}
    for group, unit_prefix in groups.items():
        units = _strings(reader, f"POINT:{unit_prefix}_UNITS")
        for lab in _strings(reader, f"POINT:{group}"):
            if lab:
                out[lab] = (unit_prefix.lower(), units[0] if units else "")
    return out


def _pick(
    names: Sequence[str] | str | None,
    available: list[str],
    other: dict[str, str],
    param: str,
    path: Path,
    what: str,
) -> list[str]:
    """Check the requested names; name unknown ones with their close matches."""
    if names is None:
        return list(available)
    if isinstance(names, str):
        names = [names]
    names = list(names)
    bad = [n for n in names if not isinstance(n, str)]
    if bad:
        raise ValueError(f"{param}: names must be strings, got {bad!r}")
    problems = []
    for n in names:
        if n in available:
            continue
        if n in other:
            problems.append(f"{n!r} is {other[n]}")
            continue
        close = difflib.get_close_matches(n, available, 3, 0.6)
        if not close:
            folded = {a.lower(): a for a in available}
            close = [folded[c] for c in difflib.get_close_matches(n.lower(), folded, 3)]
        hint = f" (close: {', '.join(map(repr, close))})" if close else ""
        problems.append(f"{n!r} is not in the file{hint}")
    if problems:
        raise ValueError(
            f"{param}: {'; '.join(problems)}; {path.name} has {len(available)} "
            f"{what}: {', '.join(available[:12])}{', …' if len(available) > 12 else ''}"
        )
    if len(set(names)) != len(names):
        raise ValueError(f"{param}: repeated names in {names!r}")
    return names


def read_c3d(
    path: PathLike,
    *,
    markers: Sequence[str] | str | None = None,
    computed: bool | Sequence[str] = False,
) -> xr.Dataset:
    """Read the 3-D points of a C3D motion-capture file into a labelled Dataset.

    Points whose residual word is negative (not reconstructed in that frame) are NaN.
    Labels are read from ``POINT:LABELS`` and its continuations (``LABELS2``, …);
    computed channels (the labels of the ``POINT`` groups ``ANGLES``, ``FORCES``,
    ``MOMENTS``, ``POWERS``, ``SCALARS``, or those ``POINT:TYPE_GROUPS`` names) are
    kept apart from the markers. See the module notes.

    Parameters
    ----------
    path : path-like
        The ``.c3d`` file, or ``"foreign:REL"`` (see :func:`c3d_path`).
    markers : sequence of str, str or None
        Marker labels to keep, in this order (default None: every point that is not
        a computed channel, modelled markers included).
    computed : bool or sequence of str
        Computed channels to read as well: False (default) none, True all, or their
        labels.

    Returns
    -------
    xarray.Dataset
        ``markers`` (frame, marker, axis) in ``POINT:UNITS`` (NaN where missing) and
        ``residual`` (frame, marker) in the same unit; with ``computed``, also
        ``computed`` (frame, channel, axis) with coordinates ``channel_kind``
        (angle, force, …) and ``channel_units``. Coordinates ``frame`` (the file's
        frame numbers), ``frame_time`` (s, :math:`(n - 1)/f_s`), ``marker``, ``axis``.
        Attrs: ``fs`` (``POINT:RATE``, Hz), ``units``, ``first_frame``,
        ``last_frame``, ``source`` (file name), ``n_points``, ``computed_channels``
        (labels of every computed channel in the file), ``modeled_markers``,
        ``analog_labels``, ``analog_units``, ``analog_fs``, ``subjects``.

    Raises
    ------
    ReadError
        No such file, not a C3D file, or a file the parser cannot read.
    ValueError
        ``markers`` or ``computed`` names a point the file lacks (the message lists
        close matches) or a point of the other kind.

    Examples
    --------
    >>> read_c3d("no_such_walk.c3d")
    Traceback (most recent call last):
    ...
    tiltlab.io._common.ReadError: no_such_walk.c3d: no such file
    """
    import c3d

    if isinstance(path, str) and path.startswith(_FOREIGN):
        resolved = c3d_path(path)
        if resolved is None:
            raise ReadError(
                f"{path}: a 'foreign:' source needs the data mirror; set TILTLAB_DATA_DIR"
            )
        path = resolved
    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    head = file_head(path, 512)
    if head is None or len(head) < 512 or head[1] != _C3D_PARAMETER_ID:
        raise ReadError(
            f"{path}: not a C3D file (a C3D file starts with a 512-byte header whose "
            f"second byte is {_C3D_PARAMETER_ID})"
        )
    with open(path, "rb") as handle:
        try:
            # the parser's warnings ("No analog data found", end of file) are
            # recorded; only an early end of the file is passed on
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                reader = c3d.Reader(handle)
                n_points = int(reader.point_used)
                fs = float(reader.point_rate)
                first = int(reader.first_frame)
                frames, points = [], []
                for number, pts, _ in reader.read_frames(copy=True):
                    frames.append(number)
                    points.append(pts)
        except Exception as exc:  # the parser's own errors, with their names
            raise ReadError(
                f"{path}: not a readable C3D file ({type(exc).__name__}: {exc})"
            ) from None
        if not np.isfinite(fs) or fs <= 0:
            raise ReadError(f"{path}: POINT:RATE is {fs}, not a sampling rate")
        eof = [w for w in caught if "end of file" in str(w.message)]
        if eof:
            warnings.warn(
                f"{path.name}: the file ends early; {len(frames)} frames read",
                stacklevel=user_stacklevel(),
            )
        labels = _labels(reader, n_points, path)
        comp = _computed(reader)
        units = (_strings(reader, "POINT:UNITS") or [""])[0]
        analog_labels = _strings(reader, "ANALOG:LABELS")[: int(reader.analog_used)]
        analog_units = _strings(reader, "ANALOG:UNITS")[: len(analog_labels)]
        analog_fs = float(reader.analog_rate) if reader.analog_used else float("nan")
        modeled = _strings(reader, "POINT:MODELED_MARKERS")
        subjects = _strings(reader, "SUBJECTS:NAMES")
    data = (
        np.stack(points).astype(np.float64)
        if points
        else np.empty((0, n_points, 5), np.float64)
    )
    missing = data[:, :, 3] < 0
    xyz = np.where(missing[..., None], np.nan, data[:, :, :3])
    residual = np.where(missing, np.nan, data[:, :, 3])
    index = {lab: i for i, lab in enumerate(labels)}
    kinds = {lab: comp[lab] for lab in labels if lab in comp}
    mk_names = [lab for lab in labels if lab not in kinds]
    kind_text = {
        lab: f"a computed channel ({k}); pass it in computed"
        for lab, (k, _) in kinds.items()
    }
    chosen = _pick(markers, mk_names, kind_text, "markers", path, "markers")
    mk_idx = [index[n] for n in chosen]
    frame = np.asarray(frames, dtype=np.int64)
    ds = xr.Dataset(
        {
            "markers": (
                ("frame", "marker", "axis"),
                xyz[:, mk_idx, :],
                {
                    "units": units,
                    "long_name": "marker position (lab frame, as exported)",
                    "frame": "motion-capture lab frame",
                },
            ),
            "residual": (
                ("frame", "marker"),
                residual[:, mk_idx],
                {
                    "units": units,
                    "long_name": "reconstruction residual (NaN: not reconstructed)",
                },
            ),
        },
        coords={
            "frame": ("frame", frame, {"long_name": "C3D frame number"}),
            "frame_time": (
                "frame",
                (frame - 1) / fs,
                {"units": "s", "long_name": "time of the frame, (frame - 1) / fs"},
            ),
            "marker": ("marker", np.asarray(chosen, dtype=object)),
            "axis": ("axis", ["x", "y", "z"]),
        },
        attrs={
            "fs": fs,
            "units": units,
            "first_frame": first,
            "last_frame": int(frame[-1]) if frame.size else first - 1,
            "source": path.name,
            "n_points": n_points,
            "computed_channels": list(kinds),
            "modeled_markers": modeled,
            "analog_labels": analog_labels,
            "analog_units": analog_units,
            "analog_fs": analog_fs,
            "subjects": subjects,
        },
    )
    if computed is False or computed is None:
        return ds
    marker_text = {n: "a marker; pass it in markers" for n in mk_names}
    wanted = _pick(
        None if computed is True else computed,
        list(kinds),
        marker_text,
        "computed",
        path,
        "computed channels",
    )
    ch_idx = [index[n] for n in wanted]
    return ds.assign(
        computed=(
            ("frame", "channel", "axis"),
            xyz[:, ch_idx, :],
            {"long_name": "computed channel stored as a point (units per channel)"},
        )
    ).assign_coords(
        channel=("channel", np.asarray(wanted, dtype=object)),
        channel_kind=("channel", [kinds[n][0] for n in wanted]),
        channel_units=("channel", [kinds[n][1] for n in wanted]),
    )
