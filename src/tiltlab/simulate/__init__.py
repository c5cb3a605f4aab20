"""Simulated recordings with ground truth.

* :mod:`~tiltlab.simulate.kinematics` — rat head motion driven by behavioural states
  (:func:`head_kinematics`, :class:`BehaviourParams`, :class:`Lesion`);
* :mod:`~tiltlab.simulate.sensor` — IMU error model and freely-moving sessions
  (:class:`SensorModel`, :func:`apply_sensor_model`, :func:`simulate_session`);
* :mod:`~tiltlab.simulate.tumble` — tumble tests on a Fibonacci lattice
  (:func:`tumble_test`, on :func:`tiltlab.sphere.fibonacci_lattice`);
* :mod:`~tiltlab.simulate.mocap` — head markers and TTL synchronisation
  (:func:`mocap_markers`, :func:`simulate_mocap_session`);
* :mod:`~tiltlab.simulate.study` — a motion-capture study: rats with their own sensor,
  tumble-test calibration and session (:func:`mocap_study`);
* :mod:`~tiltlab.simulate.cohort` — lesion cohorts on disk
  (:func:`simulate_cohort`, :func:`load_cohort`);
* :mod:`~tiltlab.simulate.export` — a Recording written as a phone logger's export, one
  CSV per sensor on its own jittery clock (:func:`phone_export`);
* :mod:`~tiltlab.simulate.track` — bio-logging demonstrations: 3-D tracks for dead
  reckoning and flapping/gliding heave (:func:`simulate_track`, :func:`simulate_heave`).

The statistics that compare simulated with real recordings live in
:mod:`tiltlab.behavior` (:func:`~tiltlab.behavior.realism_table`).

Every simulated recording is a validated Recording (:mod:`tiltlab.schema`) with its
ground truth (``q_ref``, ``a_lin``, ``state``, ``true_*`` attrs) and is bit-identical
for a given seed.
"""

from .kinematics import (
    STATES,
    BehaviourParams,
    Lesion,
    TrueMotion,
    behaviour_bouts,
    head_kinematics,
    target_tilt,
)
from .sensor import (
    ACC_OFFSET_RANGE_G,
    GYR_OFFSET_RANGE_DPS,
    SensorModel,
    apply_sensor_model,
    magnetometer_readings,
    draw_sensor,
    recording_from_motion,
    simulate_session,
    true_sensor_values,
)
from .tumble import stage_angles, stage_quaternion, tumble_test, zoh_angular_velocity
from .export import PHONE_FILES, phone_export
from .mocap import (
    MarkerSupport,
    head_frame_from_markers,
    mocap_markers,
    simulate_mocap_session,
)
from .cohort import (
    ANAESTHESIA,
    EFFECTS,
    FAYAT_GROUPS,
    HOURS,
    TIME_POINTS,
    Cohort,
    CohortDesign,
    iter_sessions,
    load_cohort,
    session_plan,
    simulate_cohort,
)
from .study import MocapRat, mocap_study
from .track import Track, simulate_heave, simulate_track
from .turntable import TurntableMotion, back_and_forth, radian_test
import tiltlab.simulate.cohort as _cohort
import tiltlab.simulate.export as _export
import tiltlab.simulate.kinematics as _kinematics
import tiltlab.simulate.mocap as _mocap
import tiltlab.simulate.sensor as _sensor
import tiltlab.simulate.study as _study
import tiltlab.simulate.track as _track
import tiltlab.simulate.tumble as _tumble
import tiltlab.simulate.turntable as _turntable

__all__ = [
    *_kinematics.__all__,
    *_sensor.__all__,
    *_tumble.__all__,
    *_export.__all__,
    *_mocap.__all__,
    *_study.__all__,
    *_cohort.__all__,
    *_track.__all__,
    *_turntable.__all__,
]
