"""Auto-Rig Mesh through bpy.ops on MakeHuman's base mesh, and a real take baked onto the result."""
import numpy as np
import pytest

from kinect_retarget.autorig import autorig, load_mesh
from kinect_retarget.core.skeletons import KINECT_V1

Y_UP_TO_Z_UP = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=float)  # Blender's OBJ import axes


@pytest.fixture(scope="module")
def body(data_dir):
    m = load_mesh(data_dir / "meshes" / "makehuman" / "base.obj", group="body")
    return m.vertices @ Y_UP_TO_Z_UP.T * 0.1, m.faces  # decimetres -> metres, facing -Y


def _add_body(bpy, body, location=(0.0, 0.0, 0.0)):
    from kinect_retarget.blender.mesh_autorig import new_mesh_object
    obj = new_mesh_object("Body", body[0], body[1], bpy.context.scene.collection)
    obj.location = location
    bpy.context.view_layer.update()
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj


def _weights(obj):
    names = {g.index: g.name for g in obj.vertex_groups}
    count = np.zeros(len(obj.data.vertices), int)
    total = np.zeros(len(obj.data.vertices))
    for v in obj.data.vertices:
        count[v.index] = sum(1 for g in v.groups if g.weight > 0)
        total[v.index] = sum(g.weight for g in v.groups)
    return names, count, total


def test_operator_rigs_the_mesh(registered, body):
    bpy = registered
    obj = _add_body(bpy, body, location=(1.0, 2.0, 0.0))
    assert bpy.ops.kinect_retarget.autorig_mesh() == {"FINISHED"}
    arm = bpy.context.active_object
    assert arm.type == "ARMATURE" and obj.parent == arm
    assert [b.name for b in arm.data.bones] == list(KINECT_V1.joints)
    assert any(m.type == "ARMATURE" and m.object == arm for m in obj.modifiers)
    # rest pose = the mesh's pose, in world space (the object was moved: world coordinates count)
    ref = autorig_from_world(body, (1.0, 2.0, 0.0))
    heads = {b.name: np.array(b.tail_local) for b in arm.data.bones}
    for j, name in enumerate(KINECT_V1.joints):
        if name != "HipCenter":
            np.testing.assert_allclose(heads[name], ref[j], atol=1e-4)
    names, count, total = _weights(obj)
    assert set(names.values()) == set(KINECT_V1.joints)
    assert count.max() <= 4 and count.min() >= 1
    np.testing.assert_allclose(total, 1.0, atol=1e-3)
    np.testing.assert_allclose(np.array(obj.matrix_world)[:3, 3], [1.0, 2.0, 0.0], atol=1e-6)  # not moved


def autorig_from_world(body, offset):
    from kinect_retarget.autorig import Mesh
    return autorig(Mesh(body[0] + np.asarray(offset), body[1])).joints


@pytest.mark.parametrize("shape, message", [("cube", "too small to rig"), ("sphere", "not a human")])
def test_not_a_human_leaves_scene_untouched(registered, shape, message):
    bpy = registered
    if shape == "cube":
        bpy.ops.mesh.primitive_cube_add()
    else:
        bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32)
    before = len(bpy.data.objects), len(bpy.data.armatures)
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.kinect_retarget.autorig_mesh()
    assert (len(bpy.data.objects), len(bpy.data.armatures)) == before
    assert bpy.context.active_object.parent is None


def test_take_baked_on_autorigged_mesh_deforms_cleanly(registered, body, data_dir):
    bpy = registered
    from kinect_retarget.blender.mesh_autorig import rig_mesh_object
    from kinect_retarget.blender.bake_take import bake_take
    from kinect_retarget.takes import load_take
    obj = _add_body(bpy, body)
    arm, _, _ = rig_mesh_object(bpy.context, obj)
    take = load_take(data_dir / "kinect_v2" / "Ges02_balancinghands.csv")
    result = bake_take(arm, take, preset="kinect")
    assert result.preset == "kinect"
    rest_edges = _edge_lengths(obj.data)
    first, last = result.frame_range
    for frame in np.linspace(first, last, 5).astype(int):
        bpy.context.scene.frame_set(int(frame))
        ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
        co = np.empty(len(ev.vertices) * 3)
        ev.vertices.foreach_get("co", co)
        assert np.isfinite(co).all()
        stretch = _edge_lengths(ev) / np.maximum(rest_edges, 1e-9)
        assert np.percentile(stretch, 99.9) < 3.0  # no tearing: edges keep their length within reason
        obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()


def _edge_lengths(me):
    co = np.empty(len(me.vertices) * 3)
    me.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    e = np.empty(len(me.edges) * 2, dtype=np.int64)
    me.edges.foreach_get("vertices", e)
    e = e.reshape(-1, 2)
    return np.linalg.norm(co[e[:, 0]] - co[e[:, 1]], axis=1)


def test_heat_weights_option(registered, body):
    bpy = registered
    obj = _add_body(bpy, body)
    assert bpy.ops.kinect_retarget.autorig_mesh(weights="HEAT") == {"FINISHED"}
    names, count, total = _weights(obj)
    assert set(names.values()) >= set(KINECT_V1.joints)
    assert count.max() <= 4 and count.min() >= 1
    np.testing.assert_allclose(total, 1.0, atol=1e-3)


def test_other_selected_meshes_are_bound(registered, body):
    """A garment kept as its own object (here: a shell around the left arm) follows the same rig."""
    bpy = registered
    from kinect_retarget.blender.mesh_autorig import new_mesh_object
    v, f = body
    left_arm = v[:, 0] > 0.25
    keep = left_arm[f].all(axis=1)
    used, inv = np.unique(f[keep], return_inverse=True)
    normals_out = (v[used] - v[used].mean(axis=0)) * 0.02
    sleeve = new_mesh_object("Sleeve", v[used] + normals_out, inv.reshape(-1, 3), bpy.context.scene.collection)
    obj = _add_body(bpy, body)
    sleeve.select_set(True)
    assert bpy.ops.kinect_retarget.autorig_mesh() == {"FINISHED"}
    arm = bpy.context.active_object
    assert sleeve.parent == arm and any(m.type == "ARMATURE" and m.object == arm for m in sleeve.modifiers)
    names, count, total = _weights(sleeve)
    np.testing.assert_allclose(total, 1.0, atol=1e-3)
    top = {}
    for vert in sleeve.data.vertices:
        g = max(vert.groups, key=lambda g: g.weight)
        top[names[g.group]] = top.get(names[g.group], 0) + 1
    assert max(top, key=top.get) in ("ElbowLeft", "WristLeft", "HandLeft")
    assert obj.parent == arm


def test_failure_after_armature_is_rolled_back(registered, body, monkeypatch):
    """If anything fails half-way (here: writing the weights), the mesh is left exactly as it was."""
    bpy = registered
    from kinect_retarget.blender import mesh_autorig as autorig_op
    obj = _add_body(bpy, body, location=(0.5, 0.0, 0.0))
    obj.vertex_groups.new(name="mine")

    def broken(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(autorig_op, "assign_weights", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        autorig_op.rig_mesh_object(bpy.context, obj)
    assert obj.parent is None and not obj.modifiers and [g.name for g in obj.vertex_groups] == ["mine"]
    assert not bpy.data.armatures or all(a.users == 0 for a in bpy.data.armatures)
    assert [o.type for o in bpy.data.objects] == ["MESH"]
    np.testing.assert_allclose(np.array(obj.matrix_world)[:3, 3], [0.5, 0, 0], atol=1e-6)


def test_paper_joints_and_paper_skeleton_built(registered, body):
    """Joints = Paper: the rig's joints are the paper rule's (K moves them), and the paper's skeleton points
    come out as a second armature with one bone per connection of their tree."""
    bpy = registered
    from kinect_retarget.autorig import Mesh
    from kinect_retarget.blender.io.paper_skeleton import tree_bones
    _add_body(bpy, body)
    assert bpy.ops.kinect_retarget.autorig_mesh(joints="PAPER", levels=5, normalization="GLOBAL",
                                                paper_skeleton=True) == {"FINISHED"}
    arm = bpy.context.active_object
    expected = autorig(Mesh(body[0], body[1]), levels=5, joints="paper", normalization="global")
    tails = {b.name: np.array(b.tail_local) for b in arm.data.bones}
    np.testing.assert_allclose(tails["ElbowLeft"], expected.joints[KINECT_V1.index("ElbowLeft")], atol=1e-4)
    points = bpy.data.objects[arm["kinect_retarget_paper_skeleton"]]
    assert points.type == "ARMATURE" and len(points.data.bones) == len(expected.paper.points) - 1
    assert len(tree_bones(expected.paper)) == len(expected.paper.tree)
    ends = np.array([b.tail_local for b in points.data.bones])
    assert np.abs(ends[:, None, :] - expected.paper.points[None]).max(axis=2).min(axis=1).max() < 1e-4
    assert not any(b.use_deform for b in points.data.bones)
