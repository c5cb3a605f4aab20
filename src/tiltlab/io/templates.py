"""Mappings shipped with tiltlab for public recordings from other labs."""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

__all__ = ["TEMPLATES", "mapping_template"]

#: Mappings for public recordings made by other labs, by name (see
#: :func:`mapping_template`).
TEMPLATES: tuple[str, ...] = ("sunsided_board", "twlogger_tag", "gaitmap_foot")


def mapping_template(name: str) -> dict[str, Any]:
    """Return a mapping shipped with tiltlab for a public recording from another lab.

    Each is a worked example of one kind of export: ``"sunsided_board"`` (one MATLAB
    v7.3 file per sensor on separate bursty clocks, gravity-signed accelerometer and
    reversed gyroscope axes), ``"twlogger_tag"`` (a bio-logging tag's CSV with an
    accelerometer and magnetometer only, raw counts and a jittery millisecond clock)
    and ``"gaitmap_foot"`` (a CSV with a two-row header, no time column). The
    ``description`` key says what is inferred rather than documented.

    Parameters
    ----------
    name : str
        One of :data:`TEMPLATES`.

    Returns
    -------
    dict
        A new mapping (edit it freely), for :func:`tiltlab.io.read` /
        :func:`tiltlab.io.read_csv` / :func:`tiltlab.io.read_multi` or, saved as
        JSON, ``tiltlab convert --mapping``.

    Examples
    --------
    >>> from tiltlab import io
    >>> sorted(io.mapping_template("sunsided_board")["files"])
    ['acc', 'gyr', 'mag']
    """
    if name not in TEMPLATES:
        raise ValueError(
            f"unknown mapping template {name!r}; known: {', '.join(TEMPLATES)}"
        )
    text = resources.files("tiltlab").joinpath("_mappings", f"{name}.json").read_text()
    return json.loads(text)
