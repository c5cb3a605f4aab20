"""Estimate orientation with learned networks (Zaheer et al. 2023).

A dilated 1-D CNN fusing gyro-integrated quaternions with accelerometer and
magnetometer windows, its learned-gain variant, their losses, RAdam + Lookahead
training with augmentations, closed-loop inference and grouped cross-validation on
BROAD.

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

import tiltlab.learn.data as _data
import tiltlab.learn.model as _model
import tiltlab.learn.optim as _optim
import tiltlab.learn.published as _published
import tiltlab.learn.tables as _tables
import tiltlab.learn.training as _training
import tiltlab.learn.files as _files

from .data import Sequence, sequence, window_ends
from .losses import LOSSES, TOTALS, qae, sample_loss, total_loss
from .model import ACTIVATIONS, OrientationCNN
from .optim import Lookahead, radam_lookahead
from .training import TrainConfig, build_model, closed_loop_estimate
from .training import closed_loop_estimates, train, validation_error
from .files import SUMS_FILE, load_model, read_sums, save, sha256
from .training import run  # the old name, for one release
from .files import load  # the old name, for one release
from .published import ZAHEER_TABLE2, ZAHEER_TABLE3
from .cv import BASELINES, ERROR_COLUMNS, check_files, compare, compare_summary
from .cv import cross_validate, folds, learned_estimate
from .baselines import BASELINE_GRIDS, PARAMS_FILE, TUNED_BASELINES, load_tuned
from .baselines import save_tuned, tune_baselines, tuned_compare, tuned_summary
import tiltlab.learn.gain_schedule as _gain_schedule
from .gain_schedule import GAIN_LABELS, GainTrial, fit_standardisation, gain_compare
from .gain_schedule import gain_trial
from .gain_schedule import schedule_loss, train_schedule
from .tables import config_table, layer_settings, layer_table

# every public name of data, model, optim, training, files (but write_json), published
# and tables; of losses, cv and baselines, those listed here
__all__ = [
    *_data.__all__,
    "LOSSES",
    "TOTALS",
    "qae",
    "sample_loss",
    "total_loss",
    *_model.__all__,
    *_optim.__all__,
    *_training.__all__,
    *[n for n in _files.__all__ if n != "write_json"],
    "BASELINES",
    "ERROR_COLUMNS",
    "check_files",
    "compare",
    "compare_summary",
    "cross_validate",
    "folds",
    "learned_estimate",
    "BASELINE_GRIDS",
    "PARAMS_FILE",
    "TUNED_BASELINES",
    "load_tuned",
    "save_tuned",
    "tune_baselines",
    "tuned_compare",
    "tuned_summary",
    *_published.__all__,
    *_tables.__all__,
    *_gain_schedule.__all__,
]
