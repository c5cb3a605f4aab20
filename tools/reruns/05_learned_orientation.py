"""Chapter 5 on two other held-out trials and another recording."""

from __future__ import annotations

from pathlib import Path

from ._common import printed

PARAMS = {"TRIALS": [6, 28], "EXAMPLE_TRIAL": 6, "SOURCE": "broad:10", "N_JOBS": 1}


def check(nb_path: Path, params: dict) -> str:
    """The learned-estimator chapter compared every method on exactly the trials asked."""
    found = printed(
        nb_path, r"compared (\d+) methods on (\d+) held-out trials: \[([0-9, ]*)\]"
    )
    if not found:
        raise AssertionError("the chapter printed no comparison line")
    n_methods, _, listed = found[0]
    trials = sorted(int(t) for t in listed.split(",") if t.strip())
    if trials != sorted(params["TRIALS"]):
        raise AssertionError(
            f"chapter compared trials {trials}, asked {params['TRIALS']}"
        )
    return f"{n_methods} methods on trials {trials}"
