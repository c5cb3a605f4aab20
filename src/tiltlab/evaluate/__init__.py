r"""Evaluation of tilt estimates against a reference, and parameter selection.

Per-sample errors, Table-1 statistics, error versus angular speed, empirical CDFs, per-trial error tables and leave-one-trial-out (LOTO)
parameter selection.

Error definitions
-----------------
The tilt error of an estimate is the angle between the estimated and the reference
gravity-up directions in the sensor frame,

.. math::
    \epsilon_k = \arccos\big(\hat g_k \cdot g^{\mathrm{ref}}_k\big),
    \qquad g = R(q)^\top e_z ,

which equals BROAD's inclination error :math:`2\arccos\sqrt{e_w^2 + e_z^2}` of the
error quaternion :math:`e = q \otimes q_{\mathrm{ref}}^{-1}` [2]_ (the heading part of
:math:`e` does not move :math:`e_z`). Fayat et al. [1]_ report the distribution of
:math:`\epsilon_k` (mean, standard deviation, median, Q25, Q75, Q95) during immobility
and movement separately (their Table 1); BROAD reports the RMS over the samples marked
``movement``.

Leave-one-trial-out selection
-----------------------------
For a score array :math:`S(\theta, r)` over a parameter grid :math:`\theta` and trials
:math:`r`, the held-out score of trial :math:`r` is :math:`S(\hat\theta_{-r}, r)` with
:math:`\hat\theta_{-r} = \arg\min_\theta \frac{1}{R-1}\sum_{r' \ne r} S(\theta, r')`:
parameters are never chosen on the trial they are scored on. The "all-trials
optimum" :math:`\min_\theta \bar S(\theta)` is optimistic (selection on the test data).

References
----------
.. [1] R. Fayat, V. Delgado Betancourt, T. Goyallon, M. Petremann, P. Liaudet,
   V. Descossy, L. Reveret, G. P. Dugué, "Inertial measurement of head tilt in
   rodents: principles and applications to vestibular research", Sensors 21(18):6318,
   2021. doi:10.3390/s21186318
.. [2] D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust
   Inertial Orientation Estimation", Data 6(7):72, 2021. doi:10.3390/data6070072

Modules
-------
:mod:`~tiltlab.evaluate.errors` (error definitions and statistics, BROAD's RMSEs),
:mod:`~tiltlab.evaluate.selection` (grid search over methods' parameters, LOTO),
:mod:`~tiltlab.evaluate.recipes` (a grid's best parameters, methods as estimators,
the tilt difference between two methods, errors pooled over recordings),
:mod:`~tiltlab.evaluate.mocap` (the motion-capture reference),
:mod:`~tiltlab.evaluate.speed` (error against angular speed: slope, crossover) and
:mod:`~tiltlab.evaluate.budget` (what bounds an estimate's error: its slow and fast
parts, and how far estimates can differ).
"""

import warnings as _warnings

from .._stack import user_stacklevel
from .errors import (
    FAYAT_TABLE1,
    MOTION_STATES,
    STATISTICS,
    binned_by_speed,
    broad_errors,
    ecdf,
    error_stats,
    error_summary,
    pairwise_tilt_rms,
    shift_quaternions,
    shifted_score,
    state_scores,
    table1,
    tilt_errors,
    tilt_rmse,
)
from .budget import error_budget
from .mocap import mocap_reference
from .recipes import best_params, estimator, pooled_errors, tilt_difference_rms
from .selection import error_table, grid_search, loto, loto_summary, optimum
from .speed import crossover_speed, speed_slope

from .budget import __all__ as _budget_all
from .errors import __all__ as _errors_all
from .mocap import __all__ as _mocap_all
from .recipes import __all__ as _recipes_all
from .selection import __all__ as _selection_all
from .speed import __all__ as _speed_all

__all__ = [
    *_errors_all,
    *_selection_all,
    *_recipes_all,
    *_mocap_all,
    *_budget_all,
    *_speed_all,
]


def __getattr__(name: str):
    """Return ``STATES``, the old name of :data:`MOTION_STATES`, with a warning."""
    if name == "STATES":
        _warnings.warn(
            "tiltlab.evaluate.STATES was renamed MOTION_STATES (tiltlab.simulate.STATES "
            "is another thing); the old name goes in the next release",
            FutureWarning,
            stacklevel=user_stacklevel(),
        )
        return MOTION_STATES
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
