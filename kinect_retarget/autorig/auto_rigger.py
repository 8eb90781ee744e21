"""Auto-rig a character mesh end to end (pure numpy): body component -> feature points -> segments and
levels (paper 003) -> the 20 Kinect v1 joints -> bone-projection skin weights for every vertex."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..core.skeletons import KINECT_V1, Skeleton
from .features import LABELS, FeaturePoints, find_feature_points
from .graph import connected_components, mesh_graph
from .joints import kinect_joints
from .joints_paper import paper_joints
from .levels import NORMALIZATIONS, SkeletonPoints, paper_skeleton
from .mirror import asymmetry, fit_mirror_plane, symmetrize_joints
from .mesh import Mesh, MeshError, nearest_vertex
from .weights import bone_projection_weights

LEVELS = 4  # the paper's K
# Joint rules: "fractions" (default: rings at fixed fractions of the body's geodesic length, joints.py; it
# measures better, benchmarks/bench_autorig.py) or "paper" (the paper's skeleton points, joints_paper.py:
# there K and the eq. 6 normalization move the joints).
JOINT_RULES = ("fractions", "paper")


@dataclass
class AutoRig:
    """Everything in the input mesh's coordinates and units.

    joints (20, 3) in KINECT_V1 order; bone j ends at joint j (root bone: a stub at the hip centre).
    weight_index / weight (V, 4) for every vertex of the input mesh (bone indices, weights summing to 1).
    """

    skeleton: Skeleton
    joints: np.ndarray
    weight_index: np.ndarray
    weight: np.ndarray
    body: np.ndarray            # (Vb,) input vertex indices of the body component
    segment: np.ndarray         # (Vb,) feature-point segment (features.LABELS) of each body vertex
    features: FeaturePoints     # vertex indices are body-local
    paper: SkeletonPoints       # the paper's skeleton points (body-local groups)
    height: float
    report: dict = field(default_factory=dict)
    body_points: np.ndarray | None = None  # (Vb, 3) positions of the body vertices

    @property
    def bone_names(self) -> tuple[str, ...]:
        return self.skeleton.joints

    def summary(self) -> str:
        r = self.report
        return (f"auto-rig: {len(self.joints)} joints from a body of {r['body_vertices']} vertices "
                f"(height {self.height:.3g} units, {r['components']} mesh pieces, {r['bound_vertices']} vertices "
                f"bound from other pieces), {r['joint_rule']} joints, {len(self.paper.points)} skeleton points over "
                f"{r['levels']} levels ({r['normalization']} normalization), "
                f"{r['seconds']:.2f} s")


def _check_single_body(mesh: Mesh, comp: np.ndarray) -> None:
    sizes = np.bincount(comp)
    if len(sizes) < 2:
        return
    ext = [np.ptp(mesh.vertices[comp == c], axis=0).max() for c in (0, 1)]
    if sizes[1] > 0.5 * sizes[0] and ext[1] > 0.5 * ext[0]:
        raise MeshError(f"{mesh.name}: {len(sizes)} disconnected pieces, the two largest of similar size "
                        f"({sizes[0]} and {sizes[1]} vertices): several bodies? Rig one character at a time")


def autorig(mesh: Mesh, levels: int = LEVELS, joints: str = "fractions",
            normalization: str = "segment") -> AutoRig:
    """Rig a humanoid mesh. Raises MeshError with what was found when no human skeleton can be built.
    `joints` picks the joint rule (JOINT_RULES), `normalization` eq. 6's reading (levels.NORMALIZATIONS)."""
    if joints not in JOINT_RULES:
        raise ValueError(f"joints {joints!r}: expected one of {JOINT_RULES}")
    if normalization not in NORMALIZATIONS:
        raise ValueError(f"normalization {normalization!r}: expected one of {NORMALIZATIONS}")
    if not 1 <= levels <= 50:
        raise ValueError(f"levels {levels}: expected 1 to 50 (the paper uses 2-7)")
    rule = joints
    t0 = time.perf_counter()
    timings = {}
    graph = mesh_graph(mesh.vertices, mesh.faces)
    comp = connected_components(graph.n, graph.edges)
    _check_single_body(mesh, comp)
    face_in = np.all(comp[mesh.faces] == 0, axis=1)
    body_mesh, used = mesh.submesh(np.flatnonzero(face_in))
    if len(used) < 50:
        raise MeshError(f"{mesh.name}: the largest piece has only {len(used)} vertices: too small to rig")
    body = used
    v = body_mesh.vertices
    bgraph = mesh_graph(v, body_mesh.faces)
    timings["graph"] = time.perf_counter() - t0
    try:
        fp = find_feature_points(v, bgraph)
    except MeshError as e:
        raise MeshError(f"{mesh.name}: {e}") from None
    timings["features"] = time.perf_counter() - t0
    segment = np.argmin(fp.distances, axis=0)
    up_coord = v @ fp.up
    height = float(up_coord.max() - up_coord.min())
    paper = paper_skeleton(v, bgraph, fp.distances, levels, normalization)
    joints = (paper_joints(v, fp, paper, height) if rule == "paper"
              else kinect_joints(v, body_mesh.faces, fp, segment, height))
    if not np.all(np.isfinite(joints)):
        raise MeshError(f"{mesh.name}: joint placement failed (non-finite positions)")
    # A body that is its own mirror image gets a mirror-symmetric rig (mirror.py: geodesics measured on a
    # triangulation that is not itself mirrored place the two sides' joints differently).
    plane = fit_mirror_plane(v, body_mesh.faces, fp.left, height)
    mirror = {"symmetric": plane.symmetric, "surface_mismatch_pct": round(plane.mismatch * 100, 4),
              "joint_asymmetry_found_pct": round(asymmetry(joints, plane, height), 4)}
    if plane.symmetric:
        joints = symmetrize_joints(joints, plane)
    timings["joints"] = time.perf_counter() - t0
    # Every vertex gets weights: other pieces (eyes, teeth, clothes) take the segment of the nearest body
    # vertex, so they follow the body part they sit on.
    seg_all = np.empty(len(mesh.vertices), dtype=np.int64)
    seg_all[body] = segment
    others = np.setdiff1d(np.arange(len(mesh.vertices)), body)
    if len(others):
        seg_all[others] = _segment_of_nearest(mesh.vertices[others], v, segment)
    index, weight = bone_projection_weights(mesh.vertices, seg_all, joints, height, graph)
    timings["weights"] = time.perf_counter() - t0
    report = {"body_vertices": int(len(body)), "components": int(comp.max()) + 1,
              "bound_vertices": int(len(others)), "feature_points": {l: v[i].tolist() for l, i in zip(LABELS, fp.vertices)},
              "up": fp.up.tolist(), "front": fp.front.tolist(), "seconds": time.perf_counter() - t0,
              "timings": timings, "levels": levels, "joint_rule": rule,
              "normalization": normalization, "mirror": mirror,
              "points_per_level": paper.count_per_level(levels).tolist()}
    return AutoRig(KINECT_V1, joints, index, weight, body, segment, fp, paper, height, report, v)


def _segment_of_nearest(points: np.ndarray, body: np.ndarray, segment: np.ndarray) -> np.ndarray:
    sample = np.arange(0, len(body), 4)  # a quarter of the body is plenty to tell which part a piece sits on
    return segment[sample[nearest_vertex(points, body[sample])]]


def bind_mesh(rig: AutoRig, mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Skin weights (V, 4) for another mesh in the same space as the rigged body (clothes, hair, eyes
    kept as separate objects): each vertex follows the body part nearest to it."""
    segment = _segment_of_nearest(mesh.vertices, rig.body_points, rig.segment)
    graph = mesh_graph(mesh.vertices, mesh.faces) if len(mesh.faces) else None
    return bone_projection_weights(mesh.vertices, segment, rig.joints, rig.height, graph)
