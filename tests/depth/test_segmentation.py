"""Segmentation stage: floor from gravity + plane fit, connected components, person choice."""
from __future__ import annotations

import numpy as np

from kinect_retarget.sim.depth_render import Room, gravity_in_camera, room_depth
from kinect_retarget.depth.segmentation import DepthGrid, connected_components, find_people, fit_floor


def _mm(depth_m):
    return np.where(np.isfinite(depth_m), np.round(depth_m * 1000), 0).astype(np.uint16)


def test_floor_plane_from_gravity_and_fit(camera):
    for tilt in (0.0, 12.0):
        depth = room_depth(Room(floor_y=-0.85, back_wall_z=4.0), camera, tilt)
        g = gravity_in_camera(tilt)
        grid = DepthGrid.from_mm(_mm(depth), camera)
        floor = fit_floor(grid, g)
        assert floor is not None
        assert np.degrees(np.arccos(np.clip(floor.normal @ -g, -1, 1))) < 1.0
        assert abs(floor.height(np.zeros(3)) - 0.85) < 0.02      # the camera is 0.85 m above the floor
        # a wrong gravity guess (level instead of 12 deg) is corrected by the plane fit only within 10 deg
    depth = room_depth(Room(floor_y=-0.85, back_wall_z=4.0), camera, 6.0)
    floor = fit_floor(DepthGrid.from_mm(_mm(depth), camera), np.array([0.0, -1.0, 0.0]))
    assert np.degrees(np.arccos(floor.normal @ -gravity_in_camera(6.0))) < 1.0


def test_no_floor_in_view_gives_none(camera):
    grid = DepthGrid.from_mm(np.zeros((480, 640), np.uint16), camera)
    assert fit_floor(grid, None) is None


def test_connected_components_split_at_depth_steps():
    z = np.full((30, 40), 2.0)
    z[:, 20:] = 1.5                                # two surfaces 50 cm apart, touching in the image
    mask = np.ones_like(z, bool)
    mask[10:12, :] = False                         # and a gap splitting the top from the bottom
    lab = connected_components(mask, z, max_jump=0.1)
    assert len(np.unique(lab[lab >= 0])) == 4
    assert (lab[~mask] == -1).all()
    assert len(np.unique(connected_components(mask, z, max_jump=1.0)[mask])) == 2


def test_rendered_person_is_found_among_furniture_and_a_bystander(data_dir, camera):
    from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence
    seq = render_sequence(str(data_dir / "mocap_bvh" / "131_02.bvh"), str(data_dir / "meshes" / "makehuman"),
                          Scenario(second_person=(1.2, 3.5), boxes=[((-1.6, -0.9, 2.0), (-0.9, -0.1, 2.6))], seed=1),
                          frames=1)
    grid = DepthGrid.from_mm(seq.mm[0], camera)
    floor = fit_floor(grid, seq.gravity)
    people = find_people(grid, floor, seq.gravity)
    assert len(people) >= 2                        # performer and bystander (the box may also pass the size test)
    hip = seq.joints[0, 0]
    performer = min(people, key=lambda p: np.linalg.norm(p.centroid - hip))
    assert np.linalg.norm(performer.centroid[[0, 2]] - hip[[0, 2]]) < 0.2
    assert 1.3 < performer.height < 1.8
    from kinect_retarget.depth.skeleton_tracker import SkeletonTracker
    tr = SkeletonTracker(gravity=seq.gravity)
    tr.update(seq.mm[0], 0.0)
    assert tr.last_mask is not None and np.array_equal(tr.last_mask, performer.mask)


def _body_with_pieces(camera, pieces):
    """A person-sized rounded slab (its front 2.5 m away; pre-segmented: no floor, no background) and square
    pieces ((column, row, half size in pixels, depth m))."""
    v, u = np.mgrid[0:480, 0:640].astype(float)
    across = (u - 320.0) / 50.0                          # the body: 100 px (about 0.5 m) wide, 1.7 m tall
    depth = np.where((np.abs(across) < 1) & (v > 40) & (v < 380), 2.8 - 0.3 * np.sqrt(1 - np.minimum(across ** 2, 1)),
                     np.nan)
    for col, row, half, z in pieces:
        depth[row - half:row + half, col - half:col + half] = z
    return DepthGrid.from_mm(_mm(depth), camera)


def test_an_arm_pointing_at_the_sensor_is_attached_to_its_person(camera):
    # a forearm seen end-on is a blob 40 cm before the chest: a component of its own, too small for a person
    grid = _body_with_pieces(camera, [(310, 150, 12, 2.1)])
    assert len(np.unique(connected_components(grid.valid, grid.z, 0.2)[grid.valid])) == 2
    people = find_people(grid, None, None)
    assert len(people) == 1
    blob = np.zeros((480, 640), bool)
    blob[138:162, 298:322] = True
    cells = blob[2::4, 2::4]
    assert people[0].mask[cells].all()
    assert people[0].pixels == people[0].mask.sum() - cells.sum()    # its size (and centroid) stay the body's


def test_pieces_beside_far_before_or_as_big_as_the_person_are_not_theirs(camera):
    for piece in ((400, 150, 12, 2.45),                 # beside the body, outside its silhouette's box
                  (310, 150, 12, 1.6),                  # 0.9 m before it: not an arm
                  (310, 200, 48, 2.1)):                 # 40 % of its size: another thing in front of it
        grid = _body_with_pieces(camera, [piece])
        people = find_people(grid, None, None)
        body = max(people, key=lambda p: p.pixels)
        col, row, half, _ = piece
        blob = np.zeros((480, 640), bool)
        blob[row - half:row + half, col - half:col + half] = True
        assert not body.mask[blob[2::4, 2::4]].any(), piece


def test_in_view_is_inside_the_grid_not_on_or_past_its_last_cell(camera):
    grid = DepthGrid.from_mm(np.full((480, 640), 2000, np.uint16), camera)
    centre = grid.xyz[60, 80]
    last = grid.xyz[119, 159]                              # the grid's last row and column
    beyond = centre + np.array([2.0, 0.0, 0.0])            # 2 m to the side at 2 m: out of view
    assert grid.in_view(np.array([centre, last, beyond])).tolist() == [True, False, False]
    assert grid.in_view(np.zeros((2, 5, 3)) + centre).shape == (2, 5)
