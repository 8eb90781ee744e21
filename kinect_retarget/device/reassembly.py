"""Depth frame reassembly from isochronous packets, with libfreenect's loss rules.

Packets carry a u8 sequence number and a position flag (start/middle/end of frame). A gap of up to
MAX_GAP packets is skipped over (the missing payload stays 0xFF bytes, which unpack to raw 2047 = "no
reading"); a larger gap, or a flag that contradicts the packet's position, drops the frame in progress and
waits for the next start-of-frame. A frame is delivered only when at most MAX_LOST_PER_FRAME of its packets
were missing or damaged in total. The same code runs on live USB data, the emulated device and dump replay.

Inherently sequential (a state machine over the packet stream), so it is a per-packet loop kept to a few
byte comparisons and one slice copy per packet.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .protocol import (DEPTH_FRAME_BYTES, DEPTH_LAST_PAYLOAD, DEPTH_PACKETS_PER_FRAME, DEPTH_PAYLOAD,
                       FLAG_DEPTH_EOF, FLAG_DEPTH_MOF, FLAG_DEPTH_SOF, PACKET_HEADER_SIZE,
                       TICKS_PER_FRAME, advance_ticks, ticks_between)

MAX_GAP = 5
MAX_LOST_PER_FRAME = 5
MAX_COUNTED_GAP = 300        # a longer timestamp jump is a restarted stream, not lost frames
_FILL = b"\xff" * DEPTH_FRAME_BYTES


@dataclass
class AssembledFrame:
    packed: bytearray          # DEPTH_FRAME_BYTES of 11-bit packed depth
    timestamp: int             # device ticks (60 MHz) of the frame's first packet
    lost_packets: int          # packets missing or damaged in this frame (their pixels read 2047)
    holes: list = field(default_factory=list)   # (start, end) byte ranges of the packed frame never received


@dataclass
class AssemblyStats:
    packets: int = 0           # packets with a valid header
    packets_lost: int = 0      # inferred from sequence gaps
    packets_error: int = 0     # slots the USB stack reported as failed (dump length 0)
    packets_bad: int = 0       # non-empty slots without a depth header, or too long
    packets_damaged: int = 0   # truncated payloads
    frames: int = 0            # delivered
    frames_dropped: int = 0    # started but not delivered
    frames_missed: int = 0     # gaps between delivered frames' timestamps: every frame not delivered
    resyncs: int = 0


class FrameAssembler:
    def __init__(self, max_gap: int = MAX_GAP, max_lost_per_frame: int = MAX_LOST_PER_FRAME):
        self.max_gap = max_gap
        self.max_lost = max_lost_per_frame
        self.stats = AssemblyStats()
        self._synced = False
        self._seq = 0              # sequence number expected next
        self._pkt = 0              # position in the frame of the packet expected next
        self._lost = 0
        self._holes: list = []
        self._timestamp = 0
        self._abs = 0                  # packets since the stream began, counted by sequence number
        self._last_seq: int | None = None
        self._anchor: tuple[int, int] | None = None   # (abs index, timestamp) of the last start-of-frame
        self._last_delivered: int | None = None
        self._buf = bytearray()

    def feed(self, packets) -> list[AssembledFrame]:
        """Feed iso packets in arrival order; None marks a slot the USB stack reported as failed.

        Returns the frames completed by these packets (usually zero or one).
        """
        out: list[AssembledFrame] = []
        for packet in packets:
            if packet is None:
                self.stats.packets_error += 1
                continue
            if len(packet) == 0:
                continue               # empty microframe: normal, the device sends ~242 of every 267
            frame = self._feed_one(packet)
            if frame is not None:
                out.append(frame)
        return out

    # --- state machine -------------------------------------------------------------------------------------
    def _start_frame(self, seq: int) -> None:
        self._synced = True
        self._seq = seq
        self._pkt = 0
        self._lost = 0
        self._holes = []
        self._buf = bytearray(_FILL)

    def _hole(self, first_packet: int, count: int) -> None:
        start = first_packet * DEPTH_PAYLOAD
        self._holes.append((start, min(start + count * DEPTH_PAYLOAD, DEPTH_FRAME_BYTES)))

    def _abandon(self) -> None:
        if self._pkt:
            self.stats.frames_dropped += 1
        self.stats.resyncs += 1
        self._synced = False
        self._pkt = 0

    def _finish(self) -> AssembledFrame | None:
        """End the current frame; the next one starts in a fresh buffer."""
        buf, lost, holes = self._buf, self._lost, self._holes
        self._pkt, self._lost, self._buf, self._holes = 0, 0, bytearray(_FILL), []
        if lost > self.max_lost:
            self.stats.frames_dropped += 1
            return None
        self.stats.frames += 1
        if self._last_delivered is not None:
            gap = round(ticks_between(self._last_delivered, self._timestamp) / TICKS_PER_FRAME) - 1
            self.stats.frames_missed += gap if 0 < gap < MAX_COUNTED_GAP else 0
        self._last_delivered = self._timestamp
        return AssembledFrame(buf, self._timestamp, lost, holes)

    def _resync_without_sof(self, flag: int, seq: int) -> bool:
        """While resyncing, a frame whose start-of-frame (and at most max_gap more) was lost can still be
        picked up: its position follows from the last start-of-frame seen, 242 packets per frame."""
        if self._anchor is None:
            return False
        since = self._abs - self._anchor[0]
        pos = since % DEPTH_PACKETS_PER_FRAME
        last = DEPTH_PACKETS_PER_FRAME - 1
        if not 0 < pos <= self.max_gap or flag != (FLAG_DEPTH_EOF if pos == last else FLAG_DEPTH_MOF):
            return False
        self._start_frame(seq)
        self._timestamp = advance_ticks(self._anchor[1], (since // DEPTH_PACKETS_PER_FRAME) * TICKS_PER_FRAME)
        self._pkt = self._lost = pos
        self._hole(0, pos)
        return True

    def _skip(self, count: int, seq: int) -> None:
        """Skip `count` packets at the start of a frame: its start-of-frame (and timestamp) was lost, so the
        timestamp follows the previous frame's, which is exact because the previous frame just ended."""
        if count:
            self._timestamp = advance_ticks(self._timestamp, TICKS_PER_FRAME)
        self._pkt = count
        self._lost = count
        self._seq = seq
        if count:
            self._hole(0, count)

    def _feed_one(self, p) -> AssembledFrame | None:
        n = len(p)
        if n < PACKET_HEADER_SIZE or p[0] != 0x52 or p[1] != 0x42 or (p[3] & 0xF0) != 0x70:
            self.stats.packets_bad += 1
            return None
        self.stats.packets += 1
        flag, seq = p[3], p[5]
        done = None
        # Absolute packet count (from sequence numbers), and the last start-of-frame seen: together they
        # give any packet's position in its frame, even while resyncing.
        if self._last_seq is not None:
            step = (seq - self._last_seq) & 0xFF
            self._abs += step
            self.stats.packets_lost += step - 1 if step else 0
        self._last_seq = seq
        if flag == FLAG_DEPTH_SOF:
            self._anchor = (self._abs, int.from_bytes(p[8:12], "little"))
        if not self._synced:
            if flag == FLAG_DEPTH_SOF:
                self._start_frame(seq)
            elif not self._resync_without_sof(flag, seq):
                return None
        if seq != self._seq:
            gap = (seq - self._seq) & 0xFF
            left = DEPTH_PACKETS_PER_FRAME - self._pkt
            if gap > self.max_gap:
                self._abandon()                       # too many packets lost
                if flag == FLAG_DEPTH_SOF:
                    self._start_frame(seq)
                elif not self._resync_without_sof(flag, seq):
                    return None
            elif gap >= left:
                # The frame's tail is missing and this packet belongs to the next frame.
                self._lost += left
                self._hole(self._pkt, left)
                done = self._finish()
                self._skip(gap - left, seq)
            elif self._pkt == 0:
                self._skip(gap, seq)                  # this frame's start-of-frame was lost
            else:
                self._lost += gap
                self._hole(self._pkt, gap)
                self._pkt += gap
                self._seq = seq
        pkt = self._pkt
        last = DEPTH_PACKETS_PER_FRAME - 1
        expected_flag = FLAG_DEPTH_SOF if pkt == 0 else (FLAG_DEPTH_EOF if pkt == last else FLAG_DEPTH_MOF)
        if flag != expected_flag:
            self._abandon()                           # the packet's flag does not fit its position
            if flag != FLAG_DEPTH_SOF:
                return done
            self._start_frame(seq)
            pkt = 0
        if pkt == 0:
            self._timestamp = int.from_bytes(p[8:12], "little")
        size = DEPTH_LAST_PAYLOAD if pkt == last else DEPTH_PAYLOAD
        got = n - PACKET_HEADER_SIZE
        start = pkt * DEPTH_PAYLOAD
        if got > size:
            self.stats.packets_bad += 1          # longer than the format allows: keep the 0xFF fill
            self._lost += 1
            self._holes.append((start, start + size))
        else:
            self._buf[start:start + got] = p[PACKET_HEADER_SIZE:]
            if got < size:
                self.stats.packets_damaged += 1
                self._lost += 1
                self._holes.append((start + got, start + size))
        self._pkt = pkt + 1
        self._seq = (seq + 1) & 0xFF
        if self._pkt == DEPTH_PACKETS_PER_FRAME:
            return self._finish()
        return done
