"""Several performers on one source: numbered OSC users become bodies, and BodyFanout routes each body's
frames to the session of its own rig (bpy-free)."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V2, NOT_TRACKED
from kinect_retarget.sources import SourceError, TakePlayback
from kinect_retarget.sources.body_fanout import BodyFanout
from kinect_retarget.sources.frame_queue import FrameQueue
from kinect_retarget.sources.osc_receiver import UserFrames
from kinect_retarget.takes import load_take
from tests.takes.two_performers import write_two_person_ntu

HAND = KINECT_V2.index("HandLeft")


@pytest.mark.parametrize("address,body", [("/Left_Hand", 0), ("/Left_Hand_1", 0), ("/Left_Hand_2", 1),
                                          ("/2/Left_Hand", 1), ("/user3/left_hand", 2), ("/skeleton_2/HandLeft", 1)])
def test_user_numbers_in_addresses_pick_the_body(address, body):
    users = UserFrames(KINECT_V2)
    assert users.feed(address, [1.0, 2.0, 3.0]) == []
    (got_body, pos, st), = users.feed("/NI_mate_sync", [])
    assert got_body == body and st[HAND] != NOT_TRACKED
    np.testing.assert_allclose(pos[HAND], [1, 2, 3])


def test_users_are_assembled_apart():
    users = UserFrames(KINECT_V2)
    users.feed("/Left_Hand_1", [1, 1, 1])
    users.feed("/Left_Hand_2", [2, 2, 2])
    (b, pos, _), = users.feed("/Left_Hand_1", [3, 3, 3])  # a repeat ends only user 1's frame
    assert b == 0 and pos[HAND, 0] == 1
    done = users.flush()
    assert [d[0] for d in done] == [0, 1] and done[0][1][HAND, 0] == 3 and done[1][1][HAND, 0] == 2
    assert users.feed("/Foo_2", [0, 0, 0]) == [] and users.feed("/Head_0", [0, 0, 0]) == []
    assert {"/Foo_2", "/Head_0"} <= users.ignored
    zero_based = UserFrames(KINECT_V2, first_user=0)  # bridges that number users from 0
    zero_based.feed("/Head_0", [0, 0, 0])
    assert [d[0] for d in zero_based.flush()] == [0]


def test_fanout_routes_each_body_to_its_queue(data_dir, tmp_path):
    path = write_two_person_ntu(data_dir, tmp_path / "S001C001P001R001A050.skeleton")
    src = TakePlayback(str(path), speed=5.0, bodies=(0, 1))
    fan = BodyFanout(src)
    a, b = fan.body(0), fan.body(1)
    qa, qb = FrameQueue(), FrameQueue()
    a.start(qa)
    assert src.alive or src.status in ("running", "finished")
    b.start(qb)
    with pytest.raises(SourceError, match="already drives"):
        fan.body(1).start(FrameQueue())
    src._thread.join(10)
    fa, fb = qa.drain(), qb.drain()
    # b joined a moment after a (frames are 6.7 ms apart): each got its own body's frames, in order
    assert len(fa) == 60 and 55 <= len(fb) <= 60 and {f.body for f in fa} == {0} and {f.body for f in fb} == {1}
    ta, tb = load_take(path), load_take(path, body=1)
    np.testing.assert_allclose(fa[-1].positions, np.nan_to_num(ta.positions[-1]))
    np.testing.assert_allclose(fb[-1].positions, np.nan_to_num(tb.positions[-1]))
    assert a.describe().endswith("body 0") and a.skeleton is KINECT_V2 and not a.alive
    a.stop()
    assert src._stop.is_set() is False  # b still attached: the shared source is not stopped for it
    b.stop()
    assert src.stopping


def test_fanout_counts_frames_nobody_follows(data_dir, tmp_path):
    path = write_two_person_ntu(data_dir, tmp_path / "S001C001P001R001A050.skeleton")
    src = TakePlayback(str(path), speed=50.0, bodies=(0, 1))
    fan = BodyFanout(src)
    q = FrameQueue()
    view = fan.body(1)
    view.start(q)
    src._thread.join(10)
    view.stop()
    assert len(q.drain()) == 60 and fan.unrouted == 60
