"""Arms that reach to places on and around the body, for the body-part forest's training poses.

Real actions put the hands over the torso and face (crossed arms, an arm curl's hand at its shoulder, a
basketball shot's hands before the face, hands on hips, pushes and catches in front of the chest), where the
forest must tell a forearm from the chest behind it by a few centimetres of depth. Mocap clips and random arm
swings rarely put them there: on the real-depth benchmark the forearms of hands held over the torso or head
were 41 degrees off the Kinect SDK's, against 12 elsewhere. Each reaching arm picks a target (one of TARGETS,
in the pose's own body frame and scaled by its torso), solves shoulder-elbow-wrist as two bones with its own
bone lengths, and swivels the elbow about the shoulder-wrist line to a natural side (down and out, sometimes
forward or up), with random spread.
"""
from __future__ import annotations

import numpy as np

from ..core.quat import normalize

TORSO = 0.33   # hips-to-neck length of the CMU skeleton, in metres: the targets below are for this torso

# target -> (centre, lateral range, up range, forward range), metres for TORSO; centres are pose points
# ("shoulder.o" the other side's shoulder, "hip.s" this side's hip)
TARGETS = {
    "chest_across": ("across", (-0.06, 0.06), (-0.16, 0.02), (0.12, 0.22)),   # crossed arms, hand to shoulder
    "belly": ("belly", (-0.16, 0.16), (-0.08, 0.08), (0.13, 0.24)),
    "own_shoulder": ("shoulder.s", (-0.08, 0.04), (-0.06, 0.10), (0.08, 0.18)),   # arm curl
    "face": ("head", (-0.09, 0.09), (-0.14, 0.05), (0.10, 0.22)),
    "front": ("chest", (-0.22, 0.22), (-0.22, 0.30), (0.25, 0.60)),   # push, catch, box, arms to the sensor
    "overhead": ("head", (-0.25, 0.25), (0.10, 0.40), (-0.05, 0.20)),
    "hip": ("hip.s", (0.04, 0.12), (0.00, 0.10), (-0.04, 0.06)),   # hands on hips
}
WEIGHTS = np.array([0.22, 0.14, 0.16, 0.14, 0.18, 0.08, 0.08])


def _unit(v):
    return normalize(v, 1e-9)


def body_axes(p: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lateral toward the performer's left, up, forward) unit vectors of a pose's torso."""
    up = _unit(p["neck"] - p["hips"])
    lat = p["shoulder.L"] - p["shoulder.R"]
    lat = _unit(lat - (lat @ up) * up)
    fwd = np.cross(lat, up)
    toes = (p["toe.L"] + p["toe.R"]) / 2 - (p["ankle.L"] + p["ankle.R"]) / 2
    if fwd @ toes < 0:   # the feet point forward, whichever handedness the source uses
        fwd = -fwd
    return lat, up, fwd


def _centre(p: dict, name: str, s: str) -> np.ndarray:
    o = "R" if s == "L" else "L"
    if name == "across":
        return p[f"shoulder.{o}"]
    if name == "belly":
        return (p["hips"] + p["chest"]) / 2
    if name.endswith(".s"):
        return p[f"{name[:-2]}.{s}"]
    return p[name]


def reach_target(p: dict, s: str, rng) -> np.ndarray:
    """A random place for arm `s` ("L" or "R") to reach to, in the pose's coordinates."""
    lat, up, fwd = body_axes(p)
    scale = np.linalg.norm(p["neck"] - p["hips"]) / TORSO
    name = list(TARGETS)[rng.choice(len(TARGETS), p=WEIGHTS / WEIGHTS.sum())]
    centre, lr, ur, fr = TARGETS[name]
    out = lat if s == "L" else -lat   # lateral ranges are outward for this arm
    off = rng.uniform(*lr) * out + rng.uniform(*ur) * up + rng.uniform(*fr) * fwd
    return _centre(p, centre, s) + scale * off


def reach_arm(p: dict, s: str, target: np.ndarray, rng) -> dict:
    """Arm `s` of pose `p` with its hand at `target` (or as near as its bones reach), bone lengths kept."""
    p = dict(p)
    a, b, c, d = (p[f"{k}.{s}"] for k in ("shoulder", "elbow", "wrist", "hand"))
    l1, l2, l3 = np.linalg.norm(b - a), np.linalg.norm(c - b), np.linalg.norm(d - c)
    lat, up, fwd = body_axes(p)
    out = lat if s == "L" else -lat
    # the hand points on from the forearm, roughly away from the shoulder
    hand_dir = _unit(_unit(target - a) + 0.5 * rng.normal(size=3))
    wrist = target - hand_dir * l3
    v = wrist - a
    dist = float(np.linalg.norm(v))
    u = v / max(dist, 1e-9)
    dist = float(np.clip(dist, abs(l1 - l2) + 1e-3, l1 + l2 - 1e-6))
    x = (dist * dist + l1 * l1 - l2 * l2) / (2 * dist)
    r = np.sqrt(max(l1 * l1 - x * x, 0.0))
    pref = -up + rng.uniform(0.2, 1.0) * out + rng.uniform(-0.3, 0.8) * fwd + 0.3 * rng.normal(size=3)
    side = pref - (pref @ u) * u   # the elbow's swivel: toward the preferred side of the shoulder-wrist line
    if np.linalg.norm(side) < 1e-6:
        side = np.cross(u, fwd)
    elbow = a + u * x + r * _unit(side)
    wrist = elbow + _unit(a + u * dist - elbow) * l2
    p[f"elbow.{s}"], p[f"wrist.{s}"] = elbow, wrist
    p[f"hand.{s}"] = wrist + _unit(_unit(wrist - elbow) + 0.8 * hand_dir) * l3
    return p


def reaching(p: dict, rng, chance: float = 0.8) -> dict:
    """Each arm of pose `p` (p `chance`) reaching to a random target on or around the body."""
    for s in ("L", "R"):
        if rng.random() < chance:
            p = reach_arm(p, s, reach_target(p, s, rng), rng)
    return p


# two-handed grips: place -> (centre, lateral range (toward the performer's left), up range, forward range),
# metres for TORSO. A bat or racket held at one shoulder (the far arm crosses the chest), a ball or club held
# before the belly or the chest, raised to throw or shoot, or overhead
GRIPS = {
    "shoulder": ("shoulder.s", (-0.10, 0.06), (-0.06, 0.28), (0.06, 0.30)),
    "low": ("belly", (-0.16, 0.16), (-0.28, 0.06), (0.16, 0.45)),
    "high": ("chest", (-0.20, 0.20), (0.00, 0.36), (0.18, 0.50)),
    "overhead": ("head", (-0.16, 0.16), (0.08, 0.34), (-0.05, 0.22)),
}
GRIP_WEIGHTS = np.array([0.45, 0.25, 0.2, 0.1])
GRIP_SPREAD = (0.0, 0.10)   # metres for TORSO between the two hands (a bat's hands stack; a ball's face)


def gripping(p: dict, rng) -> dict:
    """Both arms of pose `p` holding one thing together: the hands a few centimetres apart at a random
    place before the body (sim/reach_poses.GRIPS), bone lengths kept."""
    lat, up, fwd = body_axes(p)
    scale = np.linalg.norm(p["neck"] - p["hips"]) / TORSO
    name = list(GRIPS)[rng.choice(len(GRIPS), p=GRIP_WEIGHTS / GRIP_WEIGHTS.sum())]
    centre, lr, ur, fr = GRIPS[name]
    g = "L" if rng.random() < 0.5 else "R"
    out = lat if g == "L" else -lat   # at one shoulder, lateral ranges are outward from it
    target = _centre(p, centre, g) + scale * (rng.uniform(*lr) * (out if centre == "shoulder.s" else lat)
                                              + rng.uniform(*ur) * up + rng.uniform(*fr) * fwd)
    handle = _unit(rng.normal(size=3))
    half = 0.5 * scale * rng.uniform(*GRIP_SPREAD) * handle
    p = reach_arm(p, "L", target + half, rng)
    return reach_arm(p, "R", target - half, rng)
