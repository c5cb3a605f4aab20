"""Chapter 4 on other data: a fast-translation BROAD trial for the first look, three other
BROAD trials with coarse grids, two short simulated rats, and a simulated rat saved as a
NetCDF file (a lab's own recording) in place of the real rat."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ._common import glued, glued_float, printed

_NUM = r"[-+]?[0-9.]+"


def prepare(tmp: Path) -> dict:
    """A 90-s simulated rat (100 Hz, with the simulator's sensor errors) written with
    ``tiltlab.io.save_netcdf``, as a reader would pass their own recording."""
    from tiltlab import io, simulate

    rat = simulate.simulate_session(90.0, 100.0, seed=11)
    path = io.save_netcdf(rat, tmp / "rat04.nc")
    return {
        "SOURCE": "broad:15",
        "RAT_SOURCE": str(path),
        "BROAD_UNDISTURBED": [3, 10, 21],
        "BROAD_DISTURBED": [24],
        "GRID": "coarse",
        "SHIFTS": [0.0, 0.75],
        "AHRS_TRIALS": [],
        "N_SIM": 2,
        "SIM_DURATION_S": 45.0,
        "SIM_SEED": 2022,
        "N_JOBS": 2,
    }


def _pairs(text: str) -> dict[str, float]:
    """``"name value, name value"`` → dict."""
    return {
        m: float(v) for m, v in re.findall(rf"([a-z_]+) ({_NUM})", text) if v != "."
    }


def _one(pattern: str, text: str, what: str) -> tuple:
    m = re.search(pattern, text)
    if m is None:
        raise AssertionError(f"the glued {what} does not read as expected: {text!r}")
    return m.groups()


def _check_first_look(nb_path: Path, params: dict, values: dict) -> str:
    """§2: the Madgwick error and the glued ranks of the seven filters, recomputed."""
    from tiltlab import datasets, evaluate, filters

    found = printed(
        nb_path,
        r"madgwick with default parameters \(beta = [0-9.]+\): tilt RMSE ([0-9.]+) deg",
        "Madgwick error for SOURCE",
    )
    rec = datasets.load(params["SOURCE"])
    expected = evaluate.tilt_rmse(filters.estimate(rec, "madgwick"), rec)
    got = float(found[0])
    if abs(got - expected) > 0.0006:
        raise AssertionError(
            f"chapter says Madgwick RMSE {got:.3f} deg on {params['SOURCE']}, "
            f"evaluate.tilt_rmse gives {expected:.3f} deg"
        )
    seven = [
        "lowpass",
        "complementary",
        "madgwick",
        "mahony",
        "ekf",
        "smoother",
        "rts_smoother",
    ]
    est = {m: filters.estimate(rec, m, gaps="segments") for m in seven}
    table = evaluate.error_summary(est, rec).sort_values("rmse")
    rank = {m: i + 1 for i, m in enumerate(table.index)}
    sm, rts, n, lp = _one(
        r"smoothers rank (\d+) and (\d+) of (\d+); the low-pass tilt, which trusts the "
        r"accelerometer alone, ranks (\d+)",
        values["ch4_first_ranking"],
        "ranking of §2",
    )
    want = (rank["smoother"], rank["rts_smoother"], len(rank), rank["lowpass"])
    if (int(sm), int(rts), int(n), int(lp)) != want:
        raise AssertionError(
            f"§2 glues ranks smoother {sm}, rts_smoother {rts} of {n}, lowpass {lp}; "
            f"evaluate.error_summary gives {want}"
        )
    return (
        f"Madgwick RMSE on {params['SOURCE']} {got:.3f} deg (package: {expected:.3f}); "
        f"§2 ranks {want} recomputed"
    )


def _check_broad_summary(nb_path: Path, values: dict) -> str:
    """§4 and the summary: the glued winners, counts and p-values against the printed
    LOTO table and paired comparisons."""
    loto = _pairs(printed(nb_path, r"LOTO mean \(deg\): (.*)", "LOTO means")[0])
    optimistic = _pairs(
        printed(nb_path, r"all-trials optimum \(deg\): (.*)", "optimistic means")[0]
    )
    best_name, best_val = _one(
        rf"The lowest LOTO mean is ([a-z_]+)'s \(({_NUM}) deg\)",
        values["ch4_sum_offline"],
        "best LOTO method",
    )
    argmin = min(loto, key=loto.get)
    if best_name != argmin or abs(float(best_val) - loto[argmin]) > 0.0006:
        raise AssertionError(
            f"summary says the lowest LOTO mean is {best_name}'s ({best_val}); the "
            f"printed LOTO means give {argmin} ({loto[argmin]:.4f})"
        )
    offline = ["offline_vqf", "smoother", "rts_smoother"]
    causal = [
        m
        for m in ("complementary", "madgwick", "mahony", "ekf", "vqf", "imufusion")
        if m in loto
    ]
    worst, verdict, best_c = _one(
        r"worst ([a-z_]+), .* is (more|not more) accurate than every causal filter "
        r"\(best ([a-z_]+),",
        values["ch4_sum_offline"],
        "offline-versus-causal statement",
    )
    w, c = max(offline, key=loto.get), min(causal, key=loto.get)
    ahead = "more" if loto[w] < loto[c] else "not more"
    if (worst, best_c, verdict) != (w, c, ahead):
        raise AssertionError(
            f"summary: worst offline {worst}, best causal {best_c}, '{verdict}'; printed "
            f"LOTO means give {w}, {c}, '{ahead}'"
        )
    n_used = len(
        printed(
            nb_path,
            r"undisturbed trials used here: \d+ of BROAD's \d+ \(([^)]*)\)",
            "trials",
        )[0].split(", ")
    )
    n_said = int(
        printed(nb_path, r"undisturbed trials used here: (\d+) of", "trial count")[0]
    )
    if n_used != n_said:
        raise AssertionError(f"§4 prints {n_said} trials but lists {n_used}")
    for m in ("rts_smoother", "smoother"):
        diff, low, n, p = printed(
            nb_path,
            rf"(?<![a-z_]){m} - offlineVQF \(LOTO\): ({_NUM}) deg; lower on (\d+) of (\d+) trials "
            rf"\(paired Wilcoxon p = ([0-9.]+)\)",
            f"{m} comparison",
        )[0]
        g = values[f"ch4_sum_{'rts' if m == 'rts_smoother' else 'smoother'}"]
        gd, gl, gn, gp, sig = _one(
            rf"by ({_NUM}) deg .* lower on (\d+) of (\d+) trials \(paired Wilcoxon p = "
            r"([0-9.]+), (significant|not significant)",
            g,
            f"{m} summary",
        )
        if (gd, gl, gn, gp) != (diff, low, n, p) or int(n) != n_used:
            raise AssertionError(f"summary {g!r} disagrees with the printed {m} line")
        if (sig == "significant") != (float(p) < 0.05):
            raise AssertionError(f"summary calls p = {p} {sig}")
        if abs(float(diff) - (loto[m] - loto["offline_vqf"])) > 0.00051:
            raise AssertionError(
                f"{m} - offlineVQF = {diff} deg, the printed LOTO means give "
                f"{loto[m] - loto['offline_vqf']:+.4f}"
            )
    stable_line = printed(nb_path, r"same choice in every fold: (.*)", "stable methods")
    stable = [s for s in stable_line[0].split(", ") if s != "none"]
    gap = {m: loto[m] - optimistic[m] for m in loto}
    text = values["ch4_sum_loto"]
    if stable:
        (got,) = _one(r"by at most ([0-9.]+) deg for the", text, "stable LOTO gap")
        if abs(float(got) - max(gap[m] for m in stable)) > 0.0011:
            raise AssertionError(f"summary {text!r}: stable methods' gap is wrong")
    unstable = [m for m in gap if m not in stable]
    if unstable:
        got, who = _one(r"by up to ([0-9.]+) deg \(([a-z_]+)\)", text, "LOTO gap")
        top = max(unstable, key=gap.get)
        if who != top or abs(float(got) - gap[top]) > 0.011:
            raise AssertionError(
                f"summary says LOTO exceeds the optimum by up to {got} ({who}); printed "
                f"means give {gap[top]:.3f} ({top})"
            )
    return f"summary: best LOTO {argmin}, offline vs causal '{ahead}', {n_used} trials"


def _check_simulation(nb_path: Path, values: dict) -> str:
    """§5: the crossover, the offset reductions and Table 1's shape against the printed
    lines; the glued session count against the sessions kept."""
    bins = printed(
        nb_path,
        r"bins \(deg/s\) where the EKF's median error is below Madgwick's: (.*)",
        "crossover bins",
    )[0]
    lows = [] if bins == "none" else [float(b.split("–")[0]) for b in bins.split(", ")]
    high = {100.0, 150.0, 200.0, 300.0}  # the chapter's bins from 100 deg/s up
    n_high = len(high & set(lows))
    phrase = (
        "does not reproduce"
        if n_high == 0
        else ("reproduces their crossover:" if n_high == len(high) else "only in part")
    )
    if phrase not in values["ch4_crossover"]:
        raise AssertionError(
            f"§5.3 glues {values['ch4_crossover']!r} but prints bins {bins!r}"
        )
    red = _pairs(
        printed(
            nb_path,
            r"reduction of the optimal error by offset correction:\n(.*)",
            "reductions",
        )[0]
    )
    larger = [s for s, v in (("moving", 27.0), ("immobile", 45.0)) if red[s] > v]
    want = (
        "larger than theirs in both"
        if len(larger) == 2
        else (
            "smaller than theirs in both" if not larger else f"only for the {larger[0]}"
        )
    )
    if want not in values["ch4_offset_comparison"]:
        raise AssertionError(
            f"§5.4 glues {values['ch4_offset_comparison']!r}; printed reductions {red}"
        )
    ours = _pairs(printed(nb_path, r"  ours:  (.*)", "movement errors")[0])
    fayat = _pairs(printed(nb_path, r"  Fayat: (.*)", "Fayat's movement errors")[0])
    lp_worst = max(ours, key=ours.get) == "lowpass"
    same = lp_worst == (max(fayat, key=fayat.get) == "lowpass")
    want = (
        f"{'has' if lp_worst else 'does not have'} the largest mean error during movement "
        f"({'as' if same else 'unlike'} in their Table 1)"
    )
    if want not in values["ch4_sum_sim"]:
        raise AssertionError(f"summary {values['ch4_sum_sim']!r}: expected {want!r}")
    kept = int(printed(nb_path, r"(\d+) of \d+ simulated sessions", "sessions kept")[0])
    rows = printed(nb_path, r"sessions per row: (\d+)", "sessions per row")
    if int(glued_float(values, "ch4_n_sim")) != kept or int(rows[0]) != kept:
        raise AssertionError(f"{kept} sessions kept, glued {values['ch4_n_sim']}")
    return f"crossover '{phrase}', offset reductions {red}, {kept} sessions"


def _check_rat(nb_path: Path, params: dict, values: dict) -> str:
    """§6 and the summary: the immobile fractions glued equal ``behavior.immobility``."""
    from tiltlab import behavior, calibration, datasets

    rat = datasets.load(params["RAT_SOURCE"])
    text = values["ch4_sum_immobility"]
    if "gyr" not in rat:
        (got,) = _one(r"\(([0-9.]+)% immobile\)", text, "tag immobility")
        want = 100 * float(behavior.immobility(rat).mean())
        if (
            "no gyroscope" not in values["ch4_rat_agreement"]
            or abs(float(got) - want) > 0.051
        ):
            raise AssertionError(f"summary {text!r}; behavior.immobility {want:.1f} %")
        return f"tag: {got} % immobile (package {want:.1f} %)"
    off = calibration.robust_gyro_offset(rat)
    fixed = behavior.immobility(rat, threshold_deg_s=12.0, gyr_offset=off)
    auto = behavior.immobility(rat, threshold_deg_s="auto", gyr_offset=off)
    agree, f12, fa = _one(
        r"class ([0-9.]+)% of the samples alike \(([0-9.]+)% and ([0-9.]+)% immobile",
        text,
        "immobility agreement",
    )
    want = [
        100 * float((fixed == auto).mean()),
        100 * float(fixed.mean()),
        100 * float(auto.mean()),
    ]
    if any(abs(float(g) - w) > 0.051 for g, w in zip((agree, f12, fa), want)):
        raise AssertionError(f"summary {text!r}; behavior.immobility gives {want}")
    return f"rat: thresholds agree on {agree} % (package {want[0]:.1f} %)"


def _check_exercises(nb_path: Path, values: dict) -> str:
    """Exercise 2: the glued fold count equals the printed choices of the folds."""
    counts = printed(
        nb_path, r"gains chosen without each trial: \{(.*)\}", "fold choices"
    )[0]
    chosen = {float(k): int(v) for k, v in re.findall(r"([0-9.e-]+): (\d+)", counts)}
    opt = float(
        printed(
            nb_path, r"all-trials optimum [0-9.]+ deg at beta = ([0-9.e-]+)", "optimum"
        )[0]
    )
    n_opt, n = _one(
        r"(\d+) of (\d+) folds", values["ch4_ex2_folds"], "exercise 2 folds"
    )
    if (int(n_opt), int(n)) != (chosen.get(opt, 0), sum(chosen.values())):
        raise AssertionError(
            f"exercise 2 glues {n_opt} of {n}; printed choices {chosen}"
        )
    return f"exercise 2: {n_opt} of {n} folds at the optimum"


def check(nb_path: Path, params: dict) -> str:
    """The chapter's glued statements agree with the tables and lines they summarise,
    and the values recomputed with the package: §2's Madgwick error and ranks, the
    summary's LOTO winner, offline-versus-causal verdict, paired comparisons and LOTO
    gaps, §5's crossover, offset reductions and Table 1 shape, Fig. 2f's speed slopes
    and crossover speed, the immobility agreement, and exercise 2's fold count."""
    values = glued(nb_path)
    return "; ".join(
        [
            _check_first_look(nb_path, params, values),
            _check_broad_summary(nb_path, values),
            _check_simulation(nb_path, values),
            _check_speed_slopes(nb_path, values),
            _check_crossover_speed(nb_path, values),
            _check_rat(nb_path, params, values),
            _check_exercises(nb_path, values),
            _check_c3d(nb_path, params),
        ]
    )


def _check_c3d(nb_path: Path, params: dict) -> str:
    """§5.5: the frames, rate and marker count printed for ``C3D_SOURCE`` are those
    ``io.read_c3d`` reads (or the section said it skipped an absent file)."""
    from tiltlab import io

    source = params.get("C3D_SOURCE", "foreign:c3d_biomechzoo/HC030A05.c3d")
    path = io.c3d_path(source)
    if path is None or not path.is_file():
        printed(nb_path, r"no such file; §5\.5 skipped", "§5.5 skip line")
        return "§5.5 skipped (no C3D file)"
    found = printed(
        nb_path,
        r"\((\d+) frames\) at ([0-9.]+) Hz, (\d+) markers",
        "C3D summary line (§5.5)",
    )
    frames, fs, markers = found[0]
    walk = io.read_c3d(path)
    want = (walk.sizes["frame"], float(walk.attrs["fs"]), walk.sizes["marker"])
    if (int(frames), float(fs), int(markers)) != want:
        raise AssertionError(f"§5.5 printed {found[0]}, io.read_c3d reads {want}")
    return f"C3D: {frames} frames at {fs} Hz, {markers} markers (as read)"


def prepare_tag(tmp: Path) -> dict:
    """The rerun's parameters with an accelerometer + magnetometer tag from another lab
    (no gyroscope, short NaN gaps), converted by ``tiltlab convert``, as the user's own
    recording of §6: only the low-pass tilt and the accelerometer immobility rule run."""
    from ._foreign import convert

    return {**prepare(tmp), "RAT_SOURCE": str(convert("tag", tmp))}


def check_tag(nb_path: Path, params: dict) -> str:
    """The immobile fraction the chapter prints and glues for the tag (§6, summary)
    equals ``behavior.immobility`` (the accelerometer rule) on the converted file, and
    the BROAD and simulation statements still agree with their tables."""
    from tiltlab import behavior, datasets

    rat = datasets.load(params["RAT_SOURCE"])
    if "gyr" in rat:
        raise AssertionError(f"{params['RAT_SOURCE']} has a gyroscope: not the tag")
    printed(nb_path, r"has no gyroscope: of these methods only lowpass runs", "skip")
    found = printed(
        nb_path,
        r"no gyroscope\): accelerometer rule -> ([0-9.]+)% immobile",
        "immobile fraction of the tag",
    )
    got = float(found[0])
    expected = 100 * float(behavior.immobility(rat).mean())
    if abs(got - expected) > 0.051:
        raise AssertionError(
            f"chapter says {got:.1f} % immobile, behavior.immobility gives {expected:.1f} %"
        )
    values = glued(nb_path)
    return "; ".join(
        [
            f"tag immobile {got:.1f} % by the accelerometer rule (package: {expected:.1f} %)",
            _check_rat(nb_path, params, values),
            _check_broad_summary(nb_path, values),
            _check_simulation(nb_path, values),
            _check_speed_slopes(nb_path, values),
            _check_crossover_speed(nb_path, values),
        ]
    )


VARIANTS = {"tag": prepare_tag}


def _html_tables(nb_path: Path, marker: str, before_glue: str) -> list[list[str]]:
    """The rows (cell texts) of the last HTML table containing ``marker`` that the
    chapter displays before the cell that glues ``before_glue``."""
    import html
    import json

    found, glued_at = None, False
    for cell in json.loads(nb_path.read_text())["cells"]:
        for o in cell.get("outputs", []) if cell["cell_type"] == "code" else []:
            if o.get("metadata", {}).get("scrapbook", {}).get("name") == before_glue:
                glued_at = True
            page = "".join(o.get("data", {}).get("text/html", ""))
            if marker in page and not glued_at:
                found = page
        if glued_at:
            break
    if found is None:
        raise AssertionError(f"the chapter shows no table of {marker!r}")
    rows = []
    for tr in re.findall(r"<tr[^>]*>(.*?)</tr>", found, flags=re.S):
        cells = re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", tr, flags=re.S)
        rows.append([html.unescape(re.sub(r"<[^>]+>", "", c)).strip() for c in cells])
    return rows


def _half_unit(text: str) -> float:
    """Half a unit of the last digit a number is written with (its rounding error)."""
    mant, _, exp = text.lower().partition("e")
    decimals = len(mant.partition(".")[2])
    return 0.5 * 10.0 ** (int(exp or 0) - decimals)


def _cell(text: str) -> float:
    return float(text) if re.fullmatch(r"[-+]?[0-9.]+(?:e[-+]?\d+)?", text) else np.nan


_SCI = r"[-+]?[0-9.]+(?:e[-+]?\d+)?"


def _check_speed_slopes(nb_path: Path, values: dict) -> str:
    """§5 Fig. 2f: the glued slope sentence against Table 5.2 (``evaluate.speed_slope``
    as displayed): the filters with the steepest and the flattest slope, their slopes,
    the reference's slope, interval and relative size, each to the digits displayed;
    every displayed slope inside its own interval."""
    rows = _html_tables(
        nb_path, "Theil–Sen slope of tilt error against speed", "ch4_slope_sentence"
    )
    per_tab = float(re.findall(r"per ([0-9.]+) deg/s", rows[0][1])[0])
    tab = {r[0]: r[1:] for r in rows[2:] if len(r) == 6}
    for m, (s, lo, hi, _, n) in tab.items():
        t = _half_unit(s) + max(_half_unit(lo), _half_unit(hi))
        if not _cell(lo) - t <= _cell(s) <= _cell(hi) + t or int(n) < 3:
            raise AssertionError(f"Table 5.2: {m}'s slope {s} outside [{lo}, {hi}]")
    ref = tab.pop("motion capture", None)
    if ref is None or not tab:
        raise AssertionError(f"Table 5.2 lacks the reference or the filters: {rows}")
    text = values["ch4_slope_sentence"]
    top, s_top, per, low, s_low, s_ref, r_lo, r_hi, pct = _one(
        rf"error of ([a-z_]+) grows fastest with speed \(({_SCI})° per ([0-9.]+) °/s\) "
        rf"and that of ([a-z_]+) least \(({_SCI})°\)\. The motion-capture reference's "
        rf"own error changes by ({_SCI})° per [0-9.]+ °/s \(interval ({_SCI}) to "
        rf"({_SCI})\), ([0-9]+)% of the largest",
        text,
        "slope sentence of Fig. 2f",
    )
    if float(per) != per_tab:
        raise AssertionError(
            f"Fig. 2f: sentence per {per} °/s, Table 5.2 per {per_tab}"
        )
    slope = {m: _cell(r[0]) for m, r in tab.items()}
    tol = {m: _half_unit(r[0]) for m, r in tab.items()}
    for name, said, pick in ((top, s_top, max), (low, s_low, min)):
        best = pick(slope.values())
        if name not in slope or abs(slope[name] - best) > tol[name] + max(tol.values()):
            raise AssertionError(
                f"Fig. 2f sentence names {name} ({said}); Table 5.2's slopes {slope} "
                f"give {pick(slope, key=slope.get)}"
            )
        if abs(float(said) - slope[name]) > _half_unit(said) + tol[name]:
            raise AssertionError(
                f"Fig. 2f sentence: {name}'s slope {said}, Table 5.2 {tab[name][0]}"
            )
    for said, shown, what in zip((s_ref, r_lo, r_hi), ref[:3], ("slope", "lo", "hi")):
        if abs(float(said) - _cell(shown)) > _half_unit(said) + _half_unit(shown):
            raise AssertionError(
                f"Fig. 2f sentence: reference {what} {said}, Table 5.2 {shown}"
            )
    big = max(abs(v) for v in slope.values())
    rel = 100 * abs(_cell(ref[0])) / big
    err = 100 * (_half_unit(ref[0]) + rel / 100 * max(tol.values())) / big
    if abs(int(pct) - rel) > 0.5 + err:
        raise AssertionError(
            f"Fig. 2f sentence: reference slope {pct}% of the largest, Table 5.2 "
            f"gives {rel:.1f}%"
        )
    return f"Fig. 2f slopes: {top} steepest, {low} flattest, reference {pct}% (table)"


def _crossing_spans(x, d, tol) -> list[tuple[float, float]]:
    """Where ``evaluate.crossover_speed``'s interpolation of a first rise of ``d`` from
    below zero to above can fall when each ``d`` is known only to within ``tol``."""
    spans = []
    for i in range(len(d) - 1):
        if (d[: i + 1] - tol[: i + 1] > 0).any() or d[i + 1] + tol[i + 1] < 0:
            continue  # an earlier bin is surely above, or the next surely below
        di = (d[i] - tol[i], min(d[i] + tol[i], 0.0))
        dj = (max(d[i + 1] - tol[i + 1], 0.0), d[i + 1] + tol[i + 1])
        s = [x[i] + (x[i + 1] - x[i]) * a / (a - b) for a in di for b in dj if a < b]
        if len(s) < 4:  # both may be zero: the crossing may lie anywhere in the bin
            s += [x[i], x[i + 1]]
        spans.append((float(min(s)), float(max(s))))
    return spans


def _check_crossover_speed(nb_path: Path, values: dict) -> str:
    """§5 Fig. 2f: the glued crossover sentence equals ``evaluate.crossover_speed`` run
    on the binned medians the chapter displays (Madgwick's minus the EKF's): whether
    they cross, which side Madgwick's stays or goes, the speed (within what the
    displayed rounding allows), the number of sign changes and the word placing it
    against Fayat et al.'s 100–150 °/s."""
    from tiltlab import evaluate

    rows = _html_tables(nb_path, "by angular speed, bin centre", "ch4_cross_sentence")
    centres = np.array([float(c) for c in rows[0][1:]])
    tab = {r[0]: r[1:] for r in rows[1:] if len(r) == len(rows[0])}
    if "madgwick" not in tab or "ekf" not in tab:
        raise AssertionError(f"the median table lacks madgwick or ekf: {list(tab)}")
    a = np.array([_cell(c) for c in tab["madgwick"]])
    b = np.array([_cell(c) for c in tab["ekf"]])
    tol = np.array(
        [_half_unit(x) + _half_unit(y) for x, y in zip(tab["madgwick"], tab["ekf"])]
    )
    cross = evaluate.crossover_speed(centres, a, b)
    ok = np.isfinite(a - b)
    x, d, tol = centres[ok], (a - b)[ok], tol[ok]
    sure = np.abs(d) > tol + 1e-9  # the sign survives the displayed rounding
    text = values["ch4_cross_sentence"]
    if "do not cross" in text:
        side = re.search(r"Madgwick's median stays (below|above) the EKF's", text)
        if side is None:
            if ok.sum() >= 2:
                raise AssertionError(f"Fig. 2f: {text!r}, yet {ok.sum()} bins compare")
            return "Fig. 2f crossover: too few bins (as displayed)"
        wrong = np.sign(d[sure]) != (-1 if side.group(1) == "below" else 1)
        if wrong.any() or (sure.all() and np.isfinite(float(cross))):
            raise AssertionError(
                f"Fig. 2f says {text!r}; evaluate.crossover_speed on the displayed "
                f"medians: {float(cross):.0f} °/s, {cross.attrs['reason']}"
            )
        return f"Fig. 2f crossover: none, Madgwick {side.group(1)} (package agrees)"
    c_said, n_said, where, lo_f, hi_f = _one(
        r"rises above the EKF's at (\d+) °/s .*?(\d+) sign change\(s\) in all\), "
        r"(inside|below|above) their range of ([0-9.]+)–([0-9.]+)",
        text,
        "crossover sentence of Fig. 2f",
    )
    c_said, lo_f, hi_f = float(c_said), float(lo_f), float(hi_f)
    want = (
        "inside" if lo_f <= c_said <= hi_f else ("below" if c_said < lo_f else "above")
    )
    if where != want:
        raise AssertionError(f"Fig. 2f: {c_said:g} °/s is {want} {lo_f:g}–{hi_f:g}")
    if not sure.all():  # a tie at the displayed digits: the package's value is one
        spans = _crossing_spans(x, d, tol)  # of many; where could the first one be?
        if not any(lo - 0.5 <= c_said <= hi + 0.5 for lo, hi in spans):
            raise AssertionError(
                f"Fig. 2f says {text!r}; within the rounding of the displayed medians "
                f"Madgwick's can first rise above the EKF's only in {spans} °/s"
            )
        return f"Fig. 2f crossover {c_said:g} °/s (ties in the display: within {spans})"
    c = float(cross)
    if np.isnan(c) or cross.attrs["reason"] != "a goes above b":
        raise AssertionError(
            f"Fig. 2f says {text!r}; evaluate.crossover_speed on the displayed medians "
            f"(a = Madgwick, b = EKF): {c:.0f} °/s, {cross.attrs['reason']}"
        )
    i = int(np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))[0])
    corners = [
        x[i] + (x[i + 1] - x[i]) * di / (di - dj)
        for di in (d[i] - tol[i], d[i] + tol[i])
        for dj in (d[i + 1] - tol[i + 1], d[i + 1] + tol[i + 1])
    ]
    if not min(corners) - 0.5 <= c_said <= max(corners) + 0.5 or int(n_said) != int(
        cross.attrs["n_crossings"]
    ):
        raise AssertionError(
            f"Fig. 2f says {text!r}; evaluate.crossover_speed on the displayed medians: "
            f"{c:.1f} °/s ({min(corners):.1f}–{max(corners):.1f} within the rounding), "
            f"{cross.attrs['n_crossings']} sign change(s)"
        )
    return f"Fig. 2f crossover {c_said:g} °/s (package on the medians: {c:.1f})"
