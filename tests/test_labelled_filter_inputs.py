"""Labelled inputs to the filter functions: units and ``fs`` attributes are honoured.

A Recording's own DataArrays (``rec["acc"]`` in g, ``rec["gyr"]`` in °/s) passed to
the array functions of :mod:`tiltlab.filters` are converted from their ``units`` (gyr to
rad/s, acc to m/s²) exactly as :func:`tiltlab.filters.estimate` converts a Recording;
contradictory sampling rates and misaligned inputs are refused by name; plain arrays
keep their documented units (gyr in rad/s) and their results.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from tiltlab import filters
from tiltlab import quaternion as quat
from tiltlab import units
from tiltlab._validate import RecordingError
from tiltlab.filters import adapters
from tiltlab.simulate import simulate_session

FS = 100.0
#: methods that use only the direction of acc (a hand conversion may keep it in g)
DIRECTION_ONLY = ("madgwick", "mahony", "ekf", "complementary")
#: methods that use acc in m/s² (labelled acc is converted; by hand: × G0)
SI_ACC = ("eskf", "smoother", "rts_smoother")
GYRO_METHODS = DIRECTION_ONLY + SI_ACC


@pytest.fixture(scope="module")
def rec():
    """30 s at 100 Hz; acc (and acc_true) in g, gyr (and gyr_true) in deg/s."""
    r = simulate_session(30.0, FS, seed=1)
    assert r["acc"].attrs["units"] == "g" and r["gyr"].attrs["units"] == "deg/s"
    assert r["acc_true"].attrs["units"] == "g"
    assert r["gyr_true"].attrs["units"] == "deg/s"
    return r


def _si(da: xr.DataArray) -> np.ndarray:
    """A labelled acc/gyr converted by hand to the kernels' unit (m/s², rad/s)."""
    to = "rad/s" if units.quantity_of(da.attrs["units"]) == "angular_velocity" else None
    return units.convert(da.values, da.attrs["units"], to or "m/s^2")


def _tilt_deg(q, q_ref) -> np.ndarray:
    return np.degrees(quat.angle_between(quat.gravity(q), quat.gravity(q_ref)))


def _mag(rec, unit="uT"):
    """A magnetometer consistent with the reference orientation (dip 60°, ENU)."""
    dip = np.radians(60.0)
    field = 40.0 * np.array([0.0, np.cos(dip), -np.sin(dip)])
    m = quat.rotate_inverse(
        rec["q_ref"].values, np.broadcast_to(field, (rec.sizes["time"], 3))
    )
    return xr.DataArray(
        m,
        dims=("time", "axis"),
        coords={"time": rec["time"].values, "axis": list("xyz")},
        attrs={"units": unit},
    )


# ------------------------------------------------------------------ the same numbers


@pytest.mark.parametrize("name", GYRO_METHODS)
def test_labelled_equals_hand_converted(rec, name):
    f = getattr(filters, name)
    q = f(rec["acc"], rec["gyr"], FS)
    assert type(q) is np.ndarray and q.shape == (rec.sizes["time"], 4)
    gyr_rad = np.radians(rec["gyr"].values)
    # exactly the SI arrays the kernels get from estimate()
    np.testing.assert_array_equal(q, f(_si(rec["acc"]), _si(rec["gyr"]), FS))
    np.testing.assert_array_equal(q, f(rec["acc"].values * units.G0, gyr_rad, FS))
    if name in DIRECTION_ONLY:  # acc's unit does not matter: g by hand is the same
        np.testing.assert_allclose(
            q, f(rec["acc"].values, gyr_rad, FS), rtol=0, atol=1e-9
        )


@pytest.mark.parametrize("name", GYRO_METHODS)
def test_labelled_equals_estimate_and_estimate_is_unchanged(rec, name):
    f = getattr(filters, name)
    est = filters.estimate(rec, name).values
    np.testing.assert_array_equal(f(rec["acc"], rec["gyr"], FS), est)
    # estimate still converts the Recording itself (g → m/s², deg/s → rad/s)
    np.testing.assert_array_equal(
        est, f(rec["acc"].values * units.G0, np.radians(rec["gyr"].values), FS)
    )


@pytest.mark.parametrize("name", GYRO_METHODS)
def test_labelled_tilt_error_is_small(rec, name):
    """The true signals (labelled g and deg/s, as the Recording's own): a few degrees
    of tilt error against q_ref, where reading deg/s as rad/s gave tens of degrees.
    (The measured acc/gyr of this simulated, uncalibrated sensor carry offsets of
    ~17 deg/s, which no 6D filter removes.)"""
    f = getattr(filters, name)
    q_ref = rec["q_ref"].values
    good = np.median(_tilt_deg(f(rec["acc_true"], rec["gyr_true"], FS), q_ref))
    acc_plain = rec["acc_true"].values * units.G0
    bad = np.median(_tilt_deg(f(acc_plain, rec["gyr_true"].values, FS), q_ref))
    assert good < 5.0, (name, good)
    assert bad > 30.0, (name, bad)


def test_other_functions_take_labels(rec):
    acc, gyr = rec["acc"], rec["gyr"]
    a_si, g_si = _si(acc), _si(gyr)
    # madgwick_batch, rest_gyro_bias, lowpass_tilt
    np.testing.assert_array_equal(
        filters.madgwick_batch(acc, gyr, FS, betas=[0.01, 0.1]),
        filters.madgwick_batch(a_si, g_si, FS, betas=[0.01, 0.1]),
    )
    b, rest = filters.rest_gyro_bias(acc, gyr, FS)
    b0, rest0 = filters.rest_gyro_bias(a_si, g_si, FS)
    np.testing.assert_array_equal(b, b0)
    np.testing.assert_array_equal(rest, rest0)
    q = filters.lowpass_tilt(acc, FS)
    assert type(q) is np.ndarray
    np.testing.assert_array_equal(q, filters.lowpass_tilt(a_si, FS))
    np.testing.assert_allclose(q, filters.lowpass_tilt(acc.values, FS), atol=1e-12)
    np.testing.assert_array_equal(q, filters.estimate(rec, "lowpass").values)
    # mahony / eskf biases come back in rad/s
    _, bias = filters.eskf(acc, gyr, FS, return_bias=True)
    _, bias0 = filters.eskf(a_si, g_si, FS, return_bias=True)
    np.testing.assert_array_equal(bias, bias0)


def test_magnetometer_labels(rec):
    acc, gyr, mag = rec["acc_true"], rec["gyr_true"], _mag(rec)
    a_si, g_si = _si(acc), _si(gyr)
    for name in ("madgwick", "mahony", "ekf", "eskf", "complementary"):
        f = getattr(filters, name)
        np.testing.assert_array_equal(
            f(acc, gyr, FS, mag=mag), f(a_si, g_si, FS, mag=mag.values)
        )
    # any magnetic-field unit: the values are kept (only the direction is used)
    np.testing.assert_array_equal(
        filters.ekf(acc, gyr, FS, mag=_mag(rec, "nT")),
        filters.ekf(a_si, g_si, FS, mag=mag.values),
    )
    q = filters.davenport(acc, mag, dip=np.radians(60.0))
    np.testing.assert_allclose(
        q, filters.davenport(acc.values, mag.values, dip=np.radians(60.0)), atol=1e-12
    )
    assert np.median(_tilt_deg(q, rec["q_ref"].values)) < 10.0  # raw acc: no filter
    assert filters.magnetic_dip(acc, mag) == pytest.approx(
        filters.magnetic_dip(acc.values, mag.values), abs=1e-12
    )
    np.testing.assert_allclose(
        filters.vector_observation(acc, FS, mag=mag),
        filters.vector_observation(acc.values, FS, mag=mag.values),
        atol=1e-12,
    )
    with pytest.raises(units.UnitsError, match=r"mag.*'g'"):
        filters.madgwick(acc, gyr, FS, mag=_mag(rec, "g"))


def test_a_recording_is_read_by_variable(rec):
    q = filters.madgwick(rec, rec)  # fs from the Recording's attrs
    np.testing.assert_array_equal(q, filters.estimate(rec, "madgwick").values)
    with pytest.raises(RecordingError, match="'mag'"):
        filters.madgwick(rec, rec, mag=rec)


ADAPTERS = {
    "run_vqf": "vqf",
    "run_offline_vqf": "vqf",
    "run_imufusion": "imufusion",
    "run_ahrs_madgwick": "ahrs",
    "run_ahrs_mahony": "ahrs",
    "run_ahrs_ekf": "ahrs",
    "run_riann": "riann",
}


@pytest.mark.parametrize("name", sorted(ADAPTERS))
def test_adapters_take_labels(rec, name):
    pytest.importorskip(ADAPTERS[name])
    short = rec.isel(time=slice(0, 300))
    f = getattr(adapters, name)
    np.testing.assert_array_equal(
        f(short["acc"], short["gyr"], FS), f(_si(short["acc"]), _si(short["gyr"]), FS)
    )
    with pytest.raises(RecordingError, match=r"200.*100|100.*200"):
        f(short["acc"].assign_attrs(fs=100.0), short["gyr"].assign_attrs(fs=200.0))


# ------------------------------------------------------------------ sampling rates


@pytest.mark.parametrize("name", GYRO_METHODS)
def test_fs_argument_contradicting_the_attribute_is_refused(rec, name):
    f = getattr(filters, name)
    acc = rec["acc"].assign_attrs(fs=FS)
    gyr = rec["gyr"].assign_attrs(fs=FS)
    with pytest.raises(RecordingError, match=r"fs = 200.*100 Hz"):
        f(acc, gyr, 200.0)
    # the attributes give fs when the argument is omitted
    np.testing.assert_array_equal(f(acc, gyr), f(acc, gyr, FS))


@pytest.mark.parametrize("name", GYRO_METHODS)
def test_acc_and_gyr_rates_disagreeing_are_refused(rec, name):
    f = getattr(filters, name)
    acc = rec["acc"].assign_attrs(fs=100.0)
    gyr = rec["gyr"].assign_attrs(fs=200.0)
    for fs in (None, 100.0, 200.0):
        with pytest.raises(RecordingError, match=r"acc.*gyr.*100 Hz.*200 Hz"):
            f(acc, gyr, fs)


def test_fs_contradicting_the_time_coordinate_is_refused(rec):
    # rec["acc"] has no fs attribute (the Recording holds it), but a time axis
    with pytest.raises(RecordingError, match=r"fs = 200 Hz.*time.*100 Hz"):
        filters.madgwick(rec["acc"], rec["gyr"], 200.0)
    with pytest.raises(RecordingError, match=r"fs = 50 Hz.*time.*100 Hz"):
        filters.lowpass_tilt(rec["acc"], 50.0)


def test_lowpass_fs_contradicting_the_attribute_is_refused(rec):
    acc = rec["acc"].assign_attrs(fs=FS)
    with pytest.raises(RecordingError, match=r"fs = 200.*100 Hz"):
        filters.lowpass_tilt(acc, 200.0)
    np.testing.assert_array_equal(
        filters.lowpass_tilt(acc), filters.lowpass_tilt(acc, FS)
    )


def test_fs_still_mandatory(rec):
    acc, gyr = rec["acc"].values, np.radians(rec["gyr"].values)
    with pytest.raises(ValueError, match="mandatory"):
        filters.madgwick(acc, gyr)
    with pytest.raises(ValueError, match="mandatory"):
        filters.lowpass_tilt(acc)
    # labelled but without an fs attribute: still needed
    with pytest.raises(RecordingError, match=r"\bfs\b.*pass fs="):
        filters.mahony(rec["acc"], rec["gyr"])


def test_davenport_rates_and_times_must_agree(rec):
    acc, mag = rec["acc_true"], _mag(rec)
    with pytest.raises(RecordingError, match=r"acc.*mag.*100 Hz.*50 Hz"):
        filters.davenport(
            acc.assign_attrs(fs=100.0), mag.assign_attrs(fs=50.0), dip=1.0
        )
    with pytest.raises(RecordingError, match=r"acc.*mag.*100 Hz.*50 Hz"):
        filters.magnetic_dip(acc.assign_attrs(fs=100.0), mag.assign_attrs(fs=50.0))
    with pytest.raises(RecordingError, match="not aligned"):
        filters.magnetic_dip(acc, mag.assign_coords(time=mag["time"] + 1.0))


# ------------------------------------------------------------------ time coordinates


@pytest.mark.parametrize("name", GYRO_METHODS)
def test_time_coordinates_of_different_lengths_are_refused(rec, name):
    f = getattr(filters, name)
    with pytest.raises(RecordingError, match=r"different lengths.*3000.*2999"):
        f(rec["acc"], rec["gyr"].isel(time=slice(0, -1)), FS)
    with pytest.raises(RecordingError, match="not aligned"):
        f(rec["acc"], rec["gyr"].assign_coords(time=rec["time"] + 0.5), FS)


# ------------------------------------------------------------------ units


def test_units_are_required_where_they_matter(rec):
    gyr_bare = xr.DataArray(rec["gyr"].values, dims=("time", "axis"))
    acc_bare = xr.DataArray(rec["acc"].values, dims=("time", "axis"))
    for name in GYRO_METHODS:
        with pytest.raises(RecordingError, match=r"gyr.*'units'"):
            getattr(filters, name)(rec["acc"], gyr_bare, FS)
    # acc without units: fine where only its direction is used ...
    gyr_rad = np.radians(rec["gyr"].values)
    for name in DIRECTION_ONLY:
        f = getattr(filters, name)
        np.testing.assert_array_equal(
            f(acc_bare, gyr_rad, FS), f(rec["acc"].values, gyr_rad, FS)
        )
    np.testing.assert_array_equal(
        filters.lowpass_tilt(acc_bare, FS), filters.lowpass_tilt(rec["acc"].values, FS)
    )
    # ... refused where the method uses m/s²
    for name in SI_ACC:
        with pytest.raises(RecordingError, match=r"acc.*'units'.*m/s²"):
            getattr(filters, name)(acc_bare, rec["gyr"], FS)


def test_wrong_or_unknown_units_are_refused_by_name(rec):
    with pytest.raises(units.UnitsError, match=r"acc.*deg/s"):
        filters.madgwick(rec["acc"].assign_attrs(units="deg/s"), rec["gyr"], FS)
    with pytest.raises(units.UnitsError, match=r"gyr.*'g'"):
        filters.madgwick(rec["acc"], rec["gyr"].assign_attrs(units="g"), FS)
    with pytest.raises(units.UnitsError, match=r"gyr.*furlong"):
        filters.eskf(rec["acc"], rec["gyr"].assign_attrs(units="furlong/s"), FS)


def test_rad_s_labels_and_mixed_inputs(rec):
    gyr_rad = np.radians(rec["gyr"].values)
    g_lab = rec["gyr"].copy(data=gyr_rad).assign_attrs(units="rad/s")
    a_si = _si(rec["acc"])
    np.testing.assert_array_equal(
        filters.mahony(rec["acc"], g_lab, FS), filters.mahony(a_si, gyr_rad, FS)
    )
    # a plain gyr next to a labelled acc keeps its documented unit, rad/s
    np.testing.assert_array_equal(
        filters.mahony(rec["acc"], gyr_rad, FS), filters.mahony(a_si, gyr_rad, FS)
    )


def test_transposed_labelled_input(rec):
    acc_t = rec["acc"].transpose("axis", "time")
    np.testing.assert_array_equal(
        filters.ekf(acc_t, rec["gyr"], FS), filters.ekf(rec["acc"], rec["gyr"], FS)
    )


# ------------------------------------------------------------------ plain arrays


def _fixed(n=400, fs=100.0):
    t = np.arange(n) / fs
    acc = np.stack(
        [
            0.8 * np.sin(1.3 * t),
            0.5 * np.cos(0.7 * t) + 0.3,
            9.6 + 0.2 * np.sin(3.1 * t),
        ],
        1,
    )
    gyr = np.stack(
        [0.4 * np.sin(2.1 * t), -0.3 * np.cos(1.1 * t), 0.2 * np.sin(0.5 * t) + 0.01], 1
    )
    mag = np.stack(
        [5 + np.sin(0.9 * t), 20 + 2 * np.cos(0.4 * t), -40 + np.sin(0.3 * t)], 1
    )
    return acc, gyr, mag, fs


#: results on plain arrays before labels were read (sum of the output, last 4 values)
PLAIN = {
    "madgwick": (458.34677651470327, [0.9455304907994693, 0.07597814323174613, 0.15308472781471108, 0.27706403380710876]),
    "madgwick9": (493.58561800607526, [0.9258179941232204, 0.05848013977884965, 0.1316805563911445, 0.3494300303030947]),
    "mahony": (452.9604039412644, [0.9498000926919196, 0.051068567314977525, 0.1353881002208083, 0.2773839354999078]),
    "mahony9b": (0.845045121367787, [0.003821956066678217, 0.006787432765105344, 0.004730120403652884, 0.0038668900338740863]),
    "ekf": (452.2484216116062, [0.9130035155551237, 0.034882038757442564, 0.1638194711132595, 0.37198253297739836]),
    "ekf9": (487.31543085134604, [0.9440190375889045, 0.057332984888655555, 0.138553397377222, 0.2938433963673595]),
    "eskf": (449.90022411394625, [0.9595163257561895, 0.04458963185833834, 0.1474424355449844, 0.23579845957648435]),
    "eskf9b": (39.18547986969167, [0.26642424973233014, 0.03888280169099316, 0.03688515138578152, 0.2669348054977433]),
    "complementary": (453.1760943004308, [0.9499695262133825, 0.05282242847583154, 0.1331374776430749, 0.27756459133448075]),
    "complementary9": (487.08196824978273, [0.946782383880213, 0.05131923687633717, 0.13372409218115835, 0.2882487132163065]),
    "smoother": (451.9501727473076, [0.9430591608413997, 0.05279019979548883, 0.18501682282602788, 0.2713326173353102]),
    "rts": (448.36549162080064, [0.9447600378863731, 0.035990773199153434, 0.19470035342370934, 0.26119898053811175]),
    "lowpass": (405.50251198535506, [0.9991558531003626, -0.007943576437184035, 0.04030484845118749, 0.0]),
    "davenport": (454.63414499458634, [0.9982449870076064, 0.01885218533727193, 0.03546021642273927, 0.043521420857384516]),
    "dip": (1.022153316244651, [1.022153316244651]),
    "vo": (452.7606748528858, [0.9983340864903387, 0.013323315252139612, 0.03570070730464594, 0.043324364047739754]),
}  # fmt: skip


def test_plain_arrays_unchanged():
    acc, gyr, mag, fs = _fixed()
    got = {
        "madgwick": filters.madgwick(acc, gyr, fs),
        "madgwick9": filters.madgwick(acc, gyr, fs, mag=mag),
        "mahony": filters.mahony(acc, gyr, fs),
        "mahony9b": filters.mahony(acc, gyr, fs, mag=mag, return_bias=True)[1],
        "ekf": filters.ekf(acc, gyr, fs),
        "ekf9": filters.ekf(acc, gyr, fs, mag=mag),
        "eskf": filters.eskf(acc, gyr, fs),
        "eskf9b": filters.eskf(acc, gyr, fs, mag=mag, return_bias=True)[1],
        "complementary": filters.complementary(acc, gyr, fs),
        "complementary9": filters.complementary(acc, gyr, fs, mag=mag),
        "smoother": filters.smoother(acc, gyr, fs),
        "rts": filters.rts_smoother(acc, gyr, fs),
        "lowpass": filters.lowpass_tilt(acc, fs),
        "davenport": filters.davenport(acc, mag, dip=1.0),
        "dip": np.array(filters.magnetic_dip(acc, mag)),
        "vo": filters.vector_observation(acc, fs, mag=mag),
    }
    for key, (total, tail) in PLAIN.items():
        v = got[key]
        assert type(v) is np.ndarray, key
        assert float(np.sum(v)) == pytest.approx(total, rel=1e-10, abs=1e-12), key
        np.testing.assert_allclose(np.ravel(v)[-len(tail) :], tail, rtol=0, atol=1e-10)
    # plain deg/s values are (still) read as rad/s: nothing is guessed
    q_deg = filters.madgwick(acc, np.degrees(gyr), fs)
    assert not np.allclose(q_deg, got["madgwick"], atol=1e-3)
