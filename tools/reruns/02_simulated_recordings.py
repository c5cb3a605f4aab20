"""Chapter 2 with another seed, smaller sizes and a BROAD trial (m/s², rad/s, 285.7 Hz)
as the real recording of the realism check; variant "tag": an accelerometer + magnetometer
bio-logging tag without a gyroscope as that recording."""

from __future__ import annotations

from pathlib import Path

from ._common import printed
from ._foreign import convert

PARAMS = {
    "SOURCE": "broad:3",
    "SEED": 5,
    "DURATION_S": 120.0,
    "N_TUMBLE": 20,
    "MOCAP_DURATION_S": 20.0,
    "COHORT_N_PER_GROUP": 1,
    "COHORT_DURATION_S": 60.0,
    "WORKERS": 1,
    "THRESHOLD_DEG_S": 10.0,
}


def check(nb_path: Path, params: dict) -> str:
    """The realism check analysed SOURCE: its fraction of time below the threshold, as
    printed, equals the package's computation on that recording."""
    from tiltlab import behavior, datasets

    real = datasets.load(params["SOURCE"])
    expected = float(
        (behavior.recording_speed(real) < params["THRESHOLD_DEG_S"]).mean()
    )
    found = printed(
        nb_path,
        r"([0-9.]+)% of the time below ([0-9.]+) °/s",
        "fraction below the threshold",
    )
    got, threshold = float(found[0][0]) / 100, float(found[0][1])
    if threshold != params["THRESHOLD_DEG_S"] or abs(got - expected) > 0.0006:
        raise AssertionError(
            f"chapter says {got:.1%} below {threshold:g} °/s, the package gives "
            f"{expected:.1%} below {params['THRESHOLD_DEG_S']:g} °/s"
        )
    return f"{got:.1%} of {params['SOURCE']} below {threshold:g} °/s (package: {expected:.1%})"


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab (no gyroscope, a few short NaN
    gaps), converted by ``tiltlab convert``, as the real recording of the realism check:
    immobility from the accelerometer's VeDBA rule, the gyroscope's comparisons skipped
    with a line."""
    return {**PARAMS, "SOURCE": str(convert("tag", tmp))}


def check_tag(nb_path: Path, params: dict) -> str:
    """The immobile fraction the chapter prints for the tag equals ``behavior.immobility``
    applied directly, with the rule it names (the accelerometer's, without a gyroscope),
    and the chapter says what it skips."""
    from tiltlab import behavior, datasets

    real = datasets.load(params["SOURCE"])
    immobile = behavior.immobility(real)
    expected = float(immobile.mean())
    found = printed(nb_path, r"immobile ([0-9.]+)% of the time", "immobile fraction")
    got = float(found[0]) / 100
    if abs(got - expected) > 0.0005:
        raise AssertionError(
            f"chapter says {got:.1%} immobile, behavior.immobility gives {expected:.1%}"
        )
    rule = printed(nb_path, r"immobility: (.+)", "immobility rule")[0].strip()
    if rule != immobile.attrs["rule_description"]:
        raise AssertionError(f"chapter used the rule {rule!r}")
    printed(nb_path, r"has no gyroscope: .+ skipped", "line saying what is skipped")
    return f"immobile fraction {got:.1%} (package: {expected:.1%}; {rule})"


VARIANTS = {"tag": prepare_tag}
