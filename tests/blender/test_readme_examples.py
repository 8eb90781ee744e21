"""The README's commands run as written: every `python -m kinect_retarget ...` line of its sh blocks runs from a
scratch folder that holds the repository's package and sample takes (what a clone has), and exits 0. Lines
that are templates (placeholders for the user's own files) are listed below, so none is skipped silently."""
from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
TEMPLATES = {   # command -> why it cannot run as written
    "bake TAKE": "placeholders for the user's take and rig",
    "lift keypoints/": "the user's OpenPose folder",
    "bake walk.krtake": "the output of the lift line and the user's rig",
    "track-2d frames/": "the user's image sequence",
}


def readme_commands() -> list[str]:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    lines = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        for line in block.replace("\\\n", " ").splitlines():
            line = line.split(" # ")[0].strip()
            if line.startswith("python -m kinect_retarget"):
                lines.append(" ".join(line.split()))
    return lines


def _template(cmd: str) -> bool:
    rest = cmd.removeprefix("python -m kinect_retarget ")
    return any(rest.startswith(t) for t in TEMPLATES)


COMMANDS = [c for c in readme_commands() if not _template(c)]


def test_the_readme_has_runnable_commands_and_every_template_is_known():
    assert len(COMMANDS) >= 7
    found = {t for t in TEMPLATES for c in readme_commands() if c.startswith(f"python -m kinect_retarget {t}")}
    assert found == set(TEMPLATES)


@pytest.mark.parametrize("cmd", COMMANDS, ids=[c.split()[3] + ":" + str(i) for i, c in enumerate(COMMANDS)])
def test_readme_command_runs_as_written(cmd, tmp_path, tmp_path_factory):
    for name in ("kinect_retarget", "sample_takes"):
        (tmp_path / name).symlink_to(REPO / name)
    args = shlex.split(cmd)
    env = dict(os.environ, KR_DEPTH_CACHE=str(tmp_path_factory.getbasetemp() / "depth_cache"))
    proc = subprocess.run([sys.executable, *args[1:]], cwd=tmp_path, capture_output=True, text=True, env=env,
                          timeout=600)
    assert proc.returncode == 0, f"{cmd}\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    if "--out" in args:
        assert (tmp_path / args[args.index("--out") + 1]).is_file()
