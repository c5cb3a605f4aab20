"""Regularly spaced GNSS anchors for dead reckoning (Benhamou 2023 §8).

:func:`anchor_steps` places a fix every ``every`` steps (and on the last position);
:func:`dead_reckon_every` reconstructs a path anchored on such fixes of a known track,
the experiment behind :func:`~tiltlab.trig.anchored_errors`.
"""

from __future__ import annotations

import numpy as np

import tiltlab._validate as _v
from ..frames import _vec3
from .deadreckoning import dead_reckon

__all__ = ["anchor_steps", "dead_reckon_every"]


def anchor_steps(n_steps: int, every: int) -> np.ndarray:
    """Step indices of anchors every ``every`` steps, from 0 to ``n_steps`` included.

    Parameters
    ----------
    n_steps : int
        Number of steps N of the path (N + 1 positions).
    every : int
        Anchor spacing (steps), at least 1.

    Returns
    -------
    ndarray of int
        ``0, every, 2 every, ...`` and ``n_steps``: the ``anchor_steps`` that
        :func:`~tiltlab.trig.dead_reckon` takes.

    Examples
    --------
    >>> anchor_steps(10, 4)
    array([ 0,  4,  8, 10])
    """
    n_steps = _v.integer(n_steps, "n_steps", minimum=1)
    every = _v.integer(every, "every", minimum=1)
    return np.unique(np.r_[np.arange(0, n_steps, every), n_steps])


def dead_reckon_every(
    truth, speed, az, el, every: int
) -> tuple[np.ndarray, np.ndarray]:
    """Dead reckoning (Eq. 17) anchored on a known track every ``every`` steps.

    Parameters
    ----------
    truth : array_like, shape (N+1, 3)
        True positions (m, local ENU); those at the anchor steps are the fixes.
    speed, az, el : array_like, shape (N,)
        Per-step speed proxy (any positive scale), azimuth and elevation (rad), e.g.
        noisy sensor estimates.
    every : int
        Anchor spacing (steps).

    Returns
    -------
    steps : ndarray of int
        The anchor steps, :func:`anchor_steps` ``(N, every)``.
    positions : ndarray, shape (N+1, 3)
        The reconstructed path; ``positions[steps]`` equals ``truth[steps]`` up to
        rounding.

    See Also
    --------
    tiltlab.trig.dead_reckon : the reconstruction between arbitrary anchors.
    tiltlab.trig.anchored_errors : its error against ``truth`` for several spacings.
    """
    truth = _vec3(truth, "truth")
    steps = anchor_steps(truth.shape[0] - 1, every)
    return steps, dead_reckon(speed, az, el, truth[steps], steps)
