"""A recording cut off mid-line (crash, power loss) keeps every complete frame; damage elsewhere is an error."""
import pytest

from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import load_take

SAMPLE = "kinect_v2_ges01_wavehand.krtake"


def test_interrupted_last_line_keeps_complete_frames(tmp_path):
    from tests.conftest import SAMPLE_TAKES
    text = (SAMPLE_TAKES / SAMPLE).read_text()
    cut = tmp_path / "cut.krtake"
    cut.write_text(text[: text.rindex("\n", 0, len(text) - 1) + 40])  # 40 characters into the last line
    take = load_take(cut)
    assert take.frame_count == load_take(SAMPLE_TAKES / SAMPLE).frame_count - 1
    assert "cut off" in take.metadata["warnings"][0] and "cut.krtake" in take.metadata["warnings"][0]


def test_truncated_line_in_the_middle_is_an_error(tmp_path):
    from tests.conftest import SAMPLE_TAKES
    lines = (SAMPLE_TAKES / SAMPLE).read_text().splitlines(keepends=True)
    lines[5] = lines[5][:60] + "\n"
    bad = tmp_path / "bad.krtake"
    bad.write_text("".join(lines))
    with pytest.raises(TakeError, match=r"bad.krtake:6: expected 101 values"):
        load_take(bad)


@pytest.mark.parametrize("content, message", [
    (b"\xff\xfe\x00garbage", "not a text take"),
    (b'["kinect_retarget.take"]\n', "header must be a JSON object"),
    (b'{"format": "kinect_retarget.take", "version": 1, "skeleton": "kinect_v1", "rate": "fast"}\n'
     + b"0 " + b"0 0 2 2 " * 20 + b"\n", "rate must be a number"),
])
def test_bad_headers_name_the_file(tmp_path, content, message):
    from kinect_retarget.takes import krtake
    bad = tmp_path / "bad.krtake"
    bad.write_bytes(content)
    with pytest.raises(TakeError, match=message) as info:
        krtake.read(bad)
    assert "bad.krtake" in str(info.value)
