import numpy as np

from kinect_retarget.core import quat
from kinect_retarget.core.rotation_modes import EULER_ORDERS, quat_to_axis_angle, quat_to_euler
from tests.conftest import assert_quat_equal


def _axis_rot(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.eye(3)
    m[i, i] = m[j, j] = c
    m[i, j], m[j, i] = -s, s
    return m


def test_matrix_round_trip_including_180_degrees(rng):
    q = quat.normalize(rng.normal(size=(2000, 4)))
    q[:4] = [[0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1], [0, 0.6, 0.8, 0]]  # half turns
    assert_quat_equal(quat.from_matrix(quat.to_matrix(q)), q, atol=1e-12)


def test_hamilton_product_matches_matrix_product(rng):
    a, b = quat.normalize(rng.normal(size=(2, 100, 4)))
    np.testing.assert_allclose(quat.to_matrix(quat.mul(a, b)), quat.to_matrix(a) @ quat.to_matrix(b), atol=1e-12)


def test_rotation_about_z_by_90_degrees_takes_x_to_y():
    q = np.array([np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)])
    np.testing.assert_allclose(quat.rotate(q, np.array([1.0, 0, 0])), [0, 1, 0], atol=1e-12)


def test_make_continuous_removes_sign_flips(rng):
    angles = np.linspace(0, 6 * np.pi, 300)
    q = np.stack([np.cos(angles / 2), np.sin(angles / 2), 0 * angles, 0 * angles], -1)
    flipped = q * np.where(rng.random(300) < 0.5, -1.0, 1.0)[:, None]
    out = quat.make_continuous(flipped)
    assert np.all(np.sum(out[1:] * out[:-1], -1) > 0)
    assert_quat_equal(out, q)


def test_angle_between_treats_q_and_minus_q_as_equal(rng):
    q = quat.normalize(rng.normal(size=(50, 4)))
    assert np.allclose(quat.angle_between(q, -q), 0.0, atol=1e-7)


def test_euler_orders_match_blender_definition(rng):
    # Blender's order 'XYZ' applies X first: R = Rz @ Ry @ Rx
    q = quat.normalize(rng.normal(size=(200, 4)))
    m = quat.to_matrix(q)
    for order in EULER_ORDERS:
        e = quat_to_euler(q, order)
        rebuilt = np.empty_like(m)
        for n in range(len(q)):
            r = np.eye(3)
            for axis_name in order:
                axis = "XYZ".index(axis_name)
                r = _axis_rot(axis, e[n, axis]) @ r
            rebuilt[n] = r
        np.testing.assert_allclose(rebuilt, m, atol=1e-9, err_msg=order)


def test_axis_angle(rng):
    q = quat.normalize(rng.normal(size=(20, 4)))
    aa = quat_to_axis_angle(q)
    back = np.concatenate([np.cos(aa[:, :1] / 2), np.sin(aa[:, :1] / 2) * aa[:, 1:]], axis=1)
    assert_quat_equal(back, q, atol=1e-12)


def test_axis_angle_keys_stay_continuous_through_half_turns():
    angles = np.linspace(0.1, 1.9 * np.pi, 200)  # one steady turn past 180° about a fixed axis
    axis = np.array([0.0, 0.6, 0.8])
    q = np.concatenate([np.cos(angles / 2)[:, None], np.sin(angles / 2)[:, None] * axis], axis=1)
    aa = quat_to_axis_angle(q)
    assert np.all(np.abs(np.diff(aa, axis=0)) < 0.1)
    np.testing.assert_allclose(aa[:, 0], angles, atol=1e-12)
