"""The structural mapper on a real Blender armature (how issue 16 will call it): Blender's human metarig,
bone heads as nodes plus the tails of leaf bones, rest pose only. Face, palm, finger, breast and heel bones
must not get in the way."""
import numpy as np

from kinect_retarget.core.structure_mapping import map_structure


def test_human_metarig_maps_by_structure(bpy_empty):
    import addon_utils
    bpy = bpy_empty
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    bones = list(bpy.context.object.data.bones)
    index = {b.name: i for i, b in enumerate(bones)}
    names = [b.name for b in bones]
    parents = [index[b.parent.name] if b.parent else -1 for b in bones]
    rest = [tuple(b.head_local) for b in bones]
    for b in bones:
        if not b.children:  # a leaf bone's tail is where its chain ends
            names.append(f"{b.name} tail")
            parents.append(index[b.name])
            rest.append(tuple(b.tail_local))
    ends = [i >= len(bones) for i in range(len(names))]
    m = map_structure(names, parents, np.array(rest), end_site=ends)
    got = {role: names[match.node] for role, match in m.roles.items() if match.node is not None}
    for side, s in (("Left", "L"), ("Right", "R")):
        assert got[f"Shoulder{side}"] == f"upper_arm.{s}" and got[f"Elbow{side}"] == f"forearm.{s}"
        assert got[f"Wrist{side}"] == f"hand.{s}" and got[f"Hip{side}"] == f"thigh.{s}"
        assert got[f"Knee{side}"] == f"shin.{s}" and got[f"Ankle{side}"] == f"foot.{s}"
        assert got[f"Foot{side}"] == f"toe.{s}"
    assert got["HipCenter"] == "spine" and got["Head"] == "spine.006"
    assert (m.up_axis, m.up_sign) == (2, 1.0)
    np.testing.assert_allclose(m.forward, [0, -1, 0], atol=1e-6)  # the metarig faces -Y
