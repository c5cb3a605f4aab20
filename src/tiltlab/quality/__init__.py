"""Data quality: sensor saturation, and whether the values are plausible for their units.

What belongs here: every data-quality finding (saturation, raw counts, values that
contradict their unit labels, among them the one gyroscope-unit check
:func:`check_gyr_units`), the :class:`Finding` record and the policy that raises or warns
them. What does not: what a Recording is (:mod:`tiltlab.schema`), argument checks
(:mod:`tiltlab._validate`) and unit conversions (:mod:`tiltlab.units`).

Layer 1, beside :mod:`tiltlab.units` and :mod:`tiltlab.schema` (which runs these checks
in :func:`tiltlab.schema.validate`). Everything here is cheap — medians, percentiles and
run lengths, O(N) — so that every Recording can be checked when it is built.

Findings and the validation policy
----------------------------------
Each check returns a :class:`Finding` (or ``None``) naming the variable and the problem,
with a severity that follows :mod:`tiltlab._validate`'s policy:

* **error** — the numbers would be wrong by a known, large factor and the evidence is
  unambiguous: an accelerometer labelled g whose median magnitude is ~9.8 (m/s²) or
  labelled m/s² with a median of ~1 (g); raw ADC counts (or values far beyond any
  physical range); a gyroscope labelled rad/s whose 99th percentile is beyond any MEMS
  gyroscope's full scale (°/s), or labelled °/s although it integrates to a fraction of
  the tilt the accelerometer sees (rad/s); a temperature labelled °C that is plainly in
  kelvin (or the reverse). :func:`tiltlab.schema.validate` raises
  :class:`~tiltlab._validate.RecordingError` with the message.
* **warning** (:class:`QualityWarning`) — the data are usable but doubtful, or the
  evidence is not decisive: clipped (saturated) samples, a median acceleration far from
  1 g that no unit mistake explains, a gyroscope 99th percentile between 40 and 100
  rad/s, a temperature outside the −40…85 °C operating range of MEMS sensors, a full
  scale attribute the data exceed.

:func:`assess` returns every finding of a Recording without raising or warning;
:func:`emit` raises the errors and warns the rest.
"""

from __future__ import annotations

from ._common import (
    QualityWarning,
    UnitCheckError,
    UNIT_CHECK_SWITCH,
    Finding,
    ACC_MEDIAN_G,
    ACC_COUNTS_G,
    GYR_COUNTS_DEG_S,
    MAG_COUNTS_UT,
    GYR_RAD_S_P99,
    TEMP_RANGE_DEGC,
)
from .clipping import (
    saturation,
    full_scale,
    limits,
    check_saturation,
    check_raw_counts,
)
from .unitcheck import (
    check_acc_units,
    check_gyr_units,
    check_temperature,
    GYR_WINDOW_S,
    GYR_MIN_TILT_DEG,
    GYR_DECISIVE_SHARE,
)
from .assess import (
    plausibility,
    assess,
    emit,
)

__all__ = [
    "QualityWarning",
    "UnitCheckError",
    "UNIT_CHECK_SWITCH",
    "Finding",
    "saturation",
    "full_scale",
    "limits",
    "check_saturation",
    "check_raw_counts",
    "check_acc_units",
    "check_gyr_units",
    "check_temperature",
    "plausibility",
    "assess",
    "emit",
    "ACC_MEDIAN_G",
    "ACC_COUNTS_G",
    "GYR_COUNTS_DEG_S",
    "MAG_COUNTS_UT",
    "GYR_RAD_S_P99",
    "GYR_WINDOW_S",
    "GYR_MIN_TILT_DEG",
    "GYR_DECISIVE_SHARE",
    "TEMP_RANGE_DEGC",
]
