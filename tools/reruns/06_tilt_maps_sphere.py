"""Chapter 6 on another BROAD trial (rad/s gyroscope instead of the rat's deg/s), on a
coarser lattice and with the heading maps of another trial."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np

from ._common import glued, glued_float, printed
from ._foreign import convert

PARAMS = {
    "SOURCE": "broad:2",
    "IMMOBILE_DEG_S": 12.0,
    "N_LATTICE": 2000,
    "N_BOOT": 200,
    "SIM_DURATION_S": 120.0,
    "HEADING_SOURCE": "broad:3",
}


def check(nb_path: Path, params: dict) -> str:
    """The immobile fraction the chapter prints (over the samples with a tilt) equals the
    package's immobility rule applied directly, and the rule it names is the one the
    recording allows (the gyroscope's, or the accelerometer's without one); the glued
    statements of the prose agree with what they summarise (see :func:`_prose`)."""
    from tiltlab import behavior, datasets, filters

    rec = datasets.load(params["SOURCE"])
    immobile = behavior.immobility(
        rec, threshold_deg_s=params["IMMOBILE_DEG_S"], gyr_offset="auto"
    )
    with warnings.catch_warnings():  # the chapter prints the gaps
        warnings.simplefilter("ignore", RuntimeWarning)
        q = filters.estimate(rec, "lowpass", cutoff_hz=2.0, gaps="segments")
    valid = q.notnull().all("quat").values
    expected = float(immobile[valid].mean())
    found = printed(nb_path, r"immobile ([0-9.]+)% of the time", "immobile fraction")
    got = float(found[0]) / 100
    if abs(got - expected) > 0.0005:
        raise AssertionError(
            f"chapter says {got:.1%} immobile, behavior.immobility gives {expected:.1%}"
        )
    rule = printed(nb_path, r"immobility: (.+)", "immobility rule")[0]
    if rule.strip() != immobile.attrs["rule_description"]:
        raise AssertionError(f"chapter used the rule {rule!r}")
    g = filters.gravity(q)[valid]
    notes = _prose(nb_path, params, g, immobile[valid].values)
    bridges = _check_sparse_bridges(nb_path, params, g)
    return (
        f"immobile fraction {got:.1%} (package: {expected:.1%}; {rule.strip()}); "
        f"{notes}; {bridges}"
    )


def _close(got: float, expected: float, what: str, rel: float = 1e-6) -> None:
    if not np.isclose(got, expected, rtol=rel, atol=1e-12):
        raise AssertionError(f"chapter glued {what} = {got}, recomputed {expected}")


def _word(text: str, expected: str, what: str) -> None:
    if expected not in text:
        raise AssertionError(
            f"chapter says {what} {text!r}; the numbers give {expected!r}"
        )


def _prose(nb_path: Path, params: dict, g, immobile: np.ndarray) -> str:
    """Each glued summary statement against the numbers it summarises: the lattice's
    area spread near its poles, the facet-count/area agreement of §3, the bootstrap and
    movement-based-KDE verdicts, the stationarity of the thirds, and the exercises'
    comparison words; the cheap ones recomputed with the package."""
    from tiltlab import sphere

    v = glued(nb_path)
    _close(glued_float(v, "ch6_immobile_deg_s"), params["IMMOBILE_DEG_S"], "threshold")
    # §2: where the large facet-area departures sit
    mesh = sphere.sphere_mesh(params["N_LATTICE"])
    z, ratio = mesh.centroids[:, 2], mesh.areas / mesh.areas.mean()
    near = np.abs(z) > np.cos(np.radians(10.0))
    if near.any() and not near.all():
        where = np.ptp(ratio[near]) > np.ptp(ratio[~near])
        _word(v["ch6_pole_areas"], "near the poles" if where else "away from", "areas")
    # §3: largest |count/area − 1| over all, active and immobile samples
    rel = []
    for part in (g, g[~immobile], g[immobile]):
        t = sphere.tilt_map(part, mesh=mesh)
        a = sphere.visited_fraction(t, mesh)
        rel.append(abs(sphere.visited_fraction(t, mesh, by="count") / a - 1))
    _close(glued_float(v, "ch6_visited_reldiff_max") / 100, max(rel), "count/area")
    # §4: the bootstrap sentence's comparison word matches its ratio
    m = re.search(r"block cone is ([0-9.]+) times", v["ch6_boot_compare"])
    if m:
        word = "understates" if float(m.group(1)) > 1 else "does not understate"
        _word(v["ch6_boot_compare"], word, "the i.i.d. bootstrap")
    # §6: the movement-based KDE against the location-based one
    step = np.degrees(sphere.angle(g.values[:-1], g.values[1:]))
    _close(glued_float(v, "ch6_step_median_deg"), float(np.nanmedian(step)), "step")
    h = np.degrees(sphere.reference_bandwidth(g))
    _close(glued_float(v, "ch6_h_deg"), h, "bandwidth", rel=1e-4)
    pct = glued_float(v, "ch6_mkde_diff_pct")
    _word(v["ch6_mkde_verdict"], "nearly" if pct < 5 else "differ", "MKDE vs LKDE")
    st3 = sphere.stationarity_thirds(g)
    _close(glued_float(v, "ch6_thirds_max_angle"), st3.attrs["max_angle_deg"], "thirds")
    # exercises: lattice comparison word and the bootstrap-block growth
    ratio2 = glued_float(v, "ch6_ex2_lattice_ratio")
    _word(v["ch6_ex2_word"], "larger" if ratio2 > 1 else "smaller", "coarse lattice")
    cones = [float(x) for x in printed(nb_path, r"cone half-angle ([0-9.]+)°", "cones")]
    m = re.search(r"by ([0-9.]+)° from .* by ([0-9.]+)° from", v["ch6_ex3_growth"])
    if m and len(cones) == 4:  # i.i.d. + three blocks
        d = np.diff(cones[1:])
        _close(float(m.group(1)), round(d[0], 2), "cone growth", rel=0.02)
        _close(float(m.group(2)), round(d[1], 2), "cone growth", rel=0.02)
    return (
        f"prose: count/area within {max(rel):.2%}, MKDE–LKDE {pct:.2f} % "
        f"({v['ch6_mkde_verdict']}), thirds {st3.attrs['max_angle_deg']:.1f}°"
    )


def _check_sparse_bridges(nb_path: Path, params: dict, g) -> str:
    """§6, sparse fixes: the glued L1 distances to the full-rate LKDE (densest row: the
    largest of the three; sparsest row: each estimate) and step / h equal
    ``sphere.kde_distance`` recomputed with ``sphere.kde``, ``sphere.brb_diffusion``
    and ``sphere.brb`` on the chapter's subsampled tilt, and the comparison words (the
    bridges closer or not, the closest estimate, the fitted D farther or not) follow."""
    from tiltlab import sphere

    v = glued(nb_path)
    fs = float(g.attrs["fs"])
    kl = sphere.kde(g, cell_deg=params.get("CELL_DEG", 1.0))
    steps = params.get("SPARSE_STEPS_S", [0.1, 0.5, 1.0])
    rows = []
    for every in (steps[0], steps[-1]):
        st = max(1, round(every * fs))
        gs = g.isel(time=slice(None, None, st)).assign_attrs(fs=fs / st)
        d_ml = sphere.brb_diffusion(gs, h_min=kl.h)
        est = [
            sphere.kde(gs, h=kl.h, grid=kl.grid),
            sphere.brb(gs, h_min=kl.h, diffusion=0.0, grid=kl.grid),
            sphere.brb(gs, h_min=kl.h, diffusion=d_ml, grid=kl.grid),
        ]
        step = float(np.median(sphere.angle(gs.values[:-1], gs.values[1:])))
        rows.append([step / kl.h, *(sphere.kde_distance(e, kl) for e in est)])
    (r0, *l1_dense), (r1, lk, b0, bd) = rows
    for name, want in (
        ("ch6_sparse_dense_ratio", r0),
        ("ch6_sparse_dense_l1", max(l1_dense)),
        ("ch6_sparse_far_ratio", r1),
        ("ch6_sparse_far_lkde", lk),
        ("ch6_sparse_far_b0", b0),
        ("ch6_sparse_far_bd", bd),
    ):
        _close(glued_float(v, name), want, f"{name} (sphere.kde_distance)", rel=1e-5)
    verdict = "closer to" if b0 < lk else "no closer to"
    if v["ch6_sparse_bridge_verdict"].strip() != verdict:
        raise AssertionError(
            f"chapter says the kernels along the arcs are "
            f"{v['ch6_sparse_bridge_verdict']!r} the full-rate LKDE; the L1 distances "
            f"give {verdict!r} ({b0:.4f} vs {lk:.4f})"
        )
    closest = ("location-based", "along the arcs", "biased random bridges")[
        int(np.argmin([lk, b0, bd]))
    ]
    _word(v["ch6_sparse_closest"], closest, "the closest estimate is the")
    _word(
        v["ch6_sparse_bd_words"],
        "are farther from it" if bd > b0 else "come closer to it",
        "the fitted-D bridges",
    )
    return (
        f"sparse fixes: L1 LKDE/arcs/bridges {lk:.3f}/{b0:.3f}/{bd:.3f} "
        f"(sphere.kde_distance, as glued)"
    )


def prepare_foreign(tmp: Path) -> dict:
    """A hand-held board from another lab, converted by ``tiltlab convert``."""
    board = str(convert("board", tmp))
    return {**PARAMS, "SOURCE": board, "HEADING_SOURCE": board, "N_BOOT": 100}


check_foreign = check
VARIANTS = {"foreign": prepare_foreign}


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab (no gyroscope, a jittery
    millisecond clock), converted by ``tiltlab convert``: tilt from the static
    acceleration, immobility from VeDBA, the gyroscope's sections skipped with a line."""
    tag = str(convert("tag", tmp))
    return {**PARAMS, "SOURCE": tag, "HEADING_SOURCE": tag, "N_BOOT": 100}


check_tag = check
VARIANTS["tag"] = prepare_tag
