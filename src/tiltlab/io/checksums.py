"""SHA-256 digests of files and ``SHA256SUMS`` lists (the ``sha256sum`` format).

A folder of saved results (model weights, feature tables) carries a ``SHA256SUMS``
file, one ``<digest>  <name>`` line per file; :func:`check_sums` verifies every file it
lists and refuses a folder whose files changed. One parser and one writer serve every
such folder of the package.
"""

from __future__ import annotations

import hashlib
import os
import re
from collections.abc import Mapping
from pathlib import Path

from ._common import IntegrityError

__all__ = ["SUMS_FILE", "file_sha256", "read_sums", "check_sums", "write_sums"]

#: Name of the checksum file of a folder (``sha256sum`` format).
SUMS_FILE = "SHA256SUMS"
_SUMS_LINE = re.compile(r"([0-9A-Fa-f]{64}) ([ *])(.+)")


def file_sha256(path: str | os.PathLike) -> str:
    """Return the SHA-256 of a file's content, read in 1 MiB chunks.

    Parameters
    ----------
    path : str or path
        The file.

    Returns
    -------
    str
        The digest, 64 lowercase hexadecimal digits (``bytes.fromhex`` gives the raw
        digest).
    """
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def read_sums(path: str | Path) -> dict[str, str]:
    """Parse a ``SHA256SUMS`` file (the format of ``sha256sum``): name -> sha256.

    Each line is 64 hex digits, a space, then a space (text mode) or ``*`` (binary
    mode), then the file name, relative to the file's folder. Blank lines are
    ignored; anything else is an error.

    Parameters
    ----------
    path : str or pathlib.Path
        The ``SHA256SUMS`` file.

    Returns
    -------
    dict
        File name (str, relative to the file's folder) -> SHA-256 hex digest (str,
        lower case).

    Raises
    ------
    tiltlab.io.IntegrityError
        (a ``ValueError`` and an ``OSError``) naming the file and the line: a
        malformed line, a name listed twice, a name outside the folder (absolute, or
        with ``..``), or no entry at all (an empty file); a missing or unreadable file.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise IntegrityError(
            f"{path}: cannot read checksum file ({exc})", path=path
        ) from None
    out: dict[str, str] = {}
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        m = _SUMS_LINE.fullmatch(line)
        if m is None:
            shown = line if len(line) <= 80 else line[:77] + "..."
            raise IntegrityError(
                f"{path}, line {number}: malformed checksum line {shown!r}; expected "
                "64 hex digits, two spaces (or a space and '*') and a file name",
                path=path,
            )
        digest, _, name = m.groups()
        parts = Path(name).parts
        if Path(name).is_absolute() or ".." in parts or not parts:
            raise IntegrityError(
                f"{path}, line {number}: {name!r} is not a file name inside "
                f"{path.parent}",
                path=path,
            )
        if name in out:
            raise IntegrityError(
                f"{path}, line {number}: {name!r} is listed twice", path=path
            )
        out[name] = digest.lower()
    if not out:
        raise IntegrityError(
            f"{path}: empty checksum file (no entries): nothing would be verified",
            path=path,
        )
    return out


def check_sums(folder: str | os.PathLike) -> dict[str, str]:
    """Verify every file listed in ``folder/SHA256SUMS``; return name -> sha256.

    Parameters
    ----------
    folder : str or os.PathLike
        Folder holding ``SHA256SUMS`` and the files it lists.

    Returns
    -------
    dict
        File name -> verified SHA-256 (hex).

    Raises
    ------
    tiltlab.io.IntegrityError
        (a ``ValueError`` and an ``OSError``) naming the problem: no ``SHA256SUMS``,
        a malformed one (:func:`read_sums`), a listed file that is missing, or one
        whose digest differs.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from tiltlab.io import check_sums, file_sha256, write_sums
    >>> d = Path(tempfile.mkdtemp())
    >>> _ = (d / "a.txt").write_text("tilt")
    >>> write_sums(d, {"a.txt": file_sha256(d / "a.txt")})
    >>> list(check_sums(d))
    ['a.txt']
    """
    folder = Path(folder)
    sums = folder / SUMS_FILE
    if not sums.is_file():
        raise IntegrityError(f"no {SUMS_FILE} in {folder}", path=sums)
    out = {}
    for name, digest in read_sums(sums).items():
        path = folder / name
        if not path.is_file():
            raise IntegrityError(f"{name} is listed in {sums} but missing", path=path)
        got = file_sha256(path)
        if got != digest:
            raise IntegrityError(
                f"{name}: sha256 {got} differs from {sums} ({digest}): the file is "
                "corrupt or was altered",
                path=path,
            )
        out[name] = got
    return out


def write_sums(folder: str | os.PathLike, digests: Mapping[str, str]) -> None:
    """Write ``folder/SHA256SUMS`` listing ``digests`` (name -> sha256), sorted by name.

    Parameters
    ----------
    folder : str or os.PathLike
        The folder (it must exist).
    digests : mapping of str to str
        File name (inside ``folder``) -> SHA-256 hex digest.
    """
    lines = [f"{digests[n]}  {n}" for n in sorted(digests)]
    (Path(folder) / SUMS_FILE).write_text("\n".join(lines) + "\n")
