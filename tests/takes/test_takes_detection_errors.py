"""Format detection on every real file and fixture, and clear errors (file and line) on corrupted copies."""
from __future__ import annotations

import json

import pytest

from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import READERS, detect_format, load_take
from tests.takes import format_fixtures as fx

REAL = {  # path under tests/data: expected format
    **{f"kinect_v2/{n}": "kinect_v2_csv" for n in (
        "Ges01_wavehand.csv", "Ges02_balancinghands.csv", "Ges03_drawlines.csv", "Ges04_comehere.csv",
        "Ges05_demopoint.csv", "Ges06_chickenwing.csv", "joints.csv")},
    "kinect_v2/recorded_skeleton.json": "kinectron_json",
    **{f"mocap_bvh/{n}": "bvh" for n in ("01_01.bvh", "131_01.bvh", "131_02.bvh", "131_03.bvh")},
    "meshes/makehuman/tpose.bvh": "bvh",
    "meshes/makehuman/benchmark.bvh": "bvh",
}
FIXTURE_FORMATS = {"ntu": "ntu_skeleton", "msrc12": "msrc12", "utkinect": "utkinect"}


@pytest.mark.parametrize("rel", sorted(REAL))
def test_detects_real_files(data_dir, rel):
    assert detect_format(data_dir / rel) == REAL[rel]


@pytest.mark.parametrize("name", sorted(FIXTURE_FORMATS))
def test_detects_converted_fixtures(name):
    path = {"ntu": "S001C001P001R001A001_converted_Ges01.skeleton", "msrc12": "P1_1_1_converted_joints.csv",
            "utkinect": "joints_s01_e01_converted_joints.txt"}[name]
    assert detect_format(fx.FIXTURES / path) == FIXTURE_FORMATS[name]
    assert load_take(fx.FIXTURES / path).frame_count > 30


def test_detection_ignores_extension(data_dir, tmp_path):
    (tmp_path / "take.txt").write_bytes((data_dir / "mocap_bvh" / "131_01.bvh").read_bytes())
    (tmp_path / "take.bvh").write_bytes((data_dir / "kinect_v2" / "Ges02_balancinghands.csv").read_bytes())
    assert detect_format(tmp_path / "take.txt") == "bvh"
    assert detect_format(tmp_path / "take.bvh") == "kinect_v2_csv"


def test_unknown_and_empty(tmp_path, data_dir):
    (tmp_path / "notes.csv").write_text("name,value\nfoo,1\n")
    with pytest.raises(TakeError, match=r"notes\.csv: unknown take format \(supported: "):
        load_take(tmp_path / "notes.csv")
    (tmp_path / "empty.csv").write_bytes(b"")
    with pytest.raises(TakeError, match=r"empty\.csv: file is empty"):
        load_take(tmp_path / "empty.csv")
    # Plain comma-separated numbers of another width are not taken for Kinect v2 CSV.
    (tmp_path / "numbers.csv").write_text("1,2,3\n4,5,6\n")
    with pytest.raises(TakeError, match=r"numbers\.csv: unknown take format"):
        load_take(tmp_path / "numbers.csv")


# --- corrupted copies: each line-based format, each corruption, the exact line named ---------------------

LINE_FORMATS = {  # format: (source file, index of a data line to damage, field separator)
    "kinect_v2_csv": ("data:kinect_v2/Ges01_wavehand.csv", 40, ","),
    "bvh": ("data:mocap_bvh/131_02.bvh", 300, " "),
    "msrc12": ("fixture:P1_1_1_converted_joints.csv", 20, " "),
    "utkinect": ("fixture:joints_s01_e01_converted_joints.txt", 20, " "),
    "ntu_skeleton": ("fixture:S001C001P001R001A001_converted_Ges01.skeleton", 210, " "),  # a joint line
}


def _source(data_dir, spec):
    kind, rel = spec.split(":", 1)
    return (data_dir / rel) if kind == "data" else fx.FIXTURES / rel


def _damage(lines, i, sep, how):
    fields = lines[i].rstrip("\r\n").rstrip(sep).split(sep)
    if how == "truncated":
        return lines[:i] + [sep.join(fields[:len(fields) // 2])]
    if how == "columns":
        return lines[:i] + [sep.join(fields[:-1]) + "\n"] + lines[i + 1:]
    if how == "nan":
        fields[2] = "nan"
    elif how == "garbage":
        fields[2] = "x=#!"
    return lines[:i] + [sep.join(fields) + "\n"] + lines[i + 1:]


EXPECTED = {  # structural damage keeps its clear error (a NaN joint value does not: tests/takes/test_bad_samples.py)
    "truncated": r"{name}:{line}: (expected \d+ values.*found \d+|file ends inside frame)",
    "columns": r"{name}:{line}: expected \d+ values.*found \d+",
    "garbage": r"{name}:{line}: non-numeric value 'x=#!'",
}


@pytest.mark.parametrize("how", sorted(EXPECTED))
@pytest.mark.parametrize("fmt", sorted(LINE_FORMATS))
def test_corrupted_line_formats(data_dir, tmp_path, fmt, how):
    spec, i, sep = LINE_FORMATS[fmt]
    src = _source(data_dir, spec)
    lines = src.read_text().splitlines(keepends=True)
    name = f"bad_{how}{src.suffix}"
    (tmp_path / name).write_text("".join(_damage(lines, i, sep, how)))
    with pytest.raises(TakeError, match=EXPECTED[how].format(name=name.replace(".", r"\."), line=i + 1)):
        load_take(tmp_path / name)


@pytest.mark.parametrize("fmt", sorted(LINE_FORMATS))
def test_empty_copy(tmp_path, fmt):
    path = tmp_path / f"empty_{fmt}"
    path.write_text("\n\n")
    with pytest.raises(TakeError, match=r"file is empty"):
        load_take(path)
    from importlib import import_module
    with pytest.raises(TakeError, match=r"file is empty"):
        import_module(f"kinect_retarget.takes.{fmt}").read(path)


def test_no_tracked_frame(data_dir, tmp_path):
    lines = (data_dir / "kinect_v2" / "joints.csv").read_text().splitlines()
    dead = []
    for line in lines[:10]:
        fields = line.rstrip(",").split(",")
        fields[4::4] = ["0"] * 25
        dead.append(",".join(fields))
    (tmp_path / "dead.csv").write_text("\n".join(dead) + "\n")
    with pytest.raises(TakeError, match=r"dead\.csv: no joint is tracked in any frame"):
        load_take(tmp_path / "dead.csv")
    fields = lines[3].split(",")
    fields[8] = "3"
    (tmp_path / "state.csv").write_text("\n".join(lines[:3] + [",".join(fields)] + lines[4:]) + "\n")
    with pytest.raises(TakeError, match=r"state\.csv:4: tracking state must be 0, 1 or 2"):
        load_take(tmp_path / "state.csv")
    (tmp_path / "time.csv").write_text("\n".join(lines[:5] + [lines[2]] + lines[6:]) + "\n")
    with pytest.raises(TakeError, match=r"time\.csv:6: timestamp \d+ is not after"):
        load_take(tmp_path / "time.csv")


def test_corrupted_kinectron(data_dir, tmp_path):
    text = (data_dir / "kinect_v2" / "recorded_skeleton.json").read_text()
    (tmp_path / "cut.json").write_text(text[: len(text) // 2])
    with pytest.raises(TakeError, match=r"cut\.json:1: invalid JSON at column \d+"):
        load_take(tmp_path / "cut.json")
    head = json.dumps(json.loads(text)[:30])  # the cases below only need the first records
    cases = {
        "joints.json": (lambda r: r[7].__setitem__("joints", r[7]["joints"][:24]),
                        r"joints\.json: record 7: expected 25 joints, found 24"),
        "key.json": (lambda r: r[9]["joints"][3].pop("cameraY"), r"key\.json: record 9: joint without 'cameraY'"),
        "text.json": (lambda r: r[12]["joints"][0].__setitem__("cameraX", "left"),
                      r"text\.json: record 12: non-numeric"),
        "time.json": (lambda r: r[20].__setitem__("record_timestamp", r[10]["record_timestamp"]),
                      r"time\.json: record 20: record_timestamp"),
        "none.json": (lambda r: [f.__setitem__("tracked", False) for f in r],
                      r"none\.json: no tracked body in any of its 30 records"),
    }
    for name, (edit, pattern) in cases.items():
        doc = json.loads(head)
        edit(doc)
        (tmp_path / name).write_text(json.dumps(doc))
        with pytest.raises(TakeError, match=pattern):
            load_take(tmp_path / name)


def test_readers_registered():
    assert {"krtake", "bvh", "kinect_v2_csv", "kinectron_json", "ntu_skeleton", "msrc12",
            "utkinect", "uiprmd"} <= set(READERS)


def test_nothing_tracked_in_converted_formats(tmp_path, data_dir):
    """A file whose every frame is empty is an error, not an empty take, in every Kinect format."""
    from kinect_retarget.core.skeletons import NOT_TRACKED
    from kinect_retarget.takes import kinect_v2_csv
    take = kinect_v2_csv.read(data_dir / "kinect_v2" / "Ges03_drawlines.csv").slice(slice(0, 12))
    take.states[:] = NOT_TRACKED
    fx.write_ntu(take, tmp_path / "none.skeleton")
    fx.write_msrc12(fx.v1_from_v2(take), tmp_path / "none_msrc.csv")
    fx.write_utkinect(fx.v1_from_v2(take), tmp_path / "none_ut.txt")
    for name, pattern in (("none.skeleton", "no tracked body in any of its 12 frames"),
                          ("none_msrc.csv", "no joint is tracked in any frame"),
                          ("none_ut.txt", "no joint is tracked in any frame")):
        with pytest.raises(TakeError, match=name.replace(".", r"\.") + ": " + pattern):
            load_take(tmp_path / name)


def test_empty_json_and_uiprmd(tmp_path):
    for name in ("empty.json", "m01_s01_e01_positions.txt"):
        (tmp_path / name).write_text("")
        with pytest.raises(TakeError, match=name.replace(".", r"\.") + ": file is empty"):
            load_take(tmp_path / name)
    (tmp_path / "list.json").write_text("[]")
    with pytest.raises(TakeError, match=r"list\.json: unknown take format"):
        load_take(tmp_path / "list.json")
    from kinect_retarget.takes import kinectron_json
    with pytest.raises(TakeError, match=r"list\.json: recording has no frames"):
        kinectron_json.read(tmp_path / "list.json")


@pytest.mark.parametrize("rel", sorted(REAL) + ["uiprmd:m05_s01_e01_angles.txt", "fixture:ntu", "fixture:msrc12",
                                                "fixture:utkinect"])
def test_every_reader_take_saves_as_krtake(data_dir, tmp_path, rel):
    """Whatever was read can be saved in the project's format and read back unchanged (metadata too)."""
    import numpy as np
    from kinect_retarget.core.skeletons import NOT_TRACKED
    from kinect_retarget.takes import krtake
    if rel.startswith("fixture:"):
        path = fx.FIXTURES / {"ntu": "S001C001P001R001A001_converted_Ges01.skeleton",
                              "msrc12": "P1_1_1_converted_joints.csv",
                              "utkinect": "joints_s01_e01_converted_joints.txt"}[rel[8:]]
    elif rel.startswith("uiprmd:"):
        path = data_dir / "kinect_v2_vicon_uiprmd" / "Kinect" / rel[7:]
    else:
        path = data_dir / rel
    take = load_take(path)
    krtake.write(tmp_path / "saved.krtake", take)
    back = krtake.read(tmp_path / "saved.krtake")
    assert back.skeleton is take.skeleton and back.rate == take.rate
    np.testing.assert_array_equal(back.states, take.states)
    seen = take.states != NOT_TRACKED
    np.testing.assert_allclose(back.positions[seen], take.positions[seen], atol=5e-6)
    np.testing.assert_allclose(back.times, take.times, atol=1e-6)
    # the time unit is the file's own: a .krtake's column is seconds whatever the source used; a .krtake
    # holds one body, so the source's body count is not carried (`body` says which one it was)
    source_meta = {k: v for k, v in take.metadata.items() if k not in ("time_unit", "bodies")}
    assert back.metadata.pop("time_unit") == "s"
    assert back.metadata == json.loads(json.dumps(source_meta))


def test_readers_are_tried_in_a_fixed_order_and_multi_body_names_readers():
    from kinect_retarget import takes
    assert READERS == ("krtake", "kinectron_json", "bvh", "kinect_v2_csv", "uiprmd", "msrc12", "utkinect",
                       "ntu_skeleton")
    assert set(takes.MULTI_BODY) <= set(READERS)
    assert all(callable(getattr(takes, name).looks_like) and callable(getattr(takes, name).read) for name in READERS)
