import json
import struct

import numpy as np
import pytest

from kinect_retarget.autorig.mesh import MeshError, load_mesh

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
QUADS_AND_TRIS = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1/1 2/2 4/3 3/4\n"


def test_obj_fan_triangulates_and_filters_groups(tmp_path):
    p = tmp_path / "m.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ng a\nf 1 2 3\ng b\nf 1/1 2/2 4/3 3/4\n")
    assert load_mesh(p).faces.shape == (3, 3)
    part = load_mesh(p, group="a")
    assert part.faces.shape == (1, 3) and len(part.vertices) == 3
    np.testing.assert_array_equal(part.source_index, [0, 1, 2])
    with pytest.raises(MeshError, match="no faces in group 'zz'"):
        load_mesh(p, group="zz")


def test_obj_bad_face_names_the_line(tmp_path):
    p = tmp_path / "bad.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nf 1 2 9\n")
    with pytest.raises(MeshError, match="line 3"):
        load_mesh(p)


def test_ply_ascii_and_binary(tmp_path):
    header = "ply\nformat {}\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n" \
             "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
    a = tmp_path / "a.ply"
    a.write_text(header.format("ascii 1.0") + "".join(f"{x} {y} {z}\n" for x, y, z in V) + "3 0 1 2\n4 0 1 3 2\n")
    b = tmp_path / "b.ply"
    body = V.astype("<f4").tobytes() + bytes([3]) + np.array([0, 1, 2], "<i4").tobytes() + \
        bytes([4]) + np.array([0, 1, 3, 2], "<i4").tobytes()
    b.write_bytes(header.format("binary_little_endian 1.0").encode() + body)
    for p in (a, b):
        m = load_mesh(p)
        np.testing.assert_allclose(m.vertices, V)
        assert m.faces.tolist() == [[0, 1, 2], [0, 1, 3], [0, 3, 2]]



def test_cut_off_ply_names_the_file(tmp_path):
    header = "ply\nformat {}\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n" \
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
    a = tmp_path / "a.ply"
    a.write_text(header.format("ascii 1.0") + "0 0 0\n1 0")
    b = tmp_path / "b.ply"
    b.write_bytes(header.format("binary_little_endian 1.0").encode() + V.astype("<f4").tobytes()[:20])
    for p in (a, b):
        with pytest.raises(MeshError, match=f"{p.name}: PLY data do not match its header"):
            load_mesh(p)

def test_point_cloud_ply_is_refused(tmp_path):
    p = tmp_path / "cloud.ply"
    p.write_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                 "property float z\nend_header\n0 0 0\n1 1 1\n")
    with pytest.raises(MeshError, match="no faces"):
        load_mesh(p)


def test_glb_with_node_translation(tmp_path):
    idx = np.array([0, 1, 2, 0, 1, 3], "<u2")
    pos = V.astype("<f4")
    binary = pos.tobytes() + idx.tobytes()
    gltf = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "translation": [0, 0, 5]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "buffers": [{"byteLength": len(binary)}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                            {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                          {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]}
    js = json.dumps(gltf).encode()
    js += b" " * (-len(js) % 4)
    binary += b"\0" * (-len(binary) % 4)
    data = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(binary), 0x004E4942) + binary
    p = tmp_path / "m.glb"
    p.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(data)) + data)
    m = load_mesh(p)
    np.testing.assert_allclose(m.vertices, V + [0, 0, 5])
    assert m.faces.tolist() == [[0, 1, 2], [0, 1, 3]]


@pytest.mark.parametrize("content", [b"", b"hello world\n", b"\x00\x01\x02"])
def test_not_a_mesh(tmp_path, content):
    p = tmp_path / "x.obj"
    p.write_bytes(content)
    with pytest.raises(MeshError, match="x.obj"):
        load_mesh(p)


def test_missing_file(tmp_path):
    with pytest.raises(MeshError, match="cannot read"):
        load_mesh(tmp_path / "nope.obj")
