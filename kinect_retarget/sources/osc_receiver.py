"""UDP/OSC receiver compatible with NI mate's skeleton stream ("Basic" format: one message per joint,
`/<Joint_Name> x y z`, then `/NI_mate_sync`).

Bound to 127.0.0.1 unless the user asks otherwise. Arguments are only ever read as numbers; a malformed
packet is counted, shown (`warning`) and skipped, since one stray datagram must not end live; only socket
errors stop the receiver. A frame ends at
`/NI_mate_sync`, at the end of a bundle, or when a joint repeats (senders without sync markers).
Positions are taken as Kinect camera space metres (NI mate's skeleton output; see docs/live.md).

Several performers on one stream: NI mate numbers its users (its `[U]` address tag), other bridges
likewise. A user number in the address picks the performer: a suffix, `/Left_Hand_2` (NI mate's
`/Left_Hand_[U]`), or a first address part, `/2/Left_Hand`, `/user2/Left_Hand`, `/skeleton_2/left_hand`.
Users are numbered from `first_user` (NI mate: 1): user `first_user + n` is body n; an address without a
number is body 0. Each user's joints are assembled on their own; a sync message or the end of a bundle ends
every user's frame, a repeated joint only that user's. Frames carry their body (sources/body_fanout.py
routes them to one rig each).
"""
from __future__ import annotations

import re
import socket
import time

import numpy as np

from ..core.skeletons import INFERRED, KINECT_V2, NOT_TRACKED, TRACKED, Skeleton
from .frame_source import FrameSource, SourceError
from .osc_codec import OscError, parse_packet

SYNC_ADDRESSES = {"/ni_mate_sync"}
# NI mate / OpenNI names that are not simply "Side_Part" spellings of SDK names.
_ALIASES = {"torso": ("SpineMid", "Spine"), "neck": ("Neck", "ShoulderCenter"),
            "pelvis": ("SpineBase", "HipCenter"), "hips": ("SpineBase", "HipCenter"),
            "waist": ("SpineBase", "HipCenter"), "spine": ("SpineMid", "Spine"),
            "spineshoulder": ("SpineShoulder", "ShoulderCenter"), "shouldercenter": ("SpineShoulder", "ShoulderCenter"),
            "hipcenter": ("SpineBase", "HipCenter"), "spinebase": ("SpineBase", "HipCenter"),
            "spinemid": ("SpineMid", "Spine")}


def joint_lookup(skeleton: Skeleton) -> dict[str, int]:
    """Lower-case OSC joint names (without '/') -> joint index, for every spelling we accept."""
    table: dict[str, int] = {}
    for j, name in enumerate(skeleton.joints):
        table[name.lower()] = j
        for side in ("Left", "Right"):
            if name.endswith(side):  # HandTipLeft -> left_hand_tip, left_handtip
                part = name[:-len(side)]
                words = "_".join(w.lower() for w in _split_camel(part))
                table[f"{side.lower()}_{words}"] = j
                table[f"{side.lower()}_{part.lower()}"] = j
    for alias, candidates in _ALIASES.items():
        for cand in candidates:
            if cand in skeleton.joints:
                table.setdefault(alias, skeleton.index(cand))
                break
    return table


def _split_camel(s: str) -> list[str]:
    out, cur = [], ""
    for ch in s:
        if ch.isupper() and cur:
            out.append(cur)
            cur = ""
        cur += ch
    return out + ([cur] if cur else [])


class FrameAssembler:
    """Collects joint messages into whole frames. Pure: feed messages, get finished frames back."""

    def __init__(self, skeleton: Skeleton):
        self.skeleton = skeleton
        self.lookup = joint_lookup(skeleton)
        self.ignored: set[str] = set()  # addresses we do not know: shown in the status, never an error
        self._reset()

    def _reset(self) -> None:
        self.positions = np.zeros((len(self.skeleton), 3))
        self.states = np.zeros(len(self.skeleton), dtype=np.uint8)

    def feed(self, address: str, args: list) -> tuple[np.ndarray, np.ndarray] | None:
        """Returns a finished (positions, states) when this message completes a frame."""
        key = address[1:].lower().replace("/", "_")
        if address.lower() in SYNC_ADDRESSES:
            return self.flush()
        j = self.lookup.get(key)
        if j is None:
            self.ignored.add(address[:64])
            return None
        if len(args) < 3 or any(isinstance(a, (str, bool)) for a in args[:3]):
            raise OscError(f"{address}: expected 3 numbers x y z, got {args[:4]!r}")
        xyz = np.array(args[:3], dtype=np.float64)
        if not np.all(np.isfinite(xyz)):
            raise OscError(f"{address}: NaN or infinite coordinate")
        done = self.flush() if self.states[j] != NOT_TRACKED else None  # a repeat starts the next frame
        self.positions[j] = xyz
        self.states[j] = TRACKED
        return done

    def flush(self) -> tuple[np.ndarray, np.ndarray] | None:
        if not self.states.any():
            return None
        pos, st = self.positions, self.states
        self._infer_root(pos, st)
        self._reset()
        return pos, st

    def _infer_root(self, pos: np.ndarray, st: np.ndarray) -> None:
        # NI mate's basic skeleton has no pelvis joint; the root is the hips' midpoint then.
        r = self.skeleton.root
        hips = [self.skeleton.joints.index(n) for n in ("HipLeft", "HipRight") if n in self.skeleton.joints]
        if st[r] == NOT_TRACKED and len(hips) == 2 and all(st[h] != NOT_TRACKED for h in hips):
            pos[r] = pos[hips].mean(axis=0)
            st[r] = INFERRED


_PREFIX = re.compile(r"^/(?:user_?|skeleton_?|u)?(\d+)(/.+)$", re.IGNORECASE)
_SUFFIX = re.compile(r"^(/.+?)_(\d+)$")
MAX_BODIES = 16  # more users than any sensor tracks: a number beyond is an address we do not know


class UserFrames:
    """Feed OSC messages; get back (body, positions, states) for every frame a message completes."""

    def __init__(self, skeleton: Skeleton, first_user: int = 1):
        self.skeleton = skeleton
        self.first_user = int(first_user)
        self.users: dict[int, FrameAssembler] = {}
        self.ignored: set[str] = set()

    def split(self, address: str) -> tuple[int, str]:
        """(body, address without the user number)."""
        lookup = self._assembler(0).lookup
        for pattern, joint_part, user_part in ((_PREFIX, 2, 1), (_SUFFIX, 1, 2)):
            m = pattern.match(address)
            if m is None or address[1:].lower().replace("/", "_") in lookup:
                continue
            body = int(m.group(user_part)) - self.first_user
            if 0 <= body < MAX_BODIES:
                return body, m.group(joint_part)
        return 0, address

    def feed(self, address: str, args: list) -> list[tuple[int, np.ndarray, np.ndarray]]:
        if address.lower() in SYNC_ADDRESSES:
            return self.flush()
        body, joint = self.split(address)
        asm = self._assembler(body)
        done = asm.feed(joint, args)
        if asm.ignored:  # shown as sent, with its user number
            self.ignored.add(address[:64])
            asm.ignored.clear()
        return [] if done is None else [(body, *done)]

    def flush(self) -> list[tuple[int, np.ndarray, np.ndarray]]:
        out = []
        for body in sorted(self.users):
            done = self.users[body].flush()
            if done is not None:
                out.append((body, *done))
        return out

    def _assembler(self, body: int) -> FrameAssembler:
        asm = self.users.get(body)
        if asm is None:
            asm = self.users[body] = FrameAssembler(self.skeleton)
        return asm


class OscReceiver(FrameSource):
    kind = "osc"

    def __init__(self, port: int = 7000, host: str = "127.0.0.1", skeleton: Skeleton = KINECT_V2,
                 rate: float = 30.0, first_user: int = 1):
        if not (0 <= int(port) <= 65535):
            raise SourceError(f"OSC port {port} is out of range 0-65535")
        super().__init__(skeleton, rate)
        self.host, self.port = host, int(port)
        self.assembler = UserFrames(skeleton, first_user)
        self.packets = 0
        self.bad_packets = 0
        self._sock: socket.socket | None = None

    def describe(self) -> str:
        return f"OSC {self.host}:{self.port}"

    def _open(self) -> None:
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            sock.bind((self.host, self.port))
        except OSError as exc:
            sock.close()
            raise SourceError(f"cannot listen for OSC on {self.host}:{self.port}: {exc.strerror or exc}") from None
        sock.settimeout(0.05)  # wake up regularly to notice stop()
        self.port = sock.getsockname()[1]  # port 0 picks a free one (tests)
        self._sock = sock

    def _close(self) -> None:
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    def _run(self) -> None:
        sock = self._sock
        while not self.stopping:
            try:
                data, sender = sock.recvfrom(65536)
            except TimeoutError:
                continue
            except OSError as exc:
                if self.stopping:
                    return
                raise SourceError(f"{self.describe()}: socket error: {exc.strerror or exc}") from None
            self.packets += 1
            try:
                messages = parse_packet(data)
                is_bundle = data.startswith(b"#bundle")
                for address, args in messages:
                    for body, pos, st in self.assembler.feed(address, args):
                        self._emit(pos, st, time.perf_counter(), where=f" packet {self.packets}", body=body)
                if is_bundle:  # a bundle holds one whole frame (of every user in it)
                    for body, pos, st in self.assembler.flush():
                        self._emit(pos, st, time.perf_counter(), where=f" packet {self.packets}", body=body)
            except OscError as exc:  # never evaluated, never fatal: count it, say which, go on
                self.bad_packets += 1
                self.warning = (f"{self.describe()}: {self.bad_packets} bad OSC packet(s) ignored; latest, "
                                f"packet {self.packets} from {sender[0]}:{sender[1]}: {exc}")
