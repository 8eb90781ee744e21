"""`make demo`: bake the bundled sample takes onto a generated Kinect rig and onto a Rigify rig, save one
.blend per take and rig, render a few Workbench stills of each with a simple body mesh, print a summary.

    .venv/bin/python tools/demo.py --out demo_output [--takes A.krtake ...] [--all] [--no-rigify]
        [--no-render] [--stills 3] [--rigify-frames N] [--resolution 640x480] [--docs-images docs/images]

Everything runs headless in one process (bpy as a module). The Rigify rig is generated once from Blender's
human metarig (rigify_generate) and reopened for each Rigify take, which is baked whole (its constraint-driven
parents are learned once and solved in numpy, issue 15); --rigify-frames N cuts Rigify takes to N frames.
"""
from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

import numpy as np  # noqa: E402

from kinect_retarget.core.take import Take, TakeError  # noqa: E402
from kinect_retarget.takes import load_take  # noqa: E402

SAMPLE_TAKES = REPO / "sample_takes"
# Default selection: Kinect v2 gestures (real sensor data) and CMU-derived Kinect v1 takes (jump, hop, walk).
GENERATED_TAKES = ("kinect_v2_ges01_wavehand", "kinect_v2_ges04_comehere", "kinect_v2_ges06_chickenwing",
                   "kinect_v2_kinectron_recorded_skeleton", "kinect_v1_cmu_131_03_hop",
                   "kinect_v1_cmu_01_01_jumps", "kinect_v1_cmu_131_01_walk")
RIGIFY_TAKES = ("kinect_v2_ges01_wavehand", "kinect_v1_cmu_131_03_hop")
# contact sheets copied into docs/images by --docs-images: (take, rig) -> file name
DOCS_IMAGES = {("kinect_v2_ges01_wavehand", "kinect"): "demo_wavehand_kinect_rig.png",
               ("kinect_v2_ges06_chickenwing", "kinect"): "demo_chickenwing_kinect_rig.png",
               ("kinect_v1_cmu_131_03_hop", "kinect"): "demo_cmu_hop_kinect_rig.png",
               ("kinect_v2_ges01_wavehand", "rigify"): "demo_wavehand_rigify.png"}
DOCS_IMAGE_LIMIT = 100_000  # bytes: keep the repository light
RIGIFY_FRAMES = 0  # whole takes: a Rigify bake costs about what the generated rig's does (issue 15)
RIGS = {"kinect": "generated Kinect rig", "rigify": "Rigify rig (human metarig)"}


@dataclass
class Job:
    take_path: Path
    rig: str                      # "kinect" | "rigify"
    max_frames: int | None = None


@dataclass
class Outcome:
    job: Job
    name: str = ""
    blend: str = ""
    stills: list[str] = field(default_factory=list)
    sheet: str = ""
    frames: int = 0
    frame_range: tuple[int, int] = (0, 0)
    bones: int = 0
    preset: str = ""
    bake_s: float = 0.0
    render_s: float = 0.0
    error: str = ""


@contextlib.contextmanager
def quiet_stdout():
    """Hide Blender's C-level chatter on stdout (render 'Saved:', Rigify timings) so the demo's own lines
    stay readable; on failure the hidden text is printed to stderr so nothing is lost."""
    sys.stdout.flush()
    saved = os.dup(1)
    with tempfile.TemporaryFile(mode="w+b") as sink:
        os.dup2(sink.fileno(), 1)
        try:
            yield
        except BaseException:
            sys.stdout.flush()
            os.dup2(saved, 1)
            sink.seek(0)
            sys.stderr.write(sink.read().decode(errors="replace"))
            raise
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)


def log(message: str) -> None:
    print(message, flush=True)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="demo_output", help="output folder (created)")
    parser.add_argument("--takes", nargs="+", type=Path, metavar="TAKE",
                        help="take files of any supported format (default: a selection of sample_takes/)")
    parser.add_argument("--all", action="store_true", help="every take in sample_takes/ on the generated rig")
    parser.add_argument("--no-rigify", action="store_true", help="skip the Rigify rig")
    parser.add_argument("--rigify-takes", nargs="*", type=Path, metavar="TAKE",
                        help="takes to bake onto Rigify (default: two sample takes; with --takes: the first)")
    parser.add_argument("--rigify-frames", type=int, default=RIGIFY_FRAMES,
                        help=f"bake only the first N frames onto Rigify (0: all; default {RIGIFY_FRAMES})")
    parser.add_argument("--no-render", action="store_true", help="bake and save only")
    parser.add_argument("--stills", type=int, default=3, help="stills rendered per take and rig (default 3)")
    parser.add_argument("--resolution", default="640x480", help="still size WxH (default 640x480)")
    parser.add_argument("--docs-images", type=Path, metavar="DIR",
                        help="also copy the contact sheets used by docs/demo.md into DIR (e.g. docs/images)")
    args = parser.parse_args(argv)
    try:
        w, h = (int(v) for v in args.resolution.lower().split("x"))
        if w < 16 or h < 16:
            raise ValueError
        args.resolution = (w, h)
    except ValueError:
        parser.error(f"--resolution must look like 640x480, got {args.resolution!r}")
    if args.stills < 1:
        parser.error("--stills must be at least 1")
    return args


def plan(args: argparse.Namespace) -> list[Job]:
    def sample(name: str) -> Path:
        return SAMPLE_TAKES / f"{name}.krtake"

    if args.takes:
        generated = list(args.takes)
        rigify = list(args.rigify_takes) if args.rigify_takes is not None else generated[:1]
    else:
        if not SAMPLE_TAKES.is_dir():
            raise SystemExit(f"error: {SAMPLE_TAKES} not found: run tools/make_sample_takes.py or pass --takes")
        generated = (sorted(SAMPLE_TAKES.glob("*.krtake")) if args.all
                     else [sample(n) for n in GENERATED_TAKES if sample(n).is_file()])
        rigify = (list(args.rigify_takes) if args.rigify_takes is not None
                  else [sample(n) for n in RIGIFY_TAKES if sample(n).is_file()])
    jobs = [Job(p, "kinect") for p in generated]
    if not args.no_rigify:
        jobs += [Job(p, "rigify", args.rigify_frames or None) for p in rigify]
    if not jobs:
        raise SystemExit("error: no take to bake")
    return jobs


def still_frames(first: int, last: int, count: int) -> list[int]:
    """`count` frames spread over the take, away from its very ends (where the performer is still)."""
    if count == 1:
        return [int(round((first + last) / 2))]
    return sorted({int(round(f)) for f in np.linspace(first, last, count + 2)[1:-1]})


def read_take(job: Job) -> Take:
    take = load_take(job.take_path)
    if job.max_frames and take.frame_count > job.max_frames:
        take = take.slice(slice(0, job.max_frames))
    return take


def make_rigify_rig(path: str) -> None:
    """Generate a Rigify rig from Blender's human metarig in a fresh file and save it as the base file.

    Rigify is enabled after read_factory_settings, which would otherwise disable it again."""
    import addon_utils
    import bpy

    from kinect_retarget.blender.headless import save_blend

    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    metarig = bpy.context.view_layer.objects.active
    bpy.ops.pose.rigify_generate()
    rig = bpy.context.view_layer.objects.active
    if rig is None or rig == metarig or rig.type != "ARMATURE":
        raise RuntimeError("Rigify did not generate a rig from the human metarig")
    metarig.hide_viewport = metarig.hide_render = True  # kept for re-generating, out of the pictures
    rig.name = "RigifyRig"
    bpy.context.preferences.filepaths.save_version = 0
    save_blend(path)


def run_job(job: Job, out: Path, args: argparse.Namespace, rigify_base: str | None) -> Outcome:
    import bpy

    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    from tools.demo_body import add_body_mesh
    from kinect_retarget.blender.headless import save_blend
    from kinect_retarget.blender.io.workbench_render import contact_sheet, stage, stage_and_render

    result = Outcome(job)
    take = read_take(job)
    name = job.take_path.stem
    result.name = name
    stem = f"{name}__{job.rig}"
    t0 = time.perf_counter()
    if job.rig == "rigify":
        with quiet_stdout():
            bpy.ops.wm.open_mainfile(filepath=rigify_base, load_ui=False)
        obj = bpy.data.objects["RigifyRig"]
        preset = "rigify"
    else:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        obj = new_generated_rig(bpy.context.scene, take)
        preset = "kinect"
    bpy.context.view_layer.objects.active = obj
    with quiet_stdout():
        baked = bake_take(obj, take, preset=preset, action_name=f"{name}_{job.rig}")
    result.bake_s = time.perf_counter() - t0
    result.frames, result.frame_range = len(baked.motion.frames), baked.frame_range
    result.bones, result.preset = len(baked.motion.bone_names), baked.preset
    body = add_body_mesh(obj)
    scene = bpy.context.scene
    t1 = time.perf_counter()
    frames = still_frames(*baked.frame_range, args.stills)
    note = f"{name} - {RIGS[job.rig]}"
    with quiet_stdout():
        if args.no_render:   # the saved file still gets its floor and camera
            stage(scene, [body], frames, note, args.resolution)
        else:
            renders = out / "renders"
            result.stills = stage_and_render(scene, [body], frames, str(renders), stem, note, args.resolution)
            if len(result.stills) > 1:
                result.sheet = contact_sheet(result.stills, str(renders / f"{stem}_sheet.png"))
    result.render_s = time.perf_counter() - t1
    scene.frame_set(baked.frame_range[0])
    scene.render.filepath = f"//renders/{stem}_anim_"  # Render Animation in the saved file writes beside it
    result.blend = str(out / f"{stem}.blend")
    bpy.context.preferences.filepaths.save_version = 0  # re-running the demo leaves no .blend1 backups
    with quiet_stdout():
        save_blend(result.blend)
    return result


def copy_docs_images(outcomes: list[Outcome], directory: Path) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    for o in outcomes:
        target = DOCS_IMAGES.get((o.name, o.job.rig))
        if not target or not o.sheet:
            continue
        size = os.path.getsize(o.sheet)
        if size > DOCS_IMAGE_LIMIT:
            log(f"  not copied to {directory}: {os.path.basename(o.sheet)} is {size // 1000} KB "
                f"(limit {DOCS_IMAGE_LIMIT // 1000} KB)")
            continue
        shutil.copyfile(o.sheet, directory / target)
        log(f"docs image:   {os.path.relpath(directory / target)} ({size // 1000} KB)")


def print_summary(outcomes: list[Outcome], out: Path, elapsed: float) -> None:
    log("")
    log(f"{'take':40s} {'rig':7s} {'frames':>6s} {'bones':>5s} {'bake s':>7s} {'render s':>8s}  output")
    for o in outcomes:
        if o.error:
            log(f"{o.job.take_path.name:40s} {o.job.rig:7s} FAILED: {o.error}")
            continue
        log(f"{o.name:40s} {o.job.rig:7s} {o.frames:6d} {o.bones:5d} {o.bake_s:7.2f} {o.render_s:8.2f}  "
            f"{os.path.relpath(o.blend)}")
    ok = [o for o in outcomes if not o.error]
    stills = sum(len(o.stills) for o in ok)
    log("")
    log(f"{len(ok)} of {len(outcomes)} bakes done: {sum(o.frames for o in ok)} frames keyed, "
        f"{stills} stills rendered, in {elapsed:.1f} s")
    log(f".blend files: {os.path.relpath(out)}/*.blend (open one and press Play; the body mesh, floor and "
        f"camera are in the file)")
    if stills:
        log(f"stills:       {os.path.relpath(out / 'renders')}/*.png (contact sheets: *_sheet.png)")
    log("colours: the character's right side is red, its left side blue; it faces the camera (-Y), so its "
        "right hand is on the left of each picture")


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    jobs = plan(args)
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    log(f"kinect_retarget demo: {len(jobs)} bake{'s' * (len(jobs) != 1)} into {os.path.relpath(out)}/")
    with quiet_stdout():
        import bpy  # noqa: F401  (first import prints Blender's start-up lines)
    rigify_base = None
    outcomes: list[Outcome] = []
    for job in jobs:
        if job.rig == "rigify" and rigify_base is None:
            rigify_base = str(out / "rigify_rig.blend")
            log("generating a Rigify rig from Blender's human metarig ...")
            try:
                with quiet_stdout():
                    make_rigify_rig(rigify_base)
            except Exception as exc:  # an addon problem must not hide the bakes already done
                rigify_base = ""
                log(f"  Rigify rig could not be generated: {exc}")
        label = f"{job.take_path.name} -> {RIGS[job.rig]}"
        if job.rig == "rigify" and not rigify_base:
            outcomes.append(Outcome(job, error="no Rigify rig"))
            continue
        log(f"baking {label}" + (f" (first {job.max_frames} frames)" if job.max_frames else "") + " ...")
        try:
            outcome = run_job(job, out, args, rigify_base)
        except (TakeError, ValueError, OSError, RuntimeError) as exc:
            outcome = Outcome(job, error=str(exc))
            log(f"  failed: {exc}")
        except Exception as exc:  # unexpected: say what, keep the other bakes going
            outcome = Outcome(job, error=f"{type(exc).__name__}: {exc}")
            log(f"  failed unexpectedly: {outcome.error}")
        else:
            stills = f"; {len(outcome.stills)} stills in {outcome.render_s:.2f} s" if outcome.stills else ""
            log(f"  {outcome.frames} frames, {outcome.bones} bones ({outcome.preset}) in {outcome.bake_s:.2f} s"
                + stills)
        outcomes.append(outcome)
    print_summary(outcomes, out, time.perf_counter() - start)
    if args.docs_images:
        copy_docs_images(outcomes, args.docs_images)
    return 1 if any(o.error for o in outcomes) else 0


if __name__ == "__main__":
    sys.exit(main())
