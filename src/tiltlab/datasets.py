"""Find, verify and load the public data sets the book uses, as validated Recordings.

The real-data registry holds the files, checksums and upstream URLs of those data sets.

The registry (``_registry/registry.txt``, pooch format) is generated from the data
manifest by ``tools/make_registry.py`` and committed; the data are not.

Where the files come from
-------------------------
* ``TILTLAB_DATA_DIR`` set: files are read from that local mirror (a folder with the
  manifest's layout, e.g. ``broad/02_undisturbed_slow_rotation_B.hdf5``); nothing is
  ever downloaded, and a missing file is an error.
* otherwise: files are downloaded once from their upstream URLs into a cache
  (``TILTLAB_CACHE_DIR``, default the OS cache folder) with :mod:`pooch`, unless
  ``TILTLAB_OFFLINE=1``, in which case a file not already cached is an error.

Every file's SHA-256 is checked against the registry; a mismatch is an error naming
the file.
"""

from __future__ import annotations

import functools
import json
import os
import re
from importlib import resources
from pathlib import Path

import xarray as xr

from . import io
from .io.checksums import file_sha256

__all__ = [
    "DataError",
    "registry",
    "data_dir",
    "fetch",
    "broad_trials",
    "broad_trial_groups",
    "broad_trial_kind",
    "broad_coverage",
    "load_broad_trial",
    "load_fayat_example",
    "load_fayat_tumble",
    "citation",
    "load",
    "source_name",
]

ENV_DATA_DIR = "TILTLAB_DATA_DIR"
ENV_CACHE_DIR = "TILTLAB_CACHE_DIR"
ENV_OFFLINE = "TILTLAB_OFFLINE"


class DataError(RuntimeError):
    """A registered file is missing, cannot be fetched, or fails its checksum."""


@functools.cache
def registry() -> dict[str, dict[str, str]]:
    """Return the registry of data files, read once from the package.

    Returns
    -------
    dict
        File name → ``{"sha256", "url", "dataset", "bytes", "license"}``.

    Raises
    ------
    DataError
        A malformed registry entry.
    """
    base = resources.files("tiltlab") / "_registry"
    meta = json.loads((base / "datasets.json").read_text())
    out: dict[str, dict[str, str]] = {}
    lines = (base / "registry.txt").read_text().splitlines()
    for number, line in enumerate(lines, start=1):
        if not line.strip() or line.startswith("#"):
            continue
        where = f"tiltlab registry (_registry/registry.txt), line {number}"
        fields = line.split()
        if len(fields) != 3:
            raise DataError(
                f"{where}: malformed entry {line!r}; expected 'NAME sha256:HEX URL'"
            )
        name, digest, url = fields
        algo, _, h = digest.partition(":")
        if algo != "sha256":
            raise DataError(f"{where}: entry {name}: unsupported hash {algo!r}")
        if not re.fullmatch(r"[0-9a-f]{64}", h):
            raise DataError(f"{where}: entry {name}: {h!r} is not a SHA-256 (64 hex)")
        if name in out:
            raise DataError(f"{where}: {name} is listed twice")
        out[name] = {"sha256": h, "url": url, **meta["files"].get(name, {})}
    if not out:
        raise DataError("tiltlab registry (_registry/registry.txt) has no entries")
    return out


def citation(dataset: str) -> str:
    """Citation of a registered data set (``"broad"`` or ``"fayat2021"``).

    Parameters
    ----------
    dataset : str
        Data set key, ``"broad"`` or ``"fayat2021"``.

    Returns
    -------
    str
        The citation text.

    Raises
    ------
    DataError
        If the data set is unknown.
    """
    meta = json.loads(
        (resources.files("tiltlab") / "_registry" / "datasets.json").read_text()
    )
    try:
        return meta["datasets"][dataset]["citation"]
    except KeyError:
        raise DataError(
            f"unknown data set {dataset!r}; known: {sorted(meta['datasets'])}"
        ) from None


def data_dir() -> Path | None:
    """Return the local mirror named by ``TILTLAB_DATA_DIR``.

    Returns
    -------
    pathlib.Path or None
        The resolved folder, or None when the variable is not set.
    """
    d = os.environ.get(ENV_DATA_DIR)
    return Path(d).expanduser().resolve() if d else None


@functools.lru_cache(maxsize=256)
def _verified(path: str, size: int, mtime_ns: int, expected: str) -> bool:
    return file_sha256(Path(path)) == expected


def verify(path: str | os.PathLike, name: str) -> Path:
    """Check the checksum of ``path`` against the registry entry ``name``.

    Parameters
    ----------
    path : str or path
        A local file.
    name : str
        Its registry file name (a key of :func:`registry`).

    Returns
    -------
    pathlib.Path
        ``path``, verified.

    Raises
    ------
    DataError
        A checksum mismatch.
    """
    path = Path(path)
    entry = registry()[name]
    st = path.stat()
    if not _verified(str(path), st.st_size, st.st_mtime_ns, entry["sha256"]):
        raise DataError(
            f"checksum mismatch for {name} ({path}): its SHA-256 is {file_sha256(path)}, the registry says "
            f"{entry['sha256']}. The file is corrupt, truncated or a different version; delete it "
            "(or repair the mirror) and fetch it again."
        )
    return path


def fetch(name: str, *, progressbar: bool = False) -> Path:
    """Return the local path of a registered file, checksum verified.

    ``name`` is e.g. ``"broad/02_undisturbed_slow_rotation_B.hdf5"``.

    Parameters
    ----------
    name : str
        A registry file name (a key of :func:`registry`).
    progressbar : bool
        Show a download progress bar (default False).

    Returns
    -------
    pathlib.Path
        Path of the verified local file (in the mirror or the cache).

    Raises
    ------
    DataError
        Unknown name; file missing from the mirror; offline and not cached; download
        failure; checksum mismatch.
    """
    reg = registry()
    if name not in reg:
        raise DataError(f"{name!r} is not in the tiltlab data registry")
    mirror = data_dir()
    if mirror is not None:
        path = mirror / name
        if not path.is_file():
            raise DataError(
                f"{name} is not in the local data mirror {mirror} ({ENV_DATA_DIR}); "
                f"unset {ENV_DATA_DIR} to download it from {reg[name]['url']}"
            )
        return verify(path, name)
    import pooch

    cache = Path(os.environ.get(ENV_CACHE_DIR) or pooch.os_cache("tiltlab"))
    target = cache / name
    if os.environ.get(ENV_OFFLINE, "").strip() not in ("", "0"):
        if not target.is_file():
            raise DataError(
                f"{name} is not cached in {cache} and {ENV_OFFLINE} forbids downloading it"
            )
        return verify(target, name)
    try:
        path = pooch.retrieve(
            url=reg[name]["url"],
            known_hash=f"sha256:{reg[name]['sha256']}",
            fname=Path(name).name,
            path=cache / Path(name).parent,
            downloader=pooch.HTTPDownloader(timeout=60, progressbar=progressbar),
        )
    except ValueError as exc:  # pooch's hash mismatch
        raise DataError(
            f"checksum mismatch for {name} downloaded from {reg[name]['url']}: {exc}"
        ) from None
    except Exception as exc:
        raise DataError(
            f"could not download {name} from {reg[name]['url']}: {type(exc).__name__}: {exc}"
        ) from None
    return Path(path)


_TRIAL = re.compile(r"^broad/(\d{2})_(.+)\.(hdf5|mat)$")


def broad_trials() -> dict[int, str]:
    """Return the registered BROAD trials (30 of the 39).

    Returns
    -------
    dict of int to str
        Trial number → registry file name, in increasing order.
    """
    out = {}
    for name in registry():
        m = _TRIAL.match(name)
        if m:
            out[int(m.group(1))] = name
    return dict(sorted(out.items()))


def broad_trial_groups() -> dict[int, list[str]]:
    """Return BROAD's group labels of every registered trial, from ``trials.json``.

    Returns
    -------
    dict of int to list of str
        Trial number → group labels (``undisturbed``, ``rotation``, ``fast`` …).
    """
    info = json.loads(fetch("broad/trials.json").read_text())["trials"]
    out = {}
    for n, name in broad_trials().items():
        key = Path(name).stem
        out[n] = list(info[key]["groups"]) if key in info else []
    return out


def broad_coverage() -> dict[str, list[int]]:
    """Say which of BROAD's trials this installation registers and which it lacks.

    BROAD lists 39 trials in ``trials.json``; the registry holds those whose files could
    be obtained. Chapters that average over BROAD trials use this to state their subset.

    Returns
    -------
    dict of str to list of int
        ``undisturbed`` and ``disturbed``: the registered trial numbers of each kind;
        ``missing_undisturbed`` and ``missing_disturbed``: the trials of each kind that
        ``trials.json`` lists and the registry lacks (all sorted).
    """
    info = json.loads(fetch("broad/trials.json").read_text())["trials"]
    have = set(broad_trials())
    out: dict[str, list[int]] = {
        "undisturbed": [],
        "disturbed": [],
        "missing_undisturbed": [],
        "missing_disturbed": [],
    }
    for key, entry in info.items():
        n = int(key.split("_", 1)[0])
        kind = "undisturbed" if "undisturbed" in entry["groups"] else "disturbed"
        out[kind if n in have else f"missing_{kind}"].append(n)
    return {k: sorted(v) for k, v in out.items()}


_BROAD_MOTIONS = ("rotation", "translation", "combined")


def broad_trial_kind(trial: int, groups: dict[int, list[str]] | None = None) -> str:
    """Name the motion of an undisturbed BROAD trial: its pace and its kind of motion.

    E.g. ``"fast rotation"`` or ``"slow translation"``.

    Parameters
    ----------
    trial : int
        A BROAD trial number.
    groups : dict, optional
        Trial number → group labels, as returned by :func:`broad_trial_groups` (read
        from ``trials.json`` when omitted; pass it to describe many trials).

    Returns
    -------
    str
        ``"<pace> <motion>"``: pace ``"fast"`` for the trials in BROAD's ``fast``
        group, else ``"slow"``; motion the trial's group among ``rotation``,
        ``translation`` and ``combined``.

    Raises
    ------
    DataError
        An unknown trial, or a trial in none of the motion groups (the disturbed
        trials).

    Examples
    --------
    >>> groups = {6: ["all_trials", "undisturbed", "rotation", "fast", "no_breaks"]}
    >>> broad_trial_kind(6, groups)
    'fast rotation'
    """
    groups = broad_trial_groups() if groups is None else groups
    if trial not in groups:
        raise DataError(f"no BROAD trial {trial!r}; trials: {sorted(groups)}")
    labels = groups[trial]
    motion = next((g for g in _BROAD_MOTIONS if g in labels), None)
    if motion is None:
        raise DataError(
            f"BROAD trial {trial} ({', '.join(labels)}) is in none of the motion "
            f"groups {_BROAD_MOTIONS}"
        )
    pace = "fast" if "fast" in labels else "slow"
    return f"{pace} {motion}"


def load_broad_trial(trial: int | str) -> xr.Dataset:
    """Load a BROAD trial by number (e.g. ``2``) or stem (``"02_undisturbed_slow_rotation_B"``).

    Returns a validated Recording with ``acc`` (m/s²), ``gyr`` (rad/s), ``mag`` (µT),
    ``q_ref`` (optical ground truth, NaN where tracking was lost), ``movement`` and
    ``opt_pos``; ``fs`` = 285.714… Hz.

    Parameters
    ----------
    trial : int or str
        A registered BROAD trial number (see :func:`broad_trials`) or its file stem.

    Returns
    -------
    xarray.Dataset
        The validated Recording.

    Raises
    ------
    DataError
        If the trial is not registered or its file cannot be fetched.
    """
    trials = broad_trials()
    if isinstance(trial, str):
        matches = [n for n, name in trials.items() if Path(name).stem == trial]
        if not matches:
            raise DataError(f"no BROAD trial named {trial!r}")
        trial = matches[0]
    if trial not in trials:
        raise DataError(
            f"BROAD trial {trial} is not available; available: {sorted(trials)}"
        )
    return io.read_broad(fetch(trials[trial]))


def load_fayat_example() -> xr.Dataset:
    """Load Fayat et al.'s freely-moving rat head IMU example.

    Returns
    -------
    xarray.Dataset
        The validated Recording: 100 Hz, ``acc`` in g and ``gyr`` in °/s, no ground
        truth.
    """
    return io.read_fayat_imu(fetch("fayat2021/example_imu.csv"))


def load_fayat_tumble() -> xr.Dataset:
    """Load Fayat et al.'s tumble-test recording.

    Returns
    -------
    xarray.Dataset
        The validated Recording: 300 Hz, the sensor still in several orientations.
    """
    return io.read_fayat_tumble(fetch("fayat2021/example_sensor_calibration.csv"))


def load(source: str | os.PathLike, **options) -> xr.Dataset:
    """Load a Recording from a data-source string: the one entry point chapters and the CLI use.

    Parameters
    ----------
    source : str or path
        ``"broad:N"`` (BROAD trial N), ``"fayat:example"`` (rat head IMU, 100 Hz),
        ``"fayat:tumble"`` (tumble test, 300 Hz), or a file that :func:`tiltlab.io.read`
        recognises from its content: a NetCDF Recording written by
        :func:`tiltlab.io.save_netcdf`, a tag-tools NetCDF archive, or a BROAD-layout
        ``.hdf5``/``.h5``/``.mat`` file.
    **options
        For files: reader options of :func:`tiltlab.io.read` (``check_units=False``
        accepts unit labels as they are; ``axes``, ``preset`` for tag-tools files).

    Returns
    -------
    xarray.Dataset
        The Recording, with its ``fs`` and units in attrs.

    Raises
    ------
    DataError
        If the source is neither a known name nor a readable file type.

    Examples
    --------
    The smallest registered recording, read from the mirror named by
    ``TILTLAB_DATA_DIR`` (or downloaded once into the cache):

    >>> import tiltlab.datasets
    >>> rec = tiltlab.datasets.load("fayat:example")
    >>> rec.attrs["fs"], rec.sizes["time"], rec["gyr"].attrs["units"]
    (100.0, 4893, 'deg/s')
    """
    if not isinstance(source, (str, os.PathLike)):
        raise DataError(
            f"source must be a data-source string (broad:N, fayat:example, "
            f"fayat:tumble) or a file path, got {source!r}"
        )
    spec = os.fspath(source)
    if spec.startswith("broad:"):
        trial = spec.split(":", 1)[1]
        return load_broad_trial(int(trial) if trial.isdigit() else trial)
    if spec == "fayat:example":
        return load_fayat_example()
    if spec == "fayat:tumble":
        return load_fayat_tumble()
    path = Path(spec)
    suffix = path.suffix.lower()
    if suffix in (".nc", ".netcdf", ".nc4", ".cdf", ".hdf5", ".h5", ".mat"):
        if path.is_dir():
            raise DataError(f"source {spec!r}: is a directory, not a file")
        if not path.exists():
            raise DataError(f"source {spec!r}: no such file")
        return io.read(path, **options)
    raise DataError(
        f"don't know how to read {spec!r}: use broad:N, fayat:example, fayat:tumble, "
        "or a .nc / .hdf5 / .mat file (tiltlab.io.detect says what a file looks like)"
    )


def source_name(source: str | os.PathLike) -> str:
    """Name a data source as a reader sees it: a trial name, or a file name.

    Chapters print this in place of the full source, so that a path to a local file
    does not spill the folder it lives in into the book.

    Parameters
    ----------
    source : str or path
        A data-source string as :func:`load` takes it (``"broad:2"``,
        ``"fayat:example"``) or the path of a file.

    Returns
    -------
    str
        The source unchanged when it names no file (no suffix), else the file's name
        without its folder.

    Examples
    --------
    >>> source_name("broad:2")
    'broad:2'
    >>> source_name("/data/lab/rat7_day3.nc")
    'rat7_day3.nc'
    """
    text = os.fspath(source) if isinstance(source, os.PathLike) else str(source)
    path = Path(text)
    return path.name if path.suffix else text
