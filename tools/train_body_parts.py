"""Train the body-part forest the depth tracker ships (kinect_retarget/assets/body_parts_forest.npz).

    .venv/bin/python tools/train_body_parts.py [--images 400] [--pixels 500] [--trees 3] [--depth 20]
                                               [--seed 0] [--out PATH] [--cache /tmp/body_parts_data.npz]

Development only: needs scikit-learn (requirements-train.txt; PYTHONPATH may point at a separate install),
which the package never imports. Training data come only from redistributable assets in ../shared/data:
the MakeHuman base mesh (CC0) posed by the CMU BVH motions (every 8th frame), with each arm (and sometimes a
leg) swung to random directions so the arm poses of real actions are covered; bodies scaled 1.45-2.0 m and
thickened or thinned per bone (0.85-1.3); performers 1.5-4 m away, up to side-on, sensor 0.6-1.6 m high and
pitched -5..20 degrees; the sensor's projector shadow, edge dropouts, disparity noise and quantisation
(render.kinect_artifacts). Labels: body_parts.PARTS from the mesh's skin weights (sim/body_part_labels.py). Each
image's person cells on the tracker's 4-pixel grid are sampled, and a pool of depth-difference features is
evaluated on them; scikit-learn's RandomForestClassifier picks from the pool at every split; the trees are
flattened into numpy arrays (part_forest.PartForest). Seeded: the same arguments give the same trees (only
the times recorded in the recipe differ).
"""
from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
DATA = REPO.parent / "shared" / "data"

from kinect_retarget.depth.body_parts import BACKGROUND, PARTS  # noqa: E402
from kinect_retarget.depth.depth_camera import DepthCamera, raw_to_mm  # noqa: E402
from kinect_retarget.depth.part_forest import BACKGROUND_DEPTH, MODEL_PATH, PartForest, probe_features  # noqa: E402
from kinect_retarget.depth.segmentation import DepthGrid  # noqa: E402
from kinect_retarget.sim.body_part_labels import render_parts, surface_labels, vertex_parts  # noqa: E402
from kinect_retarget.sim.bvh_motion import read_bvh_positions  # noqa: E402
from kinect_retarget.sim.depth_render import _tilt, kinect_artifacts, quad_sampler, surface_points  # noqa: E402
from kinect_retarget.sim.makehuman_body import DRIVER_NAMES, load_body  # noqa: E402
from kinect_retarget.sim.mocap_pose import _rest_points, cmu_points, pose_from_points  # noqa: E402

CLIPS = ("01_01", "131_01", "131_02", "131_03")
STEP = 4            # the tracker's grid stride
POOL = 400          # candidate features
MAX_OFFSET = 0.6    # metres


def _unit(v):
    return v / max(np.linalg.norm(v), 1e-9)


def load_poses() -> list[dict]:
    """One dict of canonical mocap points (each (3,)) per pose: every 8th frame of every clip."""
    poses = []
    for clip in CLIPS:
        names, _, pos, _ = read_bvh_positions(str(DATA / "mocap_bvh" / f"{clip}.bvh"))
        pts = cmu_points(names, pos[::8])
        poses += [{k: v[i] for k, v in pts.items()} for i in range(len(pos[::8]))]
    return poses


def random_direction(rng, around=None, max_deg=180.0):
    """A random unit vector, uniform on the sphere or within max_deg of `around`."""
    while True:
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        if around is None or d @ around >= np.cos(np.radians(max_deg)):
            return d


def swing_limbs(p: dict, rng) -> dict:
    """Each arm (p 0.7) and leg (p 0.2) swung to random directions with its own bone lengths."""
    p = dict(p)
    up = _unit(p["neck"] - p["hips"])
    for s in ("L", "R"):
        if rng.random() < 0.7:
            a, b, c, d = (p[f"{k}.{s}"] for k in ("shoulder", "elbow", "wrist", "hand"))
            upper = random_direction(rng)
            fore = random_direction(rng, upper, 150.0)
            hand = _unit(fore + 0.3 * rng.normal(size=3))
            p[f"elbow.{s}"] = a + upper * np.linalg.norm(b - a)
            p[f"wrist.{s}"] = p[f"elbow.{s}"] + fore * np.linalg.norm(c - b)
            p[f"hand.{s}"] = p[f"wrist.{s}"] + hand * np.linalg.norm(d - c)
        if rng.random() < 0.2:
            a, b, c, t = (p[f"{k}.{s}"] for k in ("hip", "knee", "ankle", "toe"))
            thigh = random_direction(rng, -up, 100.0)
            shin = random_direction(rng, -up, 60.0)
            p[f"knee.{s}"] = a + thigh * np.linalg.norm(b - a)
            p[f"ankle.{s}"] = p[f"knee.{s}"] + shin * np.linalg.norm(c - b)
            p[f"toe.{s}"] = p[f"ankle.{s}"] + (t - c)
    return p


def varied_body(body, rng):
    """The body thickened or thinned about each bone (torso about its vertical axis), blended by skin weight."""
    rest = _rest_points(body)
    v = body.rest_vertices
    disp = np.zeros((len(DRIVER_NAMES),) + v.shape)
    bones = {"upperarm": ("shoulder", "elbow"), "lowerarm": ("elbow", "wrist"), "hand": ("wrist", "hand"),
             "upperleg": ("hip", "knee"), "lowerleg": ("knee", "ankle"), "foot": ("ankle", "toe")}
    torso = rng.uniform(0.85, 1.3, size=2)
    for i, name in enumerate(DRIVER_NAMES):
        if name in ("pelvis", "abdomen", "chest"):
            off = v - rest["hips"]
            disp[i, :, 0], disp[i, :, 2] = (torso[0] - 1) * off[:, 0], (torso[1] - 1) * off[:, 2]
        elif name != "head":
            limb, s = name.split(".")
            a, b = rest[f"{bones[limb][0]}.{s}"], rest[f"{bones[limb][1]}.{s}"]
            t = np.clip((v - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
            axis_pt = a + t[:, None] * (b - a)
            disp[i] = (rng.uniform(0.85, 1.3) - 1) * (v - axis_pt)
    return replace(body, rest_vertices=v + np.einsum("vd,dvc->vc", body.weights, disp))


def render_one(body, vlabels_pts, groups, pose, rng, cam):
    """One random frame: (depth mm (480, 640), labels (480, 640))."""
    posed = pose_from_points(body, {k: v[None] for k, v in pose.items()})
    verts = posed.vertices(body, slice(0, 1))[0]
    j = posed.joints[0]
    verts = (verts - j[0]) * rng.uniform(1.45, 2.0) / 1.67   # MakeHuman's base body is about 1.67 m tall
    lat_dir = pose["hip.L"] - pose["hip.R"]
    heading = np.arctan2(np.cross(lat_dir, [0, 1, 0])[0], np.cross(lat_dir, [0, 1, 0])[2])
    turn = np.pi - heading + np.radians(np.clip(rng.normal(0, 35), -95, 95))
    c, s = np.cos(turn), np.sin(turn)
    verts = verts @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]).T
    sensor_h, tilt = rng.uniform(0.6, 1.6), rng.uniform(-5, 20)
    verts[:, 1] -= sensor_h + verts[:, 1].min()
    x = rng.uniform(-0.3, 0.3)
    whole = rng.random() < 0.9   # most frames show the whole body, like the real sequences
    for dist in np.arange(rng.uniform(1.5, 4.0), 6.0, 0.1):   # back off until the body is in view
        cam_v = (verts + [x * dist, 0.0, dist]) @ _tilt(tilt)   # level frame -> camera frame
        uv = cam_v[:, :2] / cam_v[:, 2:] * cam.f
        if not whole or (np.all(np.abs(uv[:, 0]) < cam.cx - 4) and np.all(np.abs(uv[:, 1]) < cam.cy - 4)):
            break
    pts = surface_points(cam_v, body.quads, groups)
    depth, labels = render_parts(pts, vlabels_pts, cam)
    raw = kinect_artifacts(depth, cam, rng, noise_raw=rng.uniform(0.3, 1.0))
    mm = raw_to_mm(raw)
    labels[mm == 0] = BACKGROUND
    return mm, labels


def make_data(args, rng):
    cam = DepthCamera()
    base = load_body(str(DATA / "meshes" / "makehuman"))
    vlab = vertex_parts(base)
    poses = load_poses()
    offsets = rng.uniform(-MAX_OFFSET, MAX_OFFSET, size=(POOL, 2, 2))
    offsets[: POOL // 3, 1] = 0.0   # a third compare with the cell itself (Shotton's unary features)
    cells_per_m = cam.f / STEP
    xs, ys = [], []
    t0 = time.perf_counter()
    body = base
    for i in range(args.images):
        if i % 10 == 0:   # a new body shape every 10 images
            body = varied_body(base, rng)
            groups = quad_sampler(body.rest_vertices, body.quads, 1.2, cam)
            vlabels_pts = surface_labels(vlab, body.quads, groups)
        mm, labels = render_one(body, vlabels_pts, groups, swing_limbs(poses[rng.integers(len(poses))], rng),
                                rng, cam)
        grid = DepthGrid.from_mm(mm, cam, STEP)
        glab = labels[STEP // 2::STEP, STEP // 2::STEP]
        person = grid.valid & (glab != BACKGROUND)
        zb = np.where(person, grid.z, BACKGROUND_DEPTH)
        r, c = np.nonzero(person)
        if len(r) < 50:
            continue
        pick = rng.choice(len(r), size=min(args.pixels, len(r)), replace=False)
        xs.append(probe_features(zb, r[pick], c[pick], offsets[None], cells_per_m).astype(np.float32))
        ys.append(glab[r[pick], c[pick]])
        if (i + 1) % 20 == 0:
            print(f"  {i + 1}/{args.images} images, {time.perf_counter() - t0:.0f} s", flush=True)
    return np.concatenate(xs), np.concatenate(ys), offsets


def flatten(forest, offsets) -> PartForest:
    """scikit-learn trees -> one set of flat node arrays (leaves loop onto themselves)."""
    feats, thr, left, right, probs, roots, depth, n0 = [], [], [], [], [], [], 0, 0
    classes = forest.classes_.astype(np.int64)
    for est in forest.estimators_:
        t = est.tree_
        leaf = t.children_left < 0
        idx = np.arange(t.node_count)
        feats.append(np.where(leaf, 0, t.feature))
        thr.append(np.where(leaf, 0.0, t.threshold))
        left.append(np.where(leaf, idx, t.children_left) + n0)
        right.append(np.where(leaf, idx, t.children_right) + n0)
        v = t.value[:, 0, :]
        v = v / np.maximum(v.sum(axis=1, keepdims=True), 1e-12)
        p = np.zeros((t.node_count, len(PARTS)))
        p[:, classes] = v
        probs.append(np.where(leaf[:, None], np.rint(p * 255), 0).astype(np.uint8))
        roots.append(n0)
        depth = max(depth, est.get_depth())
        n0 += t.node_count
    return PartForest(offsets, np.concatenate(feats), np.concatenate(thr), np.concatenate(left),
                      np.concatenate(right), np.concatenate(probs), np.array(roots), depth)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--images", type=int, default=400)
    ap.add_argument("--pixels", type=int, default=500, help="person cells sampled per image")
    ap.add_argument("--trees", type=int, default=3)
    ap.add_argument("--depth", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=MODEL_PATH)
    ap.add_argument("--cache", help="keep the sampled features here (.npz) and reuse them when present")
    args = ap.parse_args()
    from sklearn.ensemble import RandomForestClassifier
    rng = np.random.default_rng(args.seed)
    t0 = time.perf_counter()
    if args.cache and Path(args.cache).exists():
        with np.load(args.cache) as d:
            x, y, offsets = d["x"], d["y"], d["offsets"]
    else:
        x, y, offsets = make_data(args, rng)
        if args.cache:
            np.savez(args.cache, x=x, y=y, offsets=offsets)
    t1 = time.perf_counter()
    print(f"{len(y)} samples from {args.images} images ({t1 - t0:.0f} s); training {args.trees} trees of depth "
          f"{args.depth} on {x.shape[1]} candidate features", flush=True)
    rf = RandomForestClassifier(n_estimators=args.trees, max_depth=args.depth, max_features=40,
                                min_samples_leaf=5, random_state=args.seed, n_jobs=1).fit(x, y)
    forest = flatten(rf, offsets)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    forest.save(args.out, images=args.images, pixels=args.pixels, trees=args.trees, depth=args.depth,
                seed=args.seed, samples=int(len(y)), data_s=round(t1 - t0), train_s=round(time.perf_counter() - t1))
    print(f"wrote {args.out}: {len(forest.feature)} nodes, depth {forest.depth} "
          f"({Path(args.out).stat().st_size / 1e6:.1f} MB); training took {time.perf_counter() - t1:.0f} s")


if __name__ == "__main__":
    main()
