"""UDP/OSC receiver compatible with NI mate's skeleton stream ("Basic" format: one message per joint,
`/<Joint_Name> x y z`, then `/NI_mate_sync`).

Bound to 127.0.0.1 unless the user asks otherwise. Arguments are only ever read as numbers; a malformed
packet is counted, shown (`warning`) and skipped, since one stray datagram must not end live; only socket
errors stop the receiver. A frame ends at
`/NI_mate_sync`, at the end of a bundle, or when a joint repeats (senders without sync markers).
Positions are taken as Kinect camera space metres (NI mate's skeleton output; see docs/live.md).
"""
from __future__ import annotations

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


class OscReceiver(FrameSource):
    kind = "osc"

    def __init__(self, port: int = 7000, host: str = "127.0.0.1", skeleton: Skeleton = KINECT_V2,
                 rate: float = 30.0):
        if not (0 <= int(port) <= 65535):
            raise SourceError(f"OSC port {port} is out of range 0-65535")
        super().__init__(skeleton, rate)
        self.host, self.port = host, int(port)
        self.assembler = FrameAssembler(skeleton)
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
                    frame = self.assembler.feed(address, args)
                    if frame is not None:
                        self._emit(frame[0], frame[1], time.perf_counter(), where=f" packet {self.packets}")
                if is_bundle:  # a bundle holds one whole frame
                    frame = self.assembler.flush()
                    if frame is not None:
                        self._emit(frame[0], frame[1], time.perf_counter(), where=f" packet {self.packets}")
            except OscError as exc:  # never evaluated, never fatal: count it, say which, go on
                self.bad_packets += 1
                self.warning = (f"{self.describe()}: {self.bad_packets} bad OSC packet(s) ignored; latest, "
                                f"packet {self.packets} from {sender[0]}:{sender[1]}: {exc}")
