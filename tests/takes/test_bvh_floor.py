"""Up from the floor under the feet (core/floor_plane.py): a real walk (pymo_walk_meredith.bvh, Y up) turned the
ways a capture volume can be tilted, written Z up, or with the performer lying on the floor for most of the
take. Each comes out level and upright; the same files read with the floor estimate switched off (head over
feet only) do not, which is what the floor estimate is for."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinect_retarget.core import floor_plane
from kinect_retarget.takes import bvh
from tests.takes import baked_figure
from tests.takes import bvh_variants as bv

SOURCE = Path(__file__).resolve().parents[1] / "data" / "bvh" / "pymo_walk_meredith.bvh"
LYING = slice(60, 240)  # 60 % of the 300 frames: stands (walks) 0.5 s, lies 1.5 s, stands 0.5 s
STANDING = np.r_[0:60, 240:300]


@pytest.fixture(scope="module")
def source():
    return bv.load(SOURCE), bvh.read_bvh_skeleton(SOURCE), bvh.read(SOURCE, min_range=None)


def _lying(fig, motion):
    ankles = [motion.structure.roles[j].node for j in ("AnkleLeft", "AnkleRight")]
    return bv.lying_down(fig, motion.positions, ankles, LYING)


VARIANTS = {  # name: (make(figure, motion), lab axis nearest up, up in the file's axes)
    "y_up_tilted_10deg": (lambda f, m: bv.rotated(f, bv.about_x(10)), "+Y", bv.about_x(10) @ [0, 1, 0]),
    "z_up": (lambda f, m: bv.z_up(f), "+Z", np.array([0.0, 0, 1])),
    "z_up_tilted_10deg": (lambda f, m: bv.rotated(f, bv.about_x(80)), "+Z", bv.about_x(80) @ [0, 1, 0]),
    "lying_down": (_lying, "+Y", np.array([0.0, 1, 0])),
    "lying_down_tilted_7deg": (lambda f, m: bv.rotated(_lying(f, m), bv.about_x(-7)), "+Y",
                               bv.about_x(-7) @ [0, 1, 0]),
}


def _read(tmp_path, source, name):
    fig, motion, _ = source
    path = tmp_path / f"{name}.bvh"
    bv.write(VARIANTS[name][0](fig, motion), path)
    return bvh.read(path, min_range=None)


def _angle(a, b) -> float:
    return float(np.degrees(np.arccos(np.clip(np.dot(a, b) / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))))


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_floor_levels_the_take_and_stands_it_up(tmp_path, source, name):
    _, axis, truth = VARIANTS[name]
    ref = source[2]
    take = _read(tmp_path, source, name)
    meta = take.metadata
    assert meta["bvh_up_axis"] == axis and _angle(meta["bvh_up"], truth) < 1.0
    up_note = next(n for n in meta["bvh_mapping_notes"] if n.startswith("up: "))
    assert up_note.startswith("up: floor under the feet")
    assert ("not level" in up_note) == ("tilted" in name) and ("lies or bends" in up_note) == ("lying" in name)
    assert 1.4 <= meta["bvh_standing_height_m"] <= 1.9 and "warnings" not in meta
    joints, samples = baked_figure.bake(take)
    standing = STANDING if "lying" in name else np.arange(take.frame_count)
    fig = baked_figure.heights(joints[standing], take.skeleton)
    assert fig["upright"] and 1.3 <= fig["head_to_foot_m"] <= 1.8
    assert baked_figure.limb_direction_errors(joints[standing], samples[standing], ref).max() < 1.0
    if "lying" in name:  # lying on the floor: pelvis to head level with it, the body close to the floor
        k = take.skeleton.index
        trunk = joints[LYING, k("Head")] - joints[LYING, k("HipCenter")]
        assert np.all(np.abs(trunk[:, 2]) < 0.2 * np.linalg.norm(trunk, axis=-1))
    if name == "z_up":  # a level Z-up file reads exactly as the Y-up one
        np.testing.assert_allclose(take.positions, ref.positions, atol=2e-5)


@pytest.mark.parametrize("name", sorted(n for n in VARIANTS if n != "z_up"))
def test_head_over_feet_alone_gets_these_wrong(tmp_path, source, name, monkeypatch):
    """The same files with the floor estimate switched off: tilted takes lean, lying takes lie on their side."""
    monkeypatch.setattr(floor_plane, "MIN_CONTACTS", 10**9)
    _, axis, truth = VARIANTS[name]
    take = _read(tmp_path, source, name)
    meta = take.metadata
    assert "no floor estimate" in next(n for n in meta["bvh_mapping_notes"] if n.startswith("up: "))
    if "lying" in name:
        assert meta["bvh_up_axis"] != axis
    else:
        assert _angle(meta["bvh_up"], truth) > 9.0
        joints, samples = baked_figure.bake(take)
        assert baked_figure.limb_direction_errors(joints, samples, source[2]).max() > 5.0


@pytest.mark.parametrize("name, min_spread, reason", [
    ("cmu_01_01.bvh", None, "the feet stay on a patch too small to level"),  # stands in place
    ("kinect_openni_nite.bvh", None, "the feet stay on a patch too small to level"),
    ("biovision_example.bvh", None, "2 frame(s): too few to find the floor"),
    # a dance on one spot: with the spread check off, the plane through its feet is 30 degrees off level, and
    # the figure never stands up straight on it, which rejects it too
    ("cmu_131_03.bvh", 0.0, "the figure never stands up on the floor fitted under its feet (at best 20 degrees"),
])
def test_real_files_without_a_usable_floor_keep_head_over_feet(name, min_spread, reason, monkeypatch):
    if min_spread is not None:
        monkeypatch.setattr(floor_plane, "MIN_SPREAD", min_spread)
    motion = bvh.read_bvh_skeleton(SOURCE.parent / name)
    note = next(n for n in motion.structure.notes if n.startswith("up: "))
    assert note.startswith("up: head above the feet (no floor estimate: ") and reason in note
    assert (motion.up_axis, motion.up_sign) == (1, 1.0) and np.array_equal(motion.up, [0.0, 1, 0])


def test_a_real_walk_finds_its_floor_level():
    motion = bvh.read_bvh_skeleton(SOURCE)
    note = next(n for n in motion.structure.notes if n.startswith("up: "))
    assert note.startswith("up: floor under the feet") and ", level (" in note
    assert np.array_equal(motion.up, [0.0, 1, 0])
