"""LaCanna's per-axis complementary filter: reference, limits and a-tau relation."""

import numpy as np
import pytest

from tiltlab.filters.complementary import complementary_angles

FS = 25.0


def _reference(acc, gyr_rad, dt, a):
    roll_acc = np.arctan2(acc[:, 1], acc[:, 2])
    pitch_acc = np.arctan2(-acc[:, 0], np.hypot(acc[:, 1], acc[:, 2]))
    out = [[roll_acc[0], pitch_acc[0]]]
    for i in range(1, len(acc)):
        r = a * (out[-1][0] + gyr_rad[i, 0] * dt) + (1 - a) * roll_acc[i]
        p = a * (out[-1][1] + gyr_rad[i, 1] * dt) + (1 - a) * pitch_acc[i]
        out.append([r, p])
    return np.degrees(np.array(out))


def _data(n=400, seed=0):
    rng = np.random.default_rng(seed)
    acc = np.array([0.1, -0.2, 1.0]) + rng.normal(0, 0.05, (n, 3))
    gyr = rng.normal(0, 0.3, (n, 3))  # rad/s
    return acc, gyr


@pytest.mark.parametrize("a", [0.0, 0.5, 0.9, 0.98, 1.0])
def test_matches_plain_python_reference(a):
    acc, gyr = _data()
    got = complementary_angles(acc, gyr, FS, a=a)
    np.testing.assert_allclose(got, _reference(acc, gyr, 1 / FS, a), atol=1e-10)


def test_a_one_integrates_the_gyroscope():
    acc, gyr = _data()
    got = complementary_angles(acc, gyr, FS, a=1.0)
    ref = _reference(acc, gyr, 1 / FS, 0.0)[0]
    expect = ref + np.degrees(np.cumsum(gyr[:, :2], axis=0) - gyr[0, :2]) / FS
    np.testing.assert_allclose(got, expect, atol=1e-9)
    np.testing.assert_allclose(complementary_angles(acc, gyr, FS, tau_s=np.inf), got)


def test_a_zero_returns_the_accelerometer_angles():
    acc, gyr = _data()
    got = complementary_angles(acc, gyr, FS, a=0.0)
    roll = np.degrees(np.arctan2(acc[:, 1], acc[:, 2]))
    pitch = np.degrees(np.arctan2(-acc[:, 0], np.hypot(acc[:, 1], acc[:, 2])))
    np.testing.assert_allclose(got, np.column_stack([roll, pitch]), atol=1e-12)


def test_tau_gives_a_first_order_step_response():
    # a step of the accelerometer angle at rest decays as exp(-t / tau)
    n, tau = 500, 2.0
    acc = np.tile([0.0, 0.0, 1.0], (n, 1))
    acc[1:] = [0.0, np.sin(0.2), np.cos(0.2)]
    roll = complementary_angles(acc, np.zeros((n, 3)), FS, tau_s=tau)[:, 0]
    t = np.arange(n) / FS
    np.testing.assert_allclose(
        roll, np.degrees(0.2) * (1 - np.exp(-t / tau)), atol=1e-9
    )


def test_does_not_mutate_and_refuses_bad_a():
    acc, gyr = _data(50)
    a0, g0 = acc.copy(), gyr.copy()
    complementary_angles(acc, gyr, FS, a=0.9)
    np.testing.assert_array_equal(acc, a0)
    np.testing.assert_array_equal(gyr, g0)
    with pytest.raises(ValueError, match="a must lie"):
        complementary_angles(acc, gyr, FS, a=1.5)
    with pytest.raises(ValueError, match="tau_s"):
        complementary_angles(acc, gyr, FS, tau_s=-1.0)
