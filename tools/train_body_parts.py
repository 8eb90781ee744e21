"""Train the body-part forest the depth tracker ships (kinect_retarget/assets/body_parts_forest.npz).

    .venv/bin/python tools/train_body_parts.py [--images 6000] [--pixels 400] [--trees 3] [--depth 20]
                                               [--seed 0] [--jobs 2] [--balance 1.0] [--no-skirts] [--out PATH]
                                               [--cache DIR] [--reach-images N] [--grip-images N]
    .venv/bin/python tools/train_body_parts.py --evaluate FOREST.npz [FOREST.npz ...] [--images 300] [--seed 99]
                                               [--plain]

Development only: needs scikit-learn (requirements-train.txt; PYTHONPATH may point at a separate install),
which the package never imports. Training data come only from redistributable assets: the MakeHuman base mesh
(CC0) as a population (sim/body_population.py): per-segment proportions (upper arm, forearm, hand, thigh,
shin, torso length, shoulder and hip width), per-bone girth 0.85-1.3, loose clothing and hair as offset
surfaces and sometimes a skirt/coat hem, height 1.45-2.0 m, a new performer every 10 images. Poses: every
4th frame of the CMU BVH motions in ../shared/data/mocap_bvh and every frame of the Kinect v2 (LabanotationSuite
CSV, Kinectron JSON) and UI-PRMD Kinect recordings, through the project's own take readers and mocap poser
(sim/mocap_pose.pose_from_points), mirrored half the time; arms (and sometimes legs) swung to random
directions (CMU p 0.7, Kinect p 0.35) so the arm poses of real actions are covered. Performers 1.5-4 m away,
turned up to side-on, sensor 0.6-1.6 m high and pitched -5..20 degrees; the sensor's projector shadow,
edge dropouts, disparity noise and quantisation (sim/depth_render.kinect_artifacts). Labels:
body_parts.PARTS from the mesh's skin weights (sim/body_part_labels.py). Each image's person cells on the
tracker's 4-pixel grid are sampled, and a pool of depth-difference features is evaluated on them;
scikit-learn's RandomForestClassifier picks from the pool at every split; the trees are flattened into numpy
arrays (part_forest.PartForest). Small parts (hands, wrists, ankles: 0.4 % of the samples against 10 % for the
chest) would hardly shape the splits, so each sample is weighted by its part's frequency to the power
-`--balance` while the trees grow (1.0: every part weighs the same); the leaves' part probabilities are then
counted again without weights, so they stay the plain frequencies the proposals' thresholds expect.

`--reach-images N` adds N further images (numbered from REACH_FIRST, so the others' draws and cache are
unchanged) whose arms reach to places on and around the body instead of swinging at random
(sim/reach_poses.py: crossed arms, hands at a shoulder, the face, the belly, the hips, in front and overhead).
`--grip-images N` adds N images (from GRIP_FIRST) whose two hands hold one thing together
(sim/reach_poses.gripping: a bat at one shoulder, the far arm crossing the chest; a ball before the belly or
chest, raised, or overhead). With `--no-skirts` the skirted performers' images are not rendered at all (their
draws are replayed to know them): the other images' samples are the same, a fifth of the time saved.

Seeded: image i and performer g draw from their own generators (seed, i) and (seed, g), so the same
arguments give the same data (and trees) whatever --jobs is; --cache DIR keeps 50-image chunks and resumes.
--evaluate renders held-out images (use a seed not trained on) and prints each forest's per-cell accuracy;
--plain renders the older population (MakeHuman girth and scale only, CMU poses) for comparison.
"""
from __future__ import annotations

import argparse
import multiprocessing
import sys
import time
from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
DATA = REPO.parent / "shared" / "data"

from kinect_retarget.assets import MAKEHUMAN_DIR  # noqa: E402
from kinect_retarget.depth.body_parts import BACKGROUND, PARTS  # noqa: E402
from kinect_retarget.depth.depth_camera import DepthCamera, raw_to_mm  # noqa: E402
from kinect_retarget.depth.part_forest import BACKGROUND_DEPTH, MODEL_PATH, PartForest, load_forest, probe_features  # noqa: E402
from kinect_retarget.depth.segmentation import DepthGrid  # noqa: E402
from kinect_retarget.sim.body_part_labels import render_parts, surface_labels, vertex_parts  # noqa: E402
from kinect_retarget.sim.body_population import (GARMENTS, SKIRT_CHANCE, clothed_body, proportioned_body,  # noqa: E402
                                                  random_proportions, take_points)
from kinect_retarget.sim.bvh_motion import read_bvh_positions  # noqa: E402
from kinect_retarget.sim.depth_render import _tilt, kinect_artifacts, quad_sampler, surface_points  # noqa: E402
from kinect_retarget.sim.makehuman_body import DRIVER_NAMES, load_body  # noqa: E402
from kinect_retarget.sim.mocap_pose import _rest_points, cmu_points, pose_from_points  # noqa: E402
from kinect_retarget.sim.reach_poses import gripping, reaching  # noqa: E402
from kinect_retarget.takes import load_take  # noqa: E402

CLIPS = ("01_01", "131_01", "131_02", "131_03")
TAKES = tuple(f"kinect_v2/{n}" for n in ("Ges01_wavehand.csv", "Ges02_balancinghands.csv", "Ges03_drawlines.csv",
                                         "Ges04_comehere.csv", "Ges05_demopoint.csv", "Ges06_chickenwing.csv",
                                         "joints.csv", "recorded_skeleton.json")) + tuple(
    f"kinect_v2_vicon_uiprmd/Kinect/m{m:02d}_s01_e01_positions.txt" for m in (1, 5, 7))
STEP = 4            # the tracker's grid stride
POOL = 400          # candidate features
MAX_OFFSET = 0.6    # metres
PER_BODY = 10       # images per performer
CHUNK = 50          # images per cache file
TAKE_SHARE = 0.5    # share of images posed from the Kinect recordings (the rest from CMU)
REACH_FIRST = 1_000_000   # images numbered from here have their arms reaching on and around the body
GRIP_FIRST = 2_000_000    # ... and from here both hands hold one thing (a bat, a ball)


def _unit(v):
    return v / max(np.linalg.norm(v), 1e-9)


def load_poses(plain: bool = False) -> tuple[list[dict], list[dict]]:
    """(CMU poses, Kinect recording poses): dicts of canonical mocap points (each (3,))."""
    cmu = []
    for clip in CLIPS:
        names, _, pos, _ = read_bvh_positions(str(DATA / "mocap_bvh" / f"{clip}.bvh"))
        pts = cmu_points(names, pos[:: 8 if plain else 4])
        cmu += [{k: v[i] for k, v in pts.items()} for i in range(len(pts["hips"]))]
    takes = [] if plain else [p for t in TAKES for p in take_points(load_take(DATA / t))]
    return cmu, takes


def mirrored(p: dict) -> dict:
    """The pose mirrored left-right (X negated, sides swapped)."""
    swap = {"L": "R", "R": "L"}
    return {(k[:-1] + swap[k[-1]] if k[-2:] in (".L", ".R") else k): v * [-1.0, 1.0, 1.0] for k, v in p.items()}


def random_direction(rng, around=None, max_deg=180.0):
    """A random unit vector, uniform on the sphere or within max_deg of `around`."""
    while True:
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        if around is None or d @ around >= np.cos(np.radians(max_deg)):
            return d


def swing_limbs(p: dict, rng, arm_chance: float = 0.7) -> dict:
    """Each arm (p arm_chance) and leg (p 0.2) swung to random directions with its own bone lengths."""
    p = dict(p)
    up = _unit(p["neck"] - p["hips"])
    for s in ("L", "R"):
        if rng.random() < arm_chance:
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


def performer(base, vlab, rng, cam, plain: bool = False):
    """One random performer: (body, surface sample groups, their labels, metres per body unit)."""
    body, labels = base, vlab
    if not plain:
        body = proportioned_body(body, random_proportions(rng), str(MAKEHUMAN_DIR))
    body = varied_body(body, rng)
    if not plain:
        body, labels = clothed_body(body, labels, rng)
    groups = quad_sampler(body.rest_vertices, body.quads, 1.2, cam)
    height = rng.uniform(1.45, 2.0)   # MakeHuman's base body is about 1.67 m tall
    rest_height = 1.67 if plain else np.ptp(base.rest_vertices[:, 1]) * (np.ptp(body.rest_vertices[:, 1]) /
                                                                          np.ptp(base.rest_vertices[:, 1]))
    return body, groups, surface_labels(labels, body.quads, groups), height / rest_height


def render_one(body, vlabels_pts, groups, pose, rng, cam, scale=None):
    """One random frame: (depth mm (480, 640), labels (480, 640))."""
    posed = pose_from_points(body, {k: v[None] for k, v in pose.items()})
    verts = posed.vertices(body, slice(0, 1))[0]
    j = posed.joints[0]
    verts = (verts - j[0]) * (rng.uniform(1.45, 2.0) / 1.67 if scale is None else scale)
    lat_dir = pose["hip.L"] - pose["hip.R"]
    heading = np.arctan2(np.cross(lat_dir, [0, 1, 0])[0], np.cross(lat_dir, [0, 1, 0])[2])
    turn = np.pi - heading + np.radians(np.clip(rng.normal(0, 35), -95, 95))
    c, s = np.cos(turn), np.sin(turn)
    verts = verts @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]).T
    sensor_h, tilt = rng.uniform(0.6, 1.6), rng.uniform(-5, 20)
    verts[:, 1] -= sensor_h + verts[:, 1].min()
    x = rng.uniform(-0.3, 0.3)
    whole = rng.random() < 0.9   # most frames show the whole body, like the real sequences
    for dist in np.arange(rng.uniform(1.5, 4.0), 4.4, 0.1):   # back off until the body is in view (or in range)
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


_W: dict = {}   # per-process state, set before the worker pool forks


def _setup(seed: int, plain: bool) -> None:
    cam = DepthCamera()
    base = load_body(str(MAKEHUMAN_DIR))
    cmu, takes = load_poses(plain)
    _W.update(cam=cam, base=base, vlab=vertex_parts(base), cmu=cmu, takes=takes, seed=seed, plain=plain)


def person_grids(first: int, count: int):
    """Images first..first+count-1: [(person depth grid zb, grid labels)], each from its own seeded draws."""
    cam, seed, out = _W["cam"], _W["seed"], []
    body = None
    for i in range(first, first + count):
        if _W.get("skip_skirts") and skirted(seed, i // PER_BODY):
            out.append(None)   # left out anyway (--no-skirts): not rendered
            continue
        if body is None or i % PER_BODY == 0:
            body = performer(_W["base"], _W["vlab"], np.random.default_rng([seed, 2, i // PER_BODY]), cam,
                             _W["plain"])
        rng = np.random.default_rng([seed, 1, i])
        use_takes = bool(_W["takes"]) and rng.random() < TAKE_SHARE
        poses = _W["takes"] if use_takes else _W["cmu"]
        pose = poses[rng.integers(len(poses))]
        if not _W["plain"] and rng.random() < 0.5:
            pose = mirrored(pose)
        b, groups, vl, scale = body
        if i >= GRIP_FIRST:
            pose = gripping(pose, rng)
        else:
            pose = reaching(pose, rng) if i >= REACH_FIRST else swing_limbs(pose, rng, 0.35 if use_takes else 0.7)
        mm, labels = render_one(b, vl, groups, pose, rng, cam, scale)
        grid = DepthGrid.from_mm(mm, cam, STEP)
        glab = labels[STEP // 2::STEP, STEP // 2::STEP]
        person = grid.valid & (glab != BACKGROUND)
        out.append((np.where(person, grid.z, BACKGROUND_DEPTH).astype(np.float32), np.where(person, glab, BACKGROUND)))
    return out


def _chunk_samples(task):
    first, count, pixels, offsets, cache = task
    path = Path(cache) / f"chunk_{first:06d}_{count}_{pixels}.npz" if cache else None
    if path is not None and path.exists():
        with np.load(path) as d:
            if "image" in d.files:
                return d["x"], d["y"], d["image"]
            if len(d["y"]) == count * pixels:   # (older chunks: every image gave `pixels` samples, in order)
                return d["x"], d["y"], first + np.arange(len(d["y"])) // pixels
        # an older chunk with a short image: which samples are whose is not recorded, so render it again
    cells_per_m, xs, ys, images = _W["cam"].f / STEP, [], [], []
    for i, grid in enumerate(person_grids(first, count)):
        if grid is None:
            continue
        zb, glab = grid
        r, c = np.nonzero(glab != BACKGROUND)
        if len(r) < 50:
            continue
        pick = np.random.default_rng([_W["seed"], 3, first + i]).choice(len(r), size=min(pixels, len(r)),
                                                                        replace=False)
        xs.append(probe_features(zb.astype(np.float64), r[pick], c[pick], offsets[None], cells_per_m)
                  .astype(np.float32))
        ys.append(glab[r[pick], c[pick]])
        images.append(first + i)
    x, y = np.concatenate(xs), np.concatenate(ys)
    image = np.repeat(np.asarray(images), [len(v) for v in ys])
    if path is not None:   # each sample's image too, so a later run can leave some images out
        np.savez(path, x=x, y=y, image=image)
    return x, y, image


def _pool(jobs: int):
    return multiprocessing.get_context("fork").Pool(jobs) if jobs > 1 else None


def make_data(args):
    offsets = np.random.default_rng([args.seed, 0]).uniform(-MAX_OFFSET, MAX_OFFSET, size=(POOL, 2, 2))
    offsets[: POOL // 3, 1] = 0.0   # a third compare with the cell itself (Shotton's unary features)
    if args.cache:
        Path(args.cache).mkdir(parents=True, exist_ok=True)
    tasks = [(f, min(CHUNK, args.images - f), args.pixels, offsets, args.cache) for f in range(0, args.images, CHUNK)]
    tasks += [(f, min(CHUNK, REACH_FIRST + args.reach_images - f), args.pixels, offsets, args.cache)
              for f in range(REACH_FIRST, REACH_FIRST + args.reach_images, CHUNK)]
    tasks += [(f, min(CHUNK, GRIP_FIRST + args.grip_images - f), args.pixels, offsets, args.cache)
              for f in range(GRIP_FIRST, GRIP_FIRST + args.grip_images, CHUNK)]
    _setup(args.seed, False)
    _W["skip_skirts"] = args.no_skirts
    if args.no_skirts:
        check_skirt_replay(args.seed, args.images // PER_BODY + 1)
    pool = _pool(args.jobs)
    xs, ys, left_out, t0 = [], [], 0, time.perf_counter()
    for k, (x, y, image) in enumerate(pool.imap(_chunk_samples, tasks) if pool else map(_chunk_samples, tasks)):
        if args.no_skirts:   # left out chunk by chunk (memory: the samples of 24,000 images are 11 GB)
            groups, which = np.unique(image // PER_BODY, return_inverse=True)
            keep = ~np.array([skirted(args.seed, int(g)) for g in groups], bool)[which]
            left_out += int(np.sum(~keep))
            x, y = x[keep], y[keep]
        xs.append(x)
        ys.append(y)
        if (k + 1) % 20 == 0 or k + 1 == len(tasks):
            total = args.images + args.reach_images + args.grip_images
            print(f"  {min((k + 1) * CHUNK, total)}/{total} images, {time.perf_counter() - t0:.0f} s", flush=True)
    if pool:
        pool.close()
    if left_out:   # (chunks cached before skirted images were skipped while rendering still hold them)
        print(f"  leaving out the {left_out} samples of skirted performers' images", flush=True)
    x = np.empty((sum(len(v) for v in xs), xs[0].shape[1]), np.float32)
    at = 0
    for i, part in enumerate(xs):   # filled chunk by chunk, each freed once copied
        x[at:at + len(part)] = part
        at += len(part)
        xs[i] = None
    return x, np.concatenate(ys), offsets


@lru_cache(maxsize=None)
def skirted(seed: int, g: int) -> bool:
    """Whether performer g wears a skirt or coat hem: performer()'s seeded draws replayed up to that choice,
    without building the body (check_skirt_replay keeps the replay honest)."""
    return _skirt_drawn(np.random.default_rng([seed, 2, g]))


def check_skirt_replay(seed: int, count: int) -> None:
    """Build one skirted and one plain performer of 0..count-1 for real and check the replay agrees."""
    out = np.array([skirted(seed, g) for g in range(count)])
    base = _W["base"]
    for g in (int(np.argmax(out)), int(np.argmin(out))):
        body = performer(base, _W["vlab"], np.random.default_rng([seed, 2, g]), _W["cam"])[0]
        assert (len(body.rest_vertices) > len(base.rest_vertices)) == out[g], "skirt replay out of step"


def _skirt_drawn(rng) -> bool:
    """performer()'s draws in order: proportions, varied_body's girths, clothed_body's garments and hair."""
    random_proportions(rng)
    rng.uniform(size=2)
    for name in DRIVER_NAMES:
        if name not in ("pelvis", "abdomen", "chest", "head"):
            rng.uniform()
    for _ in GARMENTS:
        if rng.random() < 0.7:
            rng.uniform()
    if rng.random() < 0.6:
        rng.uniform()
    return bool(rng.random() < SKIRT_CHANCE)


def evaluate(args) -> None:
    """Per-cell accuracy of each forest on held-out renders (seed args.seed, population per args.plain)."""
    forests = {p: load_forest(p) for p in args.evaluate}
    _setup(args.seed, args.plain)
    pool = _pool(args.jobs)
    tasks = [(f, min(CHUNK, args.images - f)) for f in range(0, args.images, CHUNK)]
    grids = [g for part in (pool.starmap(person_grids, tasks) if pool else [person_grids(*t) for t in tasks])
             for g in part]
    cells_per_m = _W["cam"].f / STEP
    for path, forest in forests.items():
        if forest is None:
            print(f"{path}: missing or unreadable")
            continue
        hit = np.zeros(len(PARTS))
        seen = np.zeros(len(PARTS))
        t0 = time.perf_counter()
        for zb, glab in grids:
            r, c = np.nonzero(glab != BACKGROUND)
            pred = np.argmax(forest.classify(zb.astype(np.float64), r, c, cells_per_m), axis=1)
            np.add.at(seen, glab[r, c], 1)
            np.add.at(hit, glab[r, c], pred == glab[r, c])
        ms = (time.perf_counter() - t0) / len(grids) * 1e3
        print(f"{path}: per-cell accuracy {hit.sum() / seen.sum():.3f}, mean over parts "
              f"{np.mean(hit[seen > 0] / seen[seen > 0]):.3f} ({int(seen.sum())} cells, {len(grids)} images, "
              f"{'plain' if args.plain else 'population'} renders, seed {args.seed}; {ms:.1f} ms an image)")
        print("  per part: " + ", ".join(f"{PARTS[k]} {hit[k] / seen[k]:.2f}" for k in range(len(PARTS)) if seen[k]))


def recount_leaves(forest, x, y) -> None:
    """Each tree's node values become the unweighted part counts of the training samples reaching it."""
    cls = np.searchsorted(forest.classes_, y)
    for est in forest.estimators_:
        counts = np.zeros((est.tree_.node_count, len(forest.classes_)))
        np.add.at(counts, (est.apply(x), cls), 1.0)
        est.tree_.value[:, 0, :] = counts


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
    ap.add_argument("--images", type=int, default=6000)
    ap.add_argument("--pixels", type=int, default=400, help="person cells sampled per image")
    ap.add_argument("--reach-images", type=int, default=0,
                    help="further images whose arms reach on and around the body (sim/reach_poses.py)")
    ap.add_argument("--grip-images", type=int, default=0,
                    help="further images whose hands hold one thing together (sim/reach_poses.gripping)")
    ap.add_argument("--trees", type=int, default=3)
    ap.add_argument("--depth", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--tree-seed", type=int,
                    help="the trees' own randomness (default --seed): more trees on the same images")
    ap.add_argument("--jobs", type=int, default=2, help="rendering processes (the data do not depend on it)")
    ap.add_argument("--balance", type=float, default=1.0,
                    help="weight samples by part frequency ** -BALANCE while growing the trees (0: unweighted)")
    ap.add_argument("--no-skirts", action="store_true",
                    help="leave out the images of performers wearing a skirt or coat hem (same seeds otherwise)")
    ap.add_argument("--out", default=MODEL_PATH)
    ap.add_argument("--cache", help="directory keeping the sampled features of each 50-image chunk (resumes)")
    ap.add_argument("--data-only", action="store_true", help="render and sample (into --cache), do not train")
    ap.add_argument("--evaluate", nargs="+", metavar="FOREST", help="per-cell accuracy on held-out renders")
    ap.add_argument("--plain", action="store_true", help="--evaluate on the older, plainer population")
    args = ap.parse_args()
    if args.evaluate:
        evaluate(args)
        return
    t0 = time.perf_counter()
    x, y, offsets = make_data(args)
    t1 = time.perf_counter()
    print(f"{len(y)} samples from {args.images} + {args.reach_images} + {args.grip_images} images ({t1 - t0:.0f} s)",
          flush=True)
    if args.data_only:
        return
    from sklearn.ensemble import RandomForestClassifier
    print(f"training {args.trees} trees of depth {args.depth} on {x.shape[1]} candidate features", flush=True)
    freq = np.bincount(y, minlength=len(PARTS)) / len(y)
    tree_seed = args.seed if args.tree_seed is None else args.tree_seed
    weight = np.maximum(freq, 1e-9)[y] ** -args.balance
    rf = RandomForestClassifier(n_estimators=args.trees, max_depth=args.depth, max_features=40,
                                min_samples_leaf=5, random_state=tree_seed, n_jobs=1)
    rf.fit(x, y, sample_weight=weight * (len(y) / weight.sum()))
    recount_leaves(rf, x, y)
    forest = flatten(rf, offsets)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    forest.save(args.out, images=args.images, reach_images=args.reach_images, grip_images=args.grip_images,
                pixels=args.pixels, trees=args.trees, depth=args.depth, seed=args.seed, tree_seed=tree_seed,
                balance=args.balance, no_skirts=args.no_skirts, samples=int(len(y)), data_s=round(t1 - t0),
                train_s=round(time.perf_counter() - t1))
    print(f"wrote {args.out}: {len(forest.feature)} nodes, depth {forest.depth} "
          f"({Path(args.out).stat().st_size / 1e6:.1f} MB); training took {time.perf_counter() - t1:.0f} s")


if __name__ == "__main__":
    main()
