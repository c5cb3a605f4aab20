"""Save, load and verify the learned models' files: weights with a digest, checksums.

A model file holds the weights, the configuration and the sampling rate, with a digest
of the weights that :func:`load_model` verifies; ``SHA256SUMS`` files list the digest of
every file of a training run, in ``sha256sum`` format.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path
from typing import Any

import torch

from .._stack import user_stacklevel
from .. import _deprecate
from ..datasets import file_sha256
from ..io import IntegrityError
from ..io.checksums import SUMS_FILE, read_sums
from .model import OrientationCNN
from .training import TrainConfig, build_model

__all__ = [
    "save",
    "load_model",
    "load",
    "sha256",
    "read_sums",
    "write_json",
    "SUMS_FILE",
]


def sha256(path: str | Path) -> str:
    """SHA-256 of a file (hex), read once in 1 MiB blocks.

    Parameters
    ----------
    path : str or pathlib.Path
        File to hash.

    Returns
    -------
    str
        Hex digest (64 lower-case characters).
    """
    return file_sha256(path)


def _state_digest(blob: dict[str, Any]) -> str:
    """Hash what a model file holds with SHA-256.

    SHA-256 of what a model file holds: configuration, ``fs`` and every tensor's
    name, dtype, shape and bytes.
    """
    h = hashlib.sha256()
    head = {"config": blob["config"], "fs": float(blob["fs"])}
    h.update(json.dumps(head, sort_keys=True, default=str).encode() + b"\0")
    for name in sorted(blob["state"]):
        t = blob["state"][name]
        if not torch.is_tensor(t):
            h.update(json.dumps([name, repr(t)]).encode() + b"\0")
            continue
        t = t.detach().cpu().contiguous()
        h.update(json.dumps([name, str(t.dtype), list(t.shape)]).encode() + b"\0")
        h.update(t.reshape(-1).view(torch.uint8).numpy())
    return h.hexdigest()


def save(
    model: OrientationCNN, config: TrainConfig, fs: float, path: str | Path
) -> str:
    """Write the weights (``path``, a ``.pt`` state dict) and return their sha256.

    The file also holds the SHA-256 of its content (configuration, ``fs``, every
    tensor), which :func:`load_model` checks; the returned sha256 of the whole file is the
    one to list in the folder's ``SHA256SUMS`` (:func:`tiltlab.learn.cross_validate`
    does).

    Parameters
    ----------
    model : OrientationCNN
        Network whose weights are written.
    config : TrainConfig
        Its training configuration, stored with the weights.
    fs : float
        Sampling rate (Hz) it was trained at.
    path : str or pathlib.Path
        Output ``.pt`` file (its folder is created if needed).

    Returns
    -------
    str
        SHA-256 hex digest of the written file.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    blob = {"state": model.state_dict(), "config": config.to_dict(), "fs": float(fs)}
    blob["sha256"] = _state_digest(blob)
    torch.save(blob, path)
    return sha256(path)


def load_model(
    path: str | Path, *, sha256: str | None = None, verify: bool = True
) -> tuple[OrientationCNN, TrainConfig, float]:
    """Read weights written by :func:`save`.

    Gives the model (evaluation mode), its configuration and the sampling rate it was
    trained at.
    The file is checked first against its recorded sha256: ``sha256`` if given, else
    its entry in ``SHA256SUMS`` beside it (the committed models, :func:`cross_validate`
    folders); then against the digest of its content stored by :func:`save`. A file
    with neither record (saved before they existed, alone) loads with a warning.

    Parameters
    ----------
    path : path
        A ``.pt`` file written by :func:`save`.
    sha256 : str, optional
        The expected SHA-256 of the whole file (hex).
    verify : bool
        Check the recorded checksums (default). ``verify=False`` loads a file that
        fails them, e.g. to inspect it; never use such a model for results.

    Returns
    -------
    model : OrientationCNN
        The network, in evaluation mode.
    config : TrainConfig
        Its training configuration.
    fs : float
        Sampling rate (Hz) it was trained at.

    Raises
    ------
    tiltlab.io.IntegrityError
        (a ``ValueError``) naming the file: its sha256 differs from the recorded one,
        its content from the digest saved in it, or ``SHA256SUMS`` is malformed.
    """
    path = Path(path)
    expected, source = None, None
    if verify:
        if sha256 is not None:
            expected, source = str(sha256).strip().lower(), "the expected sha256"
        elif (path.parent / SUMS_FILE).is_file():
            sums = read_sums(path.parent / SUMS_FILE)
            if path.name in sums:
                expected, source = sums[path.name], str(path.parent / SUMS_FILE)
        if expected is not None:
            got = _file_sha256(path)
            if got != expected:
                raise IntegrityError(
                    f"{path}: model weights refused, sha256 {got} differs from "
                    f"{source} ({expected}): the file is corrupt or was altered "
                    "(load_model(path, verify=False) reads it anyway, to inspect it)",
                    path=path,
                )
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
    except FileNotFoundError:
        raise
    except Exception as exc:  # noqa: BLE001 - torch raises many types on damage
        raise IntegrityError(
            f"{path}: not a readable model file ({type(exc).__name__}: {exc})",
            path=path,
        ) from None
    stored = blob.get("sha256") if isinstance(blob, dict) else None
    if verify and stored is not None and _state_digest(blob) != stored:
        raise IntegrityError(
            f"{path}: model weights refused, their content differs from the sha256 "
            "saved with them: the file is corrupt or was altered "
            "(load_model(path, verify=False) reads it anyway, to inspect it)",
            path=path,
        )
    if verify and stored is None and expected is None:
        warnings.warn(
            f"{path}: no recorded sha256 (no SHA256SUMS entry, saved before tiltlab "
            "stored one): the weights are not checked",
            stacklevel=user_stacklevel(),
        )
    cfg = TrainConfig.from_dict(blob["config"])
    model = build_model(cfg, blob["fs"])
    model.load_state_dict(blob["state"])
    model.eval()
    return model, cfg, float(blob["fs"])


_file_sha256 = sha256  # ``load_model`` has a parameter of that name


def write_json(obj: Any, path: str | Path) -> None:
    """Write ``obj`` as indented JSON with sorted keys and a final newline.

    Parameters
    ----------
    obj : object
        JSON-serialisable value.
    path : str or pathlib.Path
        File written.
    """
    Path(path).write_text(json.dumps(obj, indent=1, sort_keys=True) + "\n")


#: the old name, for one release
load = _deprecate.alias(load_model, "load")
