"""The body parts the per-pixel classifier tells apart (Shotton et al. 2011 style), left and right distinct.

Thirty parts: head, neck, four torso quarters, and per side shoulder, upper arm, elbow, forearm, wrist, hand,
hip, thigh, knee, shin, ankle, foot. Parts around a joint are what the joint proposals (part_proposals.py)
are taken from, so every Kinect v1 limb joint has its own part.
"""
from __future__ import annotations

SIDES = ("Left", "Right")
_SIDE_PARTS = ("shoulder", "upperarm", "elbow", "forearm", "wrist", "hand",
               "hip", "thigh", "knee", "shin", "ankle", "foot")
PARTS: tuple[str, ...] = ("head", "neck", "torso_upper_left", "torso_upper_right", "torso_lower_left",
                          "torso_lower_right") + tuple(f"{p}_{s.lower()}" for s in SIDES for p in _SIDE_PARTS)
PART = {name: i for i, name in enumerate(PARTS)}
BACKGROUND = 255   # label of pixels that are not the person

# Kinect v1 joint -> the part whose centre it is (the centre joints come from the torso frame, not from parts)
JOINT_PART = {"Head": "head", "ShoulderCenter": "neck",
              **{f"{j}{s}": f"{p}_{s.lower()}" for s in SIDES for j, p in (
                  ("Shoulder", "shoulder"), ("Elbow", "elbow"), ("Wrist", "wrist"), ("Hand", "hand"),
                  ("Hip", "hip"), ("Knee", "knee"), ("Ankle", "ankle"), ("Foot", "foot"))}}
