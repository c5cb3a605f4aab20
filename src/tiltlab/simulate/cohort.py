r"""Simulated lesion cohorts written to disk exactly like real data.

Default design: Fayat et al. [1]_ §2.4 — unilateral vestibular lesion by a
trans-tympanic injection in the **left** ear; groups Kainate (n = 20), ShamKainate
(11), Arsanilate (11), ShamArsanilate (5) and Healthy (11, anaesthesia only);
sessions at baseline (1 h before) and 1 h, 1 d, 2 d, 7 d, 14 d and 28 d after.

Planted effects (group × time, §3.4 and Tables A1–A8), per session, combine

* the animal's baseline (immobility fraction, baseline tilt point, IMU errors);
* anaesthesia, in every group: more immobility and less head mobility at 1 h, less at
  1 d (the Healthy group differs from its baseline up to 1 d, Table A2);
* the lesion, scaled by a per-animal susceptibility: kainate acute (peak at 1 h: strong
  loss of mobility, moderate tilt, more immobility) and recovering within days;
  arsanilate peaking at 1–2 d for immobility and mobility, tilt toward the lesion side
  growing to ≈ 40° at 7 d with partial recovery, and late-onset counter-clockwise
  circling (7–28 d, Table A7);
* session-to-session noise.

The values of :data:`EFFECTS` are our reading of Fig. 4 and Tables A1–A8, not
numbers published by the authors; the planted values of every session are written to
``truth.csv`` as the ground truth to recover.

Directory layout::

    cohort/
      manifest.csv    the cohort manifest read by :func:`tiltlab.cohort.read_manifest`:
                      session, subject, group, timepoint, file, reader (netcdf),
                      reader_options (empty), calibration (the animal's tumble test)
                      and the covariate hours
      sessions.csv    one row per session: subject, group, timepoint, hours, file
      truth.csv       planted and realised effects per session (realised: state fraction
                      immobile, fraction of true angular speed < 12 °/s, angle to the xz
                      plane of the baseline tilt point and of the mean immobile tilt,
                      mean azimuthal rotation during active states) and the features
                      of :mod:`tiltlab.cohort` applied to the true motion
                      (``*_true`` columns, see :func:`_true_features`)
      design.json     design, effect tables, seed, duration, fs
      sessions/<subject>_<timepoint>.nc   one Recording per session (tiltlab.io.save_netcdf)
      calibration/<subject>_tumble.nc      one tumble test per animal, recorded with the
                                           animal's IMU (Fayat App. A.1)

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from .. import io as _io
from .. import quaternion as _quat
from ..behavior import detect_immobility
from .kinematics import STATES, BehaviourParams, Lesion, TrueMotion, head_kinematics
from .sensor import SensorModel, draw_sensor, recording_from_motion
from .tumble import tumble_test

#: Fayat et al.'s immobility rules (§2.9): threshold (°/s), merge gap (s), minimum (s)
_IMMOBILITY_RULES = {"threshold_deg_s": 12.0, "merge_gap_s": 0.1, "min_duration_s": 0.5}

__all__ = [
    "TIME_POINTS",
    "HOURS",
    "FAYAT_GROUPS",
    "EFFECTS",
    "ANAESTHESIA",
    "CohortDesign",
    "session_plan",
    "simulate_cohort",
    "Cohort",
    "load_cohort",
    "iter_sessions",
]

TIME_POINTS: tuple[str, ...] = ("baseline", "1h", "1d", "2d", "7d", "14d", "28d")
HOURS: tuple[float, ...] = (-1.0, 1.0, 24.0, 48.0, 168.0, 336.0, 672.0)
FAYAT_GROUPS: dict[str, int] = {
    "Kainate": 20,
    "ShamKainate": 11,
    "Arsanilate": 11,
    "ShamArsanilate": 5,
    "Healthy": 11,
}

#: Effect of anaesthesia (all groups) per time point: added immobility fraction and
#: mobility multiplier.
ANAESTHESIA: dict[str, tuple[float, ...]] = {
    "immobility": (0.0, 0.22, 0.10, 0.02, 0.0, 0.0, 0.0),
    "mobility": (1.0, 0.85, 0.93, 1.0, 1.0, 1.0, 1.0),
}

# both sham groups: the transient effect of surgery and anaesthesia, no lesion
_SHAM: dict[str, tuple[float, ...]] = {
    "immobility": (0.0, 0.03, 0.02, 0.0, 0.0, 0.0, 0.0),
    "mobility": (1.0, 0.95, 1.0, 1.0, 1.0, 1.0, 1.0),
    "tilt_deg": (0.0,) * 7,
    "pitch_deg": (0.0,) * 7,
    "circling_cpm": (0.0,) * 7,
}

#: Lesion (or vehicle) effects per group and time point (TIME_POINTS order):
#: ``immobility`` added fraction, ``mobility`` multiplier, ``tilt_deg`` toward the
#: lesion side (angle of the baseline tilt point to the sagittal plane),
#: ``pitch_deg`` extra nose-down pitch, ``circling_cpm`` toward the lesion side.
EFFECTS: dict[str, dict[str, tuple[float, ...]]] = {
    "Kainate": {
        "immobility": (0.0, 0.35, 0.12, 0.08, 0.06, 0.05, 0.05),
        "mobility": (1.0, 0.40, 0.85, 0.95, 1.0, 1.0, 1.0),
        "tilt_deg": (0.0, 15.0, 8.0, 6.0, 4.0, 3.0, 2.0),
        "pitch_deg": (0.0, 3.0, 2.0, 1.0, 0.0, 0.0, 0.0),
        "circling_cpm": (0.0, 0.2, 0.0, 0.0, 0.0, 0.0, 0.0),
    },
    "Arsanilate": {
        "immobility": (0.0, 0.10, 0.40, 0.35, 0.15, 0.10, 0.08),
        "mobility": (1.0, 0.85, 0.55, 0.60, 0.85, 0.90, 0.95),
        "tilt_deg": (0.0, 5.0, 25.0, 32.0, 40.0, 35.0, 30.0),
        "pitch_deg": (0.0, 1.0, 5.0, 6.0, 8.0, 7.0, 6.0),
        "circling_cpm": (0.0, 0.0, 0.2, 0.5, 1.5, 2.0, 2.0),
    },
    "ShamKainate": dict(_SHAM),
    "ShamArsanilate": dict(_SHAM),
    "Healthy": {
        "immobility": (0.0,) * 7,
        "mobility": (1.0,) * 7,
        "tilt_deg": (0.0,) * 7,
        "pitch_deg": (0.0,) * 7,
        "circling_cpm": (0.0,) * 7,
    },
}


@dataclass(frozen=True)
class CohortDesign:
    """Groups, time points, planted effects and between-animal variability.

    Parameters
    ----------
    groups : dict
        Group name → number of animals (default Fayat's).
    time_points, hours : tuples
        Session labels and their times relative to the lesion (h).
    effects : dict
        Group → feature → per-time-point values (see :data:`EFFECTS`).
    anaesthesia : dict
        Feature → per-time-point values applied to every group (see :data:`ANAESTHESIA`).
    lesion_side : {"left", "right"}
    baseline_immobility, baseline_immobility_sd : float
        Mean and between-animal SD of the baseline immobility fraction.
    susceptibility_sd : float
        SD of the log of a per-animal factor multiplying the lesion effects.
    baseline_pitch_deg, baseline_pitch_sd, baseline_roll_sd : float
        Baseline tilt point (IMU mounting) across animals.
    session_immobility_sd, session_tilt_sd : float
        Session-to-session noise on the planted immobility fraction and tilt (deg).
    """

    groups: dict = field(default_factory=lambda: dict(FAYAT_GROUPS))
    time_points: tuple = TIME_POINTS
    hours: tuple = HOURS
    effects: dict = field(default_factory=lambda: json.loads(json.dumps(EFFECTS)))
    anaesthesia: dict = field(
        default_factory=lambda: json.loads(json.dumps(ANAESTHESIA))
    )
    lesion_side: str = "left"
    baseline_immobility: float = 0.30
    baseline_immobility_sd: float = 0.06
    susceptibility_sd: float = 0.25
    baseline_pitch_deg: float = 25.0
    baseline_pitch_sd: float = 5.0
    baseline_roll_sd: float = 3.0
    session_immobility_sd: float = 0.03
    session_tilt_sd: float = 2.0

    def __post_init__(self):
        """Check that the tables match the time points and the lesion side is valid."""
        nt = len(self.time_points)
        if len(self.hours) != nt:
            raise ValueError("time_points and hours must have the same length")
        if self.lesion_side not in ("left", "right"):
            raise ValueError("lesion_side must be 'left' or 'right'")
        for g, n in self.groups.items():
            if int(n) != n or n < 0:
                raise ValueError(
                    f"group {g!r}: number of animals must be a non-negative integer"
                )
            if g not in self.effects:
                raise ValueError(f"group {g!r} has no entry in effects")
            for feat in (
                "immobility",
                "mobility",
                "tilt_deg",
                "pitch_deg",
                "circling_cpm",
            ):
                v = self.effects[g].get(feat)
                if v is None or len(v) != nt:
                    raise ValueError(f"effects[{g!r}][{feat!r}] needs {nt} values")
        for feat in ("immobility", "mobility"):
            if len(self.anaesthesia.get(feat, ())) != nt:
                raise ValueError(f"anaesthesia[{feat!r}] needs {nt} values")

    @classmethod
    def small(cls, n_per_group: int = 2, **kwargs) -> "CohortDesign":
        """Fayat's design with ``n_per_group`` animals in every group (for tests and the book)."""
        return cls(groups={g: n_per_group for g in FAYAT_GROUPS}, **kwargs)

    def select(self, *, groups: dict | None = None, time_points=None) -> "CohortDesign":
        """Restrict this design to some time points and change its group sizes.

        This design restricted to some time points (effect tables cut to match) and
        with other group sizes (``groups``: name → number of animals, names from
        ``effects``).
        """
        tps = list(self.time_points if time_points is None else time_points)
        unknown = [t for t in tps if t not in self.time_points]
        if unknown:
            raise ValueError(
                f"unknown time point(s) {unknown}; known {self.time_points}"
            )
        idx = [list(self.time_points).index(t) for t in tps]

        def cut(table):
            return {k: tuple(v[i] for i in idx) for k, v in table.items()}

        return replace(
            self,
            groups=dict(self.groups if groups is None else groups),
            time_points=tuple(tps),
            hours=tuple(self.hours[i] for i in idx),
            effects={g: cut(e) for g, e in self.effects.items()},
            anaesthesia=cut(self.anaesthesia),
        )

    def to_dict(self) -> dict:
        """Return the design as a JSON-serialisable dict."""
        d = asdict(self)
        d["time_points"], d["hours"] = list(self.time_points), list(self.hours)
        return json.loads(json.dumps(d))


def _subjects(design: CohortDesign) -> list[tuple[str, str]]:
    out = []
    for g, n in design.groups.items():
        for i in range(int(n)):
            out.append((f"{g}{i + 1:02d}", g))
    return out


def session_plan(
    design: CohortDesign, *, seed: int, duration_s: float, fs: float
) -> pd.DataFrame:
    """One row per session with its planted parameters (no simulation).

    Per-animal draws use ``SeedSequence([seed, animal])`` and per-session draws
    ``SeedSequence([seed, animal, session])``: a session's content does not depend on
    the order in which sessions are simulated, nor on the number of workers.

    Parameters
    ----------
    design : CohortDesign
        Cohort design: groups, time points, planted effects and their spreads.
    seed : int
        Root seed of the cohort.
    duration_s : float
        Duration of each session (s), recorded in the table.
    fs : float
        Sampling rate (Hz), recorded in the table.

    Returns
    -------
    pandas.DataFrame
        One row per (animal, time point): ``subject``, ``group``, ``timepoint``,
        ``hours``, ``session``, ``file``, ``calibration``, seeds and the planted values
        (``immobility_planted`` and ``mobility_planted`` as fractions/factors,
        ``tilt_deg_planted`` and ``pitch_deg_planted`` in degrees,
        ``circling_cpm_planted`` in circles per minute, ...).
    """
    rows = []
    sgn = 1.0 if design.lesion_side == "left" else -1.0
    for a, (subj, grp) in enumerate(_subjects(design)):
        arng = np.random.default_rng(np.random.SeedSequence([seed, a]))
        f_base = float(
            np.clip(
                arng.normal(design.baseline_immobility, design.baseline_immobility_sd),
                0.05,
                0.8,
            )
        )
        sus = float(np.exp(arng.normal(0.0, design.susceptibility_sd)))
        pitch0 = float(arng.normal(design.baseline_pitch_deg, design.baseline_pitch_sd))
        roll0 = float(arng.normal(0.0, design.baseline_roll_sd))
        imu_seed = int(arng.integers(0, 2**31 - 1))
        eff = design.effects[grp]
        for t, (tp, hr) in enumerate(zip(design.time_points, design.hours)):
            srng = np.random.default_rng(np.random.SeedSequence([seed, a, t, 1]))
            imm = (
                f_base
                + design.anaesthesia["immobility"][t]
                + sus * eff["immobility"][t]
            )
            imm = float(
                np.clip(
                    imm + srng.normal(0.0, design.session_immobility_sd), 0.03, 0.92
                )
            )
            mob = design.anaesthesia["mobility"][t] * (
                1.0 - sus * (1.0 - eff["mobility"][t])
            )
            mob = float(np.clip(mob, 0.2, 1.3))
            tilt = sus * eff["tilt_deg"][t]
            tilt = tilt + (
                srng.normal(0.0, design.session_tilt_sd) if tilt > 0 else 0.0
            )
            # a tilt point at T from the sagittal plane needs sin T <= cos(pitch): keep it reachable
            pitch = pitch0 + sus * eff["pitch_deg"][t]
            t_max = (
                math.degrees(math.asin(math.cos(math.radians(pitch))))
                - abs(roll0)
                - 2.0
            )
            tilt = float(np.clip(tilt, 0.0, min(55.0, t_max)))
            rows.append(
                {
                    "subject": subj,
                    "group": grp,
                    "timepoint": tp,
                    "hours": float(hr),
                    "session": f"{subj}_{tp}",
                    "file": f"sessions/{subj}_{tp}.nc",
                    "calibration": f"calibration/{subj}_tumble.nc",
                    "animal_index": a,
                    "session_index": t,
                    "seed": seed,
                    "duration_s": float(duration_s),
                    "fs": float(fs),
                    "susceptibility": sus,
                    "baseline_pitch_deg": pitch0,
                    "baseline_roll_deg": roll0,
                    "imu_seed": imu_seed,
                    "immobility_planted": imm,
                    "mobility_planted": mob,
                    "tilt_deg_planted": tilt,
                    "pitch_deg_planted": float(sus * eff["pitch_deg"][t]),
                    "circling_cpm_planted": float(sus * eff["circling_cpm"][t]),
                    "lesion_side": design.lesion_side,
                    "side_sign": sgn,
                }
            )
    return pd.DataFrame(rows)


def _animal_sensor(row: dict) -> SensorModel:
    """Draw the animal's IMU: errors from the animal's seed; temperatures left to each recording."""
    sensor = draw_sensor(SensorModel(), np.random.default_rng(row["imu_seed"]))
    return SensorModel(**{**sensor.__dict__, "temp_start": None, "temp_end": None})


def _simulate_tumble(row: dict, out_dir: str) -> str:
    """Simulate and write the tumble test of one animal (its own IMU; run in a worker)."""
    rec = tumble_test(
        50,
        300.0,
        seed=np.random.SeedSequence([row["seed"], row["animal_index"], 3]),
        sensor=_animal_sensor(row),
    )
    rec.attrs.update(subject=row["subject"], session="tumble test")
    _io.save_netcdf(rec, Path(out_dir) / row["calibration"])
    return row["calibration"]


def _true_features(motion: TrueMotion, side_sign: float) -> dict:
    """Compute the features of :mod:`tiltlab.cohort` on the TRUE motion.

    Why this is the truth to recover: a feature such as "immobile fraction" is defined
    by a rule set applied to an angular speed (Fayat §2.9: < 12 °/s, gaps < 0.1 s
    merged, periods < 0.5 s dropped), not by the simulator's behavioural states, which
    include slow movements and brief still moments that no speed rule can (or should)
    classify the same way. Applying the same definitions to the true angular velocity
    and the true tilt gives what a perfect sensor and a perfect orientation estimate
    would measure; the difference between a pipeline's output and these values is then
    purely measurement error (sensor noise and offsets, calibration, filter), which is
    what a recovery test must bound.
    """
    speed = np.degrees(np.linalg.norm(motion.omega, axis=1))
    imm = np.asarray(detect_immobility(speed, motion.fs, **_IMMOBILITY_RULES))
    gs = _quat.gravity(motion.q)
    out = {"immobile_fraction_true": float(np.mean(imm))}
    mu = gs[imm].sum(axis=0) if imm.any() else np.full(3, np.nan)
    mu = mu / np.linalg.norm(mu)
    out.update({f"tilt_immobile_{a}_true": float(v) for a, v in zip("xyz", mu)})
    out["tilt_sagittal_deg_true"] = float(
        np.degrees(np.arcsin(np.clip(-side_sign * mu[1], -1, 1)))
    )
    az = np.degrees(np.sum(motion.omega * gs, axis=1))  # ω·g_s, °/s
    moving = ~imm
    out["circling_index_cpm_true"] = (
        float(np.mean(az[moving]) * 60.0 / 360.0) if moving.any() else np.nan
    )
    return out


def _simulate_one(row: dict, out_dir: str, keep_true: bool) -> dict:
    """Simulate and write one session; returns the realised truth (run in a worker)."""
    beh = BehaviourParams(
        baseline_pitch_deg=row["baseline_pitch_deg"],
        baseline_roll_deg=row["baseline_roll_deg"],
    )
    lesion = Lesion(
        tilt_deg=row["tilt_deg_planted"],
        pitch_deg=row["pitch_deg_planted"],
        circling_cpm=row["circling_cpm_planted"],
        immobility_fraction=row["immobility_planted"],
        mobility=row["mobility_planted"],
        side=row["lesion_side"],
    )
    # the animal keeps its IMU: sensor errors from the animal's seed, temperatures per session
    sensor = _animal_sensor(row)
    rng = np.random.default_rng(
        np.random.SeedSequence(
            [row["seed"], row["animal_index"], row["session_index"], 2]
        )
    )
    motion = head_kinematics(
        row["duration_s"], row["fs"], behaviour=beh, lesion=lesion, rng=rng
    )
    attrs = {
        "subject": row["subject"],
        "session": row["timepoint"],
        "group": row["group"],
        "hours_after_lesion": row["hours"],
        "lesion_side": row["lesion_side"],
    }
    rec = recording_from_motion(
        motion, rng=rng, sensor=sensor, keep_true=keep_true, attrs=attrs
    )
    _io.save_netcdf(rec, Path(out_dir) / row["file"])
    # realised truth from the true motion
    active = motion.state != 0
    g = np.asarray(motion.params["baseline_tilt"])
    gs = _quat.gravity(motion.q)
    az = np.sum(motion.omega * gs, axis=1)  # angular velocity about the vertical, rad/s
    cpm = float(np.mean(az[active]) * 60.0 / (2 * math.pi)) if active.any() else 0.0
    # mean direction (vMF estimator) of the true tilt during the immobile state
    mu = gs[~active].sum(axis=0) if (~active).any() else g
    mu = mu / np.linalg.norm(mu)
    speed = np.degrees(np.linalg.norm(motion.omega, axis=1))
    return {
        "file": row["file"],
        "n_samples": int(len(motion)),
        "immobility_realised": float(np.mean(~active)),
        "fraction_below_12dps_true": float(np.mean(speed < 12.0)),
        "tilt_to_xz_deg_true": float(
            np.degrees(np.arcsin(np.clip(-row["side_sign"] * g[1], -1, 1)))
        ),
        "tilt_to_xz_deg_realised": float(
            np.degrees(np.arcsin(np.clip(-row["side_sign"] * mu[1], -1, 1)))
        ),
        "baseline_tilt_x": float(g[0]),
        "baseline_tilt_y": float(g[1]),
        "baseline_tilt_z": float(g[2]),
        "circling_cpm_realised": float(row["side_sign"] * cpm),
        **_true_features(motion, row["side_sign"]),
        "true_gyr_offset_mean": json.dumps(rec.attrs["true_gyr_offset_mean"]),
        "true_acc_offset_mean": json.dumps(rec.attrs["true_acc_offset_mean"]),
    }


def simulate_cohort(
    path,
    *,
    design: CohortDesign | None = None,
    duration_s: float = 120.0,
    fs: float = 100.0,
    seed: int = 0,
    workers: int = 2,
    progress: bool = True,
    keep_true: bool = False,
    overwrite: bool = False,
    calibration: bool = True,
) -> Path:
    """Simulate a lesion cohort into a directory that reads like real data.

    Parameters
    ----------
    path : path-like
        Output directory (created).
    design : CohortDesign, optional
        Default: Fayat's design (58 animals × 7 sessions).
    duration_s, fs : float
        Session length (s; the paper's is 1200) and sampling rate (Hz).
    seed : int
        Master seed; the output does not depend on ``workers``.
    workers : int
        Worker processes (:class:`concurrent.futures.ProcessPoolExecutor`); 1 runs in
        this process.
    progress : bool
        Show a tqdm progress bar.
    keep_true : bool
        Also store ``acc_true``, ``gyr_true`` and ``pos`` in each session.
    overwrite : bool
        Allow writing into a directory that already holds a cohort.
    calibration : bool
        Also write one tumble test per animal (``calibration/<subject>_tumble.nc``,
        50 Fibonacci orientations at 300 Hz, recorded with the animal's IMU) and name
        it in the manifest's ``calibration`` column.

    Returns
    -------
    pathlib.Path
        The cohort directory (read it with :func:`load_cohort`, or its
        ``manifest.csv`` with :func:`tiltlab.cohort.read_manifest`).
    """
    from tqdm import tqdm

    design = design or CohortDesign()
    if fs is None or not np.isfinite(fs) or fs <= 0:
        raise ValueError(f"fs must be a positive number of Hz, got {fs!r}")
    if duration_s <= 0:
        raise ValueError("duration_s must be positive")
    if workers < 1:
        raise ValueError("workers must be >= 1")
    path = Path(path)
    if (path / "sessions.csv").exists() and not overwrite:
        raise FileExistsError(f"{path} already holds a cohort (pass overwrite=True)")
    (path / "sessions").mkdir(parents=True, exist_ok=True)
    plan = session_plan(design, seed=seed, duration_s=duration_s, fs=fs)
    rows = plan.to_dict("records")
    animals = list({r["subject"]: r for r in rows}.values()) if calibration else []
    # compile (or load cached) kernels once here so that workers find them in the cache
    head_kinematics(0.1, fs, seed=0)
    results = []
    bar = tqdm(
        total=len(rows) + len(animals),
        desc="simulating sessions",
        unit="recording",
        disable=not progress,
    )
    if workers == 1:
        for r in animals:
            _simulate_tumble(r, str(path))
            bar.update()
        for r in rows:
            results.append(_simulate_one(r, str(path), keep_true))
            bar.update()
    else:
        with ProcessPoolExecutor(max_workers=workers) as ex:
            futs = [ex.submit(_simulate_tumble, r, str(path)) for r in animals]
            futs += [ex.submit(_simulate_one, r, str(path), keep_true) for r in rows]
            for fu in as_completed(futs):
                res = fu.result()
                if isinstance(res, dict):
                    results.append(res)
                bar.update()
    bar.close()
    real = pd.DataFrame(results).set_index("file").loc[plan["file"]].reset_index()
    truth = plan.merge(real, on="file")
    plan[["subject", "group", "timepoint", "hours", "file"]].to_csv(
        path / "sessions.csv", index=False
    )
    # the cohort manifest of tiltlab.cohort (written here: the simulator sits below it)
    manifest = pd.DataFrame(
        {
            "session": plan["session"],
            "subject": plan["subject"],
            "group": plan["group"],
            "timepoint": plan["timepoint"],
            "file": plan["file"],
            "reader": "netcdf",
            "reader_options": "",
            "calibration": plan["calibration"] if calibration else "",
            "hours": plan["hours"],
        }
    )
    manifest.to_csv(path / "manifest.csv", index=False)
    truth.to_csv(path / "truth.csv", index=False)
    meta = {
        "design": design.to_dict(),
        "seed": seed,
        "duration_s": float(duration_s),
        "fs": float(fs),
        "states": list(STATES),
        "n_sessions": len(rows),
        "generator": "tiltlab.simulate.simulate_cohort",
    }
    (path / "design.json").write_text(json.dumps(meta, indent=1))
    return path


@dataclass
class Cohort:
    """A cohort directory with its sessions, planted truth and design.

    A cohort directory: ``sessions`` table, planted ``truth`` (None for real data),
    ``design`` metadata.
    """

    path: Path
    sessions: pd.DataFrame
    truth: pd.DataFrame | None
    design: dict

    def __len__(self) -> int:
        """Return the number of sessions."""
        return len(self.sessions)

    def load(
        self, subject: str, timepoint: str, *, validate: bool = True
    ) -> xr.Dataset:
        """One session's Recording."""
        sel = self.sessions[
            (self.sessions.subject == subject) & (self.sessions.timepoint == timepoint)
        ]
        if len(sel) != 1:
            raise KeyError(
                f"no unique session for subject={subject!r}, timepoint={timepoint!r}"
            )
        return _io.load_netcdf(self.path / sel.iloc[0]["file"], validate=validate)

    def iter_sessions(
        self, *, validate: bool = True
    ) -> Iterator[tuple[pd.Series, xr.Dataset]]:
        """Yield ``(row, recording)`` for every session, in table order."""
        for _, row in self.sessions.iterrows():
            yield row, _io.load_netcdf(self.path / row["file"], validate=validate)


def load_cohort(path) -> Cohort:
    """Read a cohort directory.

    Read a cohort directory (``sessions.csv`` with columns subject, group,
    timepoint, hours, file; optional ``truth.csv`` and ``design.json``).

    Parameters
    ----------
    path : str or os.PathLike
        Cohort directory.

    Returns
    -------
    Cohort
        ``path``, ``sessions`` (DataFrame), ``truth`` (DataFrame or None) and
        ``design`` (dict, empty without ``design.json``).

    Raises
    ------
    FileNotFoundError
        If there is no ``sessions.csv`` or a session file is missing.
    ValueError
        If ``sessions.csv`` lacks a required column.
    """
    path = Path(path)
    table = path / "sessions.csv"
    if not table.is_file():
        raise FileNotFoundError(f"{path}: no sessions.csv, not a cohort directory")
    sessions = pd.read_csv(
        table, dtype={"subject": str, "group": str, "timepoint": str, "file": str}
    )
    missing = {"subject", "group", "timepoint", "file"} - set(sessions.columns)
    if missing:
        raise ValueError(f"{table}: missing column(s) {sorted(missing)}")
    absent = [f for f in sessions["file"] if not (path / f).is_file()]
    if absent:
        raise FileNotFoundError(
            f"{path}: {len(absent)} session file(s) missing, e.g. {absent[0]}"
        )
    truth = pd.read_csv(path / "truth.csv") if (path / "truth.csv").is_file() else None
    design = (
        json.loads((path / "design.json").read_text())
        if (path / "design.json").is_file()
        else {}
    )
    return Cohort(path=path, sessions=sessions, truth=truth, design=design)


def iter_sessions(
    path, *, validate: bool = True
) -> Iterator[tuple[pd.Series, xr.Dataset]]:
    """Shortcut for ``load_cohort(path).iter_sessions()``.

    Parameters
    ----------
    path : str or os.PathLike
        Cohort directory (see :func:`load_cohort`).
    validate : bool, default True
        Validate each Recording when it is read.

    Returns
    -------
    iterator of (pandas.Series, xarray.Dataset)
        ``(row, recording)`` for every session, in table order.
    """
    return load_cohort(path).iter_sessions(validate=validate)
