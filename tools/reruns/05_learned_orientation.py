"""Chapter 5 on two other held-out trials and another recording."""

from __future__ import annotations

import json
from pathlib import Path

from ._common import printed

PARAMS = {"TRIALS": [6, 28], "EXAMPLE_TRIAL": 6, "SOURCE": "broad:10", "N_JOBS": 1}
MODELS = Path(__file__).resolve().parents[2] / "data" / "learn"


def check(nb_path: Path, params: dict) -> str:
    """The chapter compared every method on exactly the trials asked, and the
    inclination error it printed for ``SOURCE`` (§6) is the package's, computed here
    with the model of the fold that held the trial out."""
    import torch

    from tiltlab import datasets, evaluate, learn

    found = printed(
        nb_path,
        r"compared (\d+) methods on (\d+) held-out trials:\n([0-9,\s]*)",
        "comparison line",
    )
    n_methods, _, listed = found[0]
    trials = sorted(int(t) for t in listed.split(",") if t.strip())
    if trials != sorted(params["TRIALS"]):
        raise AssertionError(
            f"chapter compared trials {trials}, asked {params['TRIALS']}"
        )

    got = printed(
        nb_path,
        r"against the reference: inclination RMSE ([0-9.]+) deg",
        "error for SOURCE (§6)",
    )
    trial = int(params["SOURCE"].split(":")[1])
    folds = json.loads((MODELS / "run.json").read_text())["folds"]
    fold = next(k for k, f in enumerate(folds) if trial in f)
    torch.set_num_threads(1)
    rec = datasets.load(params["SOURCE"])
    q = learn.learned_estimate(rec, MODELS / f"gain_fold{fold}.pt")
    expected = evaluate.broad_errors(q, rec)["inclination"]
    if abs(float(got[0]) - expected) > 0.006:
        raise AssertionError(
            f"chapter says {got[0]} deg for {params['SOURCE']}, the package "
            f"{expected:.2f} deg"
        )
    return (
        f"{n_methods} methods on trials {trials}; {params['SOURCE']} inclination "
        f"{got[0]} deg (package: {expected:.2f} deg)"
    )


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab, converted by ``tiltlab
    convert``, as the reader's own recording of §6: the learned models need a
    gyroscope, which the chapter says instead of estimating."""
    from ._foreign import convert

    return {**PARAMS, "SOURCE": str(convert("tag", tmp))}


def check_tag(nb_path: Path, params: dict) -> str:
    """The chapter names the missing gyroscope for the tag rather than failing."""
    found = printed(
        nb_path, r"(\S+) has no ([a-z, ]+): the learned models", "skip line"
    )
    name, missing = found[0]
    if name != Path(params["SOURCE"]).name or "gyr" not in missing:
        raise AssertionError(f"chapter printed {found[0]!r}")
    return f"{name}: no {missing}, the learned models skipped"


VARIANTS = {"tag": prepare_tag}
