"""The most used entry points show a worked example, and the example runs.

Each function below has an ``Examples`` section whose examples are executed here
(doctest, ``ELLIPSIS`` and ``NORMALIZE_WHITESPACE``): at least one example must run
(not all skipped) and every one must print what the docstring says.
"""

from __future__ import annotations

import doctest
import importlib

import numpy as np
import pytest

ENTRY_POINTS = [
    "tiltlab.io.read",
    "tiltlab.schema.make_recording",
    "tiltlab.schema.describe",
    "tiltlab.schema.to_units",
    "tiltlab.datasets.load",
    "tiltlab.simulate.simulate_session",
    "tiltlab.simulate.tumble_test",
    "tiltlab.simulate.apply_sensor_model",
    "tiltlab.filters.estimate",
    "tiltlab.filters.madgwick",
    "tiltlab.calibration.tumble_calibration",
    "tiltlab.calibration.detect_static",
    "tiltlab.calibration.calibrate",
    "tiltlab.evaluate.tilt_errors",
    "tiltlab.quaternion.angle_between",
    "tiltlab.quaternion.total_error",
    "tiltlab.quaternion.gravity",
    "tiltlab.trig.wrap_angle",
    "tiltlab.trig.angles_to_quaternion",
    "tiltlab.trig.acc_from_angles",
    "tiltlab.trig.unit_vector",
    "tiltlab.trig.heading",
    "tiltlab.trig.posture",
    "tiltlab.sphere.vmf_fit",
    "tiltlab.sphere.tilt_map",
    "tiltlab.sphere.kde",
    "tiltlab.sphere.visited_fraction",
    "tiltlab.behavior.immobility",
    "tiltlab.behavior.static_acceleration",
    "tiltlab.behavior.recording_speed",
    "tiltlab.stats.between_groups",
    "tiltlab.stats.study_design",
    "tiltlab.cohort.to_table",
]


def _resolve(dotted: str):
    module, name = dotted.rsplit(".", 1)
    return getattr(importlib.import_module(module), name)


def test_there_are_thirty_entry_points():
    assert len(set(ENTRY_POINTS)) >= 30


@pytest.mark.parametrize("dotted", ENTRY_POINTS)
def test_entry_point_example_runs(dotted):
    func = _resolve(dotted)
    doc = func.__doc__ or ""
    assert "\n    Examples\n    --------" in doc or "\nExamples\n--------" in doc, (
        f"{dotted} has no Examples section"
    )
    finder = doctest.DocTestFinder(recurse=False)
    module = importlib.import_module(func.__module__)
    tests = finder.find(func, dotted, module=module, globs={"np": np})
    runner = doctest.DocTestRunner(
        optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    )
    ran = 0
    for t in tests:
        runner.run(t)
        ran += sum(1 for ex in t.examples if not ex.options.get(doctest.SKIP, False))
    result = runner.summarize(verbose=False)
    assert ran > 0, f"{dotted}: every example is skipped"
    assert result.failed == 0, f"{dotted}: {result.failed} examples failed"
