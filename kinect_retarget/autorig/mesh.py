"""Triangle meshes from files: Wavefront OBJ, PLY (ASCII and binary) and binary glTF (.glb).

Pure numpy: the readers cover what body meshes use (positions and faces); anything else in the file is
skipped. Bad input raises MeshError naming the file and, where it applies, the line.
"""
from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np


class MeshError(ValueError):
    """The input is not a usable mesh (or not a human one); the message says what was found."""


@dataclass
class Mesh:
    """vertices (V, 3) float64 in the file's units and axes; faces (T, 3) int64 triangles (0-based)."""

    vertices: np.ndarray
    faces: np.ndarray
    name: str = "mesh"
    source_index: np.ndarray | None = None  # for a part of a file: each vertex's index in the whole file

    def __post_init__(self) -> None:
        self.vertices = np.asarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.asarray(self.faces, dtype=np.int64).reshape(-1, 3)
        if len(self.vertices) == 0:
            raise MeshError(f"{self.name}: no vertices")
        if len(self.faces) == 0:
            raise MeshError(f"{self.name}: {len(self.vertices)} vertices but no faces: not a surface mesh")
        if not np.all(np.isfinite(self.vertices)):
            bad = int(np.argmax(~np.isfinite(self.vertices).all(axis=1)))
            raise MeshError(f"{self.name}: vertex {bad} has a NaN or infinite coordinate")
        if self.faces.min() < 0 or self.faces.max() >= len(self.vertices):
            raise MeshError(f"{self.name}: a face refers to vertex {int(self.faces.max())} but there are only "
                            f"{len(self.vertices)} vertices")

    def submesh(self, face_index: np.ndarray, name: str | None = None) -> tuple["Mesh", np.ndarray]:
        """The faces listed, with only the vertices they use; also returns the old index of each new vertex."""
        faces = self.faces[face_index]
        used, inverse = np.unique(faces, return_inverse=True)
        return Mesh(self.vertices[used], inverse.reshape(-1, 3), name or self.name), used


def subdivide(mesh: Mesh, face_mask: np.ndarray | None = None) -> Mesh:
    """Split the chosen triangles (all by default) into four at their edge midpoints. Splitting only some
    leaves T-junctions and uneven triangle sizes, which is how some real meshes come."""
    chosen = np.ones(len(mesh.faces), bool) if face_mask is None else np.asarray(face_mask, bool)
    f = mesh.faces[chosen]
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    uniq, inv = np.unique(e, axis=0, return_inverse=True)
    mid = len(mesh.vertices) + inv.reshape(3, -1).T  # (T, 3) midpoints of edges 01, 12, 20
    verts = np.concatenate([mesh.vertices, mesh.vertices[uniq].mean(axis=1)])
    a, b, c = f.T
    ab, bc, ca = mid.T
    new = [np.stack(x, 1) for x in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))]
    return Mesh(verts, np.concatenate([mesh.faces[~chosen]] + new), mesh.name + "-subdivided")


def triangle_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F,) area of each triangle of `faces` (F, 3)."""
    t = vertices[faces]
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


def nearest_vertex(points: np.ndarray, targets: np.ndarray, chunk: int = 1024) -> np.ndarray:
    """Index of the nearest target for each point (brute force in float32 chunks: no scipy in Blender)."""
    out = np.empty(len(points), dtype=np.int64)
    t = targets.astype(np.float32)
    t2 = (t ** 2).sum(axis=1)
    for s in range(0, len(points), chunk):
        p = points[s:s + chunk].astype(np.float32)
        out[s:s + chunk] = np.argmin(t2[None, :] - 2 * p @ t.T, axis=1)
    return out


def triangulate(polygons: list[list[int]]) -> np.ndarray:
    """Fan-triangulate polygons given as vertex-index lists (vectorised per polygon size)."""
    out = []
    by_size: dict[int, list[list[int]]] = {}
    for p in polygons:
        by_size.setdefault(len(p), []).append(p)
    for n, polys in by_size.items():
        if n < 3:
            continue
        a = np.asarray(polys, dtype=np.int64)
        k = np.arange(1, n - 1)
        out.append(np.stack([np.repeat(a[:, :1], n - 2, axis=1), a[:, k], a[:, k + 1]], axis=-1).reshape(-1, 3))
    return np.concatenate(out) if out else np.zeros((0, 3), np.int64)


def _read_bytes(path: Path, limit: int = -1) -> bytes:
    """The file's bytes (the first `limit` only when given), or a MeshError naming it."""
    try:
        with open(path, "rb") as fh:
            return fh.read(limit)
    except OSError as e:
        raise MeshError(f"{path}: cannot read: {e.strerror or e}") from None


def read_obj(path: str | Path) -> tuple[np.ndarray, list[list[int]], list[str]]:
    """An OBJ's vertices (V, 3), polygons (0-based vertex lists, as in the file) and each polygon's `g`/`o`
    group: the one OBJ parser (meshes here, MakeHuman's body in sim/makehuman_body.py)."""
    path = Path(path)
    verts: list[list[float]] = []
    polys: list[list[int]] = []
    poly_group: list[str] = []
    current = ""
    text = _read_bytes(path).decode("utf-8", errors="replace")
    for lineno, line in enumerate(text.splitlines(), 1):
        if line.startswith("v "):
            parts = line.split()
            try:
                verts.append([float(parts[1]), float(parts[2]), float(parts[3])])
            except (IndexError, ValueError):
                raise MeshError(f"{path}, line {lineno}: bad vertex {line.strip()!r}") from None
        elif line.startswith("f "):
            try:
                idx = [int(tok.split("/")[0]) for tok in line.split()[1:]]
            except ValueError:
                raise MeshError(f"{path}, line {lineno}: bad face {line.strip()!r}") from None
            n = len(verts)
            idx = [i - 1 if i > 0 else n + i for i in idx]  # OBJ is 1-based; negatives count back
            if len(idx) < 3 or min(idx) < 0 or max(idx) >= n:
                raise MeshError(f"{path}, line {lineno}: face {line.strip()!r} refers to a vertex not defined "
                                f"before it ({n} vertices so far)")
            polys.append(idx)
            poly_group.append(current)
        elif line.startswith(("g ", "o ")):
            current = line[2:].strip()
    if not verts:
        raise MeshError(f"{path}: no 'v' lines: not an OBJ mesh")
    return np.asarray(verts), polys, poly_group


def group_polygons(path: str | Path, polys: list[list[int]], poly_group: list[str], group: str) -> list[list[int]]:
    """The polygons of one group; MeshError lists the groups there are when it has none."""
    keep = [p for p, g in zip(polys, poly_group) if g == group]
    if not keep:
        names = sorted(set(poly_group))
        raise MeshError(f"{path}: no faces in group {group!r} (groups: {', '.join(names[:12])}"
                        f"{' ...' if len(names) > 12 else ''})")
    return keep


def mesh_from_obj(path: str | Path, verts: np.ndarray, polys: list[list[int]], poly_group: list[str],
                  group: str | None = None) -> Mesh:
    """A triangle Mesh from read_obj's result; with `group`, only that group's faces and the vertices they
    use (`source_index` maps them back to the file's)."""
    path = Path(path)
    if group is not None:
        polys = group_polygons(path, polys, poly_group, group)
    if not polys:
        raise MeshError(f"{path}: {len(verts)} vertices but no faces: not a surface mesh")
    full = Mesh(verts, triangulate(polys), path.stem)
    if group is None:
        return full
    part, used = full.submesh(np.arange(len(full.faces)), f"{path.stem}:{group}")
    part.source_index = used
    return part


def load_obj(path: str | Path, group: str | None = None) -> Mesh:
    """Read an OBJ. With `group`, keep only the faces of that `g`/`o` group (e.g. MakeHuman's 'body')."""
    return mesh_from_obj(path, *read_obj(path), group=group)


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def load_ply(path: str | Path) -> Mesh:
    """Read a PLY (ascii, binary_little_endian, binary_big_endian): vertex x y z and face vertex lists."""
    path = Path(path)
    data = _read_bytes(path)
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise MeshError(f"{path}: not a PLY file (no 'ply' magic or no end_header)")
    header = data[:end].decode("ascii", errors="replace").splitlines()
    body_start = data.index(b"\n", end) + 1
    fmt = None
    elements: list[tuple[str, int, list]] = []
    for line in header:
        t = line.split()
        if not t:
            continue
        if t[0] == "format":
            fmt = t[1]
        elif t[0] == "element":
            elements.append((t[1], int(t[2]), []))
        elif t[0] == "property" and elements:
            elements[-1][2].append(t[1:])
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise MeshError(f"{path}: unsupported PLY format {fmt!r}")
    try:
        verts, faces = _ply_body(path, data, body_start, fmt, elements)
    except MeshError:
        raise
    except (ValueError, IndexError, KeyError) as exc:  # fewer values than the header promises, or odd ones
        raise MeshError(f"{path}: PLY data do not match its header (truncated or corrupt file: {exc})") from None
    if verts is None:
        raise MeshError(f"{path}: PLY has no vertex element")
    if faces is None or len(faces) == 0:
        raise MeshError(f"{path}: {len(verts)} vertices but no faces (a point cloud, not a surface mesh)")
    return Mesh(verts, faces, path.stem)


def _ply_body(path: Path, data: bytes, body_start: int, fmt: str, elements: list) -> tuple:
    """(vertices or None, triangles or None) from a PLY's data after its header."""
    verts = faces = None
    if fmt == "ascii":
        tokens = data[body_start:].split()
        pos = 0
        for name, count, props in elements:
            if name == "vertex":
                n = len(props)
                arr = np.asarray(tokens[pos:pos + count * n], dtype=np.float64).reshape(count, n)
                names = [p[-1] for p in props]
                verts = arr[:, [names.index(c) for c in "xyz"]]
                pos += count * n
            elif name == "face":
                polys = []
                for _ in range(count):
                    k = int(tokens[pos])
                    polys.append([int(x) for x in tokens[pos + 1:pos + 1 + k]])
                    pos += 1 + k + (len(props) - 1)  # skip any extra scalar face properties
                faces = triangulate(polys)
            else:
                pos += count * len(props)
    else:
        end_ch = "<" if fmt == "binary_little_endian" else ">"
        pos = body_start
        for name, count, props in elements:
            if any(p[0] == "list" for p in props):
                if name != "face" or len(props) != 1:
                    raise MeshError(f"{path}: PLY element {name!r} with list properties is not supported")
                cnt_t, idx_t = np.dtype(end_ch + _PLY_TYPES[props[0][1]]), np.dtype(end_ch + _PLY_TYPES[props[0][2]])
                polys = []
                for _ in range(count):
                    k = int(np.frombuffer(data, cnt_t, 1, pos)[0])
                    pos += cnt_t.itemsize
                    polys.append(np.frombuffer(data, idx_t, k, pos).tolist())
                    pos += k * idx_t.itemsize
                faces = triangulate(polys)
            else:
                dt = np.dtype([(p[1], end_ch + _PLY_TYPES[p[0]]) for p in props])
                arr = np.frombuffer(data, dt, count, pos)
                pos += count * dt.itemsize
                if name == "vertex":
                    verts = np.stack([arr[c].astype(np.float64) for c in "xyz"], axis=1)
    return verts, faces


def load_glb(path: str | Path) -> Mesh:
    """Read the triangle primitives of every mesh in a binary glTF, with node transforms applied."""
    path = Path(path)
    data = _read_bytes(path)
    if len(data) < 20 or data[:4] != b"glTF":
        raise MeshError(f"{path}: not a binary glTF (.glb) file")
    _, _, total = struct.unpack_from("<4sII", data, 0)
    pos, gltf, binchunk = 12, None, b""
    while pos + 8 <= min(total, len(data)):
        n, kind = struct.unpack_from("<II", data, pos)
        chunk = data[pos + 8:pos + 8 + n]
        if kind == 0x4E4F534A:
            gltf = json.loads(chunk.decode("utf-8"))
        elif kind == 0x004E4942:
            binchunk = chunk
        pos += 8 + n
    if gltf is None:
        raise MeshError(f"{path}: .glb has no JSON chunk")
    ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
    ctype = {5121: "u1", 5123: "<u2", 5125: "<u4", 5126: "<f4", 5120: "i1", 5122: "<i2"}

    def accessor(i: int) -> np.ndarray:
        a = gltf["accessors"][i]
        bv = gltf["bufferViews"][a["bufferView"]]
        if bv.get("buffer", 0) != 0:
            raise MeshError(f"{path}: external glTF buffers are not supported")
        dt, k = np.dtype(ctype[a["componentType"]]), ncomp[a["type"]]
        start = bv.get("byteOffset", 0) + a.get("byteOffset", 0)
        stride = bv.get("byteStride", 0) or dt.itemsize * k
        raw = np.frombuffer(binchunk, np.uint8, (a["count"] - 1) * stride + dt.itemsize * k, start)
        rows = np.lib.stride_tricks.as_strided(raw, (a["count"], dt.itemsize * k), (stride, 1))
        return np.ascontiguousarray(rows).view(dt).reshape(a["count"], k)

    def local(node: dict) -> np.ndarray:
        if "matrix" in node:
            return np.asarray(node["matrix"], dtype=np.float64).reshape(4, 4).T  # glTF is column-major
        m = np.eye(4)
        w, x, y, z = [node.get("rotation", [0, 0, 0, 1])[i] for i in (3, 0, 1, 2)]
        m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
        m[:3, :3] *= np.asarray(node.get("scale", [1, 1, 1]))
        m[:3, 3] = node.get("translation", [0, 0, 0])
        return m

    nodes = gltf.get("nodes", [])
    scene = gltf.get("scenes", [{}])[gltf.get("scene", 0)] if gltf.get("scenes") else {"nodes": range(len(nodes))}
    all_v, all_f, base = [], [], 0
    stack = [(i, np.eye(4)) for i in scene.get("nodes", [])]
    while stack:
        i, parent = stack.pop()
        node = nodes[i]
        m = parent @ local(node)
        stack.extend((c, m) for c in node.get("children", []))
        if "mesh" not in node:
            continue
        for prim in gltf["meshes"][node["mesh"]]["primitives"]:
            if prim.get("mode", 4) != 4 or "POSITION" not in prim.get("attributes", {}):
                continue
            v = accessor(prim["attributes"]["POSITION"]).astype(np.float64)
            f = (accessor(prim["indices"]).reshape(-1) if "indices" in prim else np.arange(len(v))).astype(np.int64)
            all_v.append(v @ m[:3, :3].T + m[:3, 3])
            all_f.append(f.reshape(-1, 3) + base)
            base += len(v)
    if not all_v:
        raise MeshError(f"{path}: the .glb holds no triangle mesh")
    return Mesh(np.concatenate(all_v), np.concatenate(all_f), path.stem)


def load_mesh(path: str | Path, group: str | None = None) -> Mesh:
    """Read OBJ, PLY or GLB, chosen from the file's content (not only its extension)."""
    path = Path(path)
    head = _read_bytes(path, 4096)
    if head.startswith(b"glTF"):
        return load_glb(path)
    if head.startswith(b"ply"):
        return load_ply(path)
    text = head.decode("latin-1")
    if any(line.startswith(("v ", "f ", "o ", "g ", "vn ", "vt ", "mtllib")) for line in text.splitlines()):
        return load_obj(path, group)
    raise MeshError(f"{path}: not a mesh file (expected OBJ, PLY or GLB content)")
