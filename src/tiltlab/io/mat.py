"""MATLAB ``.mat`` files: one numeric variable at a time, any version.

Versions 4 to 7 are read with :func:`scipy.io.loadmat`; version 7.3 files are HDF5
files with a 512-byte MATLAB header and are read with :mod:`h5py`. HDF5 stores
MATLAB's column-major arrays with their dimensions reversed, so h5py sees the
transpose of what MATLAB shows; :func:`read_matrix` undoes that and always returns
the array in the shape MATLAB's ``size`` reports.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._common import PathLike, ReadError, file_head, no_file

#: MATLAB classes that hold numbers (``logical`` included: it reads as 0/1).
_NUMERIC_CLASSES = frozenset(
    {
        "double",
        "single",
        "int8",
        "int16",
        "int32",
        "int64",
        "uint8",
        "uint16",
        "uint32",
        "uint64",
        "logical",
    }
)


def mat_version(path: PathLike) -> str | None:
    """Read the MATLAB file version from the file header; None if not a MAT-file.

    Parameters
    ----------
    path : path-like
        The file; its first 128 bytes, the MAT-file header, are read.

    Returns
    -------
    str or None
        ``"7.3"`` for HDF5-based files, ``"5"`` for versions 5 to 7 (same container),
        ``"4"`` for the old headerless layout when scipy recognises it, None otherwise.
    """
    path = Path(path)
    head = file_head(path, 128)
    if head is None:
        return None
    if head.startswith(b"MATLAB 7.3 MAT-file"):
        return "7.3"
    if head.startswith(b"MATLAB 5.0 MAT-file") or head.startswith(b"MATLAB"):
        return "5"
    if path.suffix.lower() == ".mat":
        try:
            import scipy.io.matlab as sm

            major, _ = sm.matfile_version(str(path))
        except Exception:  # noqa: BLE001 - any failure means "not recognised"
            return None
        return {0: "4", 1: "5", 2: "7.3"}.get(major)
    return None


def _describe(name: str, shape: tuple[int, ...], cls: str) -> str:
    dims = "×".join(str(int(s)) for s in shape) if shape else "scalar"
    return f"{name}({dims} {cls})"


def list_variables(path: PathLike) -> list[tuple[str, tuple[int, ...], str]]:
    """List the variables of a MATLAB file: ``(name, MATLAB shape, MATLAB class)`` each.

    Parameters
    ----------
    path
        A ``.mat`` file of any version.

    Returns
    -------
    list of tuple
        One entry per top-level variable, in file order. Shapes are as MATLAB's
        ``size`` reports them (not transposed).

    Raises
    ------
    ReadError
        If the file is missing, not a MAT-file, truncated or corrupt.
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    version = mat_version(path)
    if version == "7.3":
        import h5py

        out = []
        try:
            with h5py.File(path, "r") as f:
                for name, obj in f.items():
                    if name.startswith("#"):
                        continue  # MATLAB's internal reference/subsystem groups
                    if isinstance(obj, h5py.Dataset):
                        cls = obj.attrs.get("MATLAB_class", b"")
                        cls = cls.decode() if isinstance(cls, bytes) else str(cls)
                        shape = tuple(int(s) for s in obj.shape[::-1])
                        if obj.attrs.get("MATLAB_empty", 0):
                            shape = (0,) * max(len(shape), 2)
                        out.append((name, shape, cls or str(obj.dtype)))
                    else:
                        cls = obj.attrs.get("MATLAB_class", b"struct")
                        cls = cls.decode() if isinstance(cls, bytes) else str(cls)
                        out.append((name, (1, 1), cls))
        except OSError as exc:
            raise ReadError(
                f"{path}: cannot read MATLAB v7.3 (HDF5) file ({exc}); truncated or corrupt?"
            ) from None
        return out
    import scipy.io

    try:
        info = scipy.io.whosmat(str(path))
    except Exception as exc:  # noqa: BLE001 - scipy raises many types on damage
        raise ReadError(
            f"{path}: cannot read MATLAB file ({type(exc).__name__}: {exc}); "
            "truncated, corrupt or not a MAT-file?"
        ) from None
    return [(name, tuple(int(s) for s in shape), cls) for name, shape, cls in info]


def describe_mat(path: PathLike) -> str:
    """One line naming a MATLAB file's version and variables, e.g. for ``tiltlab info``.

    Parameters
    ----------
    path
        A ``.mat`` file.

    Returns
    -------
    str
        E.g. ``"MATLAB v7.3 file with variables accelBuffer(12243×4 double)"``.
    """
    version = mat_version(path) or "?"
    variables = list_variables(path)
    listed = ", ".join(_describe(*v) for v in variables) or "no variables"
    return f"MATLAB v{version} file with variables {listed}"


def read_matrix(path: PathLike, variable: str | None = None) -> np.ndarray:
    """Read one numeric variable from a MATLAB file, in MATLAB's own shape.

    Parameters
    ----------
    path
        A ``.mat`` file, version 4 to 7 (read with scipy) or 7.3 (HDF5, read with h5py).
    variable
        Name of the variable. None picks the only numeric variable of the file and
        refuses, listing them, when there are several or none.

    Returns
    -------
    numpy.ndarray
        The array as MATLAB's ``size`` shows it (a v7.3 file's HDF5 transpose is
        undone), at least 2-D like every MATLAB array; ``logical`` becomes bool.

    Raises
    ------
    ReadError
        If the file is missing, damaged, not a MAT-file, the variable is absent or not
        numeric (struct, cell, char), or the choice is ambiguous.

    Examples
    --------
    >>> import numpy as np, scipy.io, tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "x.mat")
    >>> scipy.io.savemat(p, {"acc": np.arange(6.0).reshape(2, 3)})
    >>> read_matrix(p).shape
    (2, 3)
    """
    path = Path(path)
    variables = list_variables(path)  # raises ReadError on missing/damaged files
    numeric = [v for v in variables if v[2] in _NUMERIC_CLASSES]
    listing = ", ".join(_describe(*v) for v in variables) or "none"
    if variable is None:
        if len(numeric) != 1:
            what = "no numeric variable" if not numeric else "several numeric variables"
            raise ReadError(f"{path}: {what}; give variable=NAME, one of: {listing}")
        variable = numeric[0][0]
    else:
        found = [v for v in variables if v[0] == variable]
        if not found:
            raise ReadError(
                f"{path}: no variable {variable!r}; variables in the file: {listing}"
            )
        if found[0][2] not in _NUMERIC_CLASSES:
            raise ReadError(
                f"{path}: variable {variable!r} is a MATLAB {found[0][2]}, not a numeric "
                f"array; numeric variables: "
                + (", ".join(_describe(*v) for v in numeric) or "none")
            )
    if mat_version(path) == "7.3":
        import h5py

        try:
            with h5py.File(path, "r") as f:
                ds = f[variable]
                if ds.attrs.get("MATLAB_empty", 0):
                    return np.zeros((0, 0))
                arr = np.asarray(ds[()])
                cls = ds.attrs.get("MATLAB_class", b"")
        except (OSError, KeyError) as exc:
            raise ReadError(
                f"{path}: cannot read {variable!r} ({exc}); truncated or corrupt?"
            ) from None
        cls = cls.decode() if isinstance(cls, bytes) else str(cls)
        if arr.dtype.names and {"real", "imag"} <= set(arr.dtype.names):
            arr = arr["real"] + 1j * arr["imag"]
        arr = arr.T
        if cls == "logical":
            arr = arr.astype(bool)
    else:
        import scipy.io

        try:
            m = scipy.io.loadmat(str(path), variable_names=[variable])
        except Exception as exc:  # noqa: BLE001
            raise ReadError(
                f"{path}: cannot read {variable!r} ({type(exc).__name__}: {exc}); "
                "truncated or corrupt?"
            ) from None
        arr = np.asarray(m[variable])
    if arr.ndim < 2:
        arr = arr.reshape((1,) * (2 - arr.ndim) + arr.shape)
    return arr
