"""Learned orientation estimation (Zaheer et al. 2023): a dilated 1-D CNN fusing
gyro-integrated quaternions with accelerometer and magnetometer windows, its
learned-gain variant, their losses, RAdam + Lookahead training with augmentations,
closed-loop inference and grouped cross-validation on BROAD.

Needs the optional extra ``learn`` (CPU PyTorch): ``pip install tiltlab[learn]``.
Command line: ``python -m tiltlab.learn train --help``.

References
----------
.. [1] M. H. Zaheer, S. Y. Yoon and B. K. Higginson, "Orientation estimation for
   instrumented helmet using neural networks", Meas. Control 56:1156–1167, 2023.
   doi:10.1177/00202940221149062
"""

from __future__ import annotations

try:
    import torch  # noqa: F401
except ImportError as err:  # pragma: no cover - depends on the environment
    raise ImportError(
        "tiltlab.learn needs PyTorch: install the 'learn' extra "
        "(pip install 'tiltlab[learn]')"
    ) from err

from .data import Sequence, sequence, window_ends
from .losses import LOSSES, TOTALS, qae, sample_loss, total_loss
from .model import ACTIVATIONS, OrientationCNN
from .optim import Lookahead, radam_lookahead
from .training import (
    TrainConfig,
    build_model,
    load,
    read_sums,
    run,
    save,
    sha256,
    train,
)
from .published import ZAHEER_TABLE2, ZAHEER_TABLE3
from .cv import BASELINES, check_files, compare, cross_validate, folds, learned_estimate
from .tables import config_table, layer_settings, layer_table

__all__ = [
    "Sequence",
    "sequence",
    "window_ends",
    "LOSSES",
    "TOTALS",
    "qae",
    "sample_loss",
    "total_loss",
    "ACTIVATIONS",
    "OrientationCNN",
    "Lookahead",
    "radam_lookahead",
    "TrainConfig",
    "build_model",
    "train",
    "run",
    "save",
    "load",
    "sha256",
    "read_sums",
    "BASELINES",
    "check_files",
    "compare",
    "cross_validate",
    "folds",
    "learned_estimate",
    "ZAHEER_TABLE2",
    "ZAHEER_TABLE3",
    "config_table",
    "layer_settings",
    "layer_table",
]
