"""A simple articulated body and a pinhole camera: the 33 MediaPipe landmarks of a posed person.

Segment lengths are shares of standing height (Drillis & Contini 1966, as tabulated in Winter,
Biomechanics and Motor Control of Human Movement, 4th ed., 2009, fig. 4.1): hip joint 0.530,
knee 0.285, ankle 0.039, shoulder 0.818, head 0.936 (eyes). The body stands on the floor (y up,
metres); a camera projects it as MediaPipe reports it (x, y in image fractions, z in the same scale
as x relative to the hips, visibility). Used by the sequence generator (:mod:`kiosk.core.tug.synth`)
only; pure numpy.
"""

from __future__ import annotations

import math

import numpy as np

from basis import record
from kiosk.core.tug.landmarks import INDEX

UP = np.array([0.0, 1.0, 0.0])


@record
class Build:
    """One person's sizes, in metres."""

    height: float
    hip_width: float
    shoulder_width: float
    thigh: float
    shank: float
    torso: float

    @classmethod
    def of_height(cls, height: float, stocky: float = 1.0) -> Build:
        return cls(
            height=height,
            hip_width=0.10 * height * stocky,
            shoulder_width=0.23 * height * stocky,
            thigh=0.245 * height,
            shank=0.246 * height,
            torso=0.288 * height,
        )


@record
class Pose:
    """Where the body is: hip midpoint (x, z on the floor, y height), facing (radians, 0 = +x),
    trunk lean forward (radians), the ankles' positions (world), arm swing (radians) and whether the
    hands are held forward on a walking aid."""

    hips: np.ndarray
    facing: float
    lean: float
    ankles: tuple[np.ndarray, np.ndarray]
    swing: float = 0.0
    aid: bool = False


def axes(facing: float) -> tuple[np.ndarray, np.ndarray]:
    """(forward, left) unit vectors on the floor for a body facing ``facing``."""
    cos, sin = math.cos(facing), math.sin(facing)
    return np.array([cos, 0.0, sin]), np.array([sin, 0.0, -cos])  # left = UP x forward


def skeleton(build: Build, pose: Pose) -> np.ndarray:
    """The 33 landmarks' world positions (33 x 3) in MediaPipe's order."""
    h = build.height
    forward, left = axes(pose.facing)
    trunk = UP * math.cos(pose.lean) + forward * math.sin(pose.lean)
    points = np.zeros((33, 3))
    hips = pose.hips
    shoulders = hips + trunk * build.torso
    head = shoulders + trunk * 0.118 * h
    side = {"left": left, "right": -left}
    for name, way in side.items():
        hip = hips + way * build.hip_width / 2
        points[INDEX[f"{name}_hip"]] = hip
        ankle = pose.ankles[0 if name == "left" else 1]
        knee = _knee(hip, ankle, build.thigh, build.shank, forward)
        points[INDEX[f"{name}_knee"]] = knee
        points[INDEX[f"{name}_ankle"]] = ankle
        points[INDEX[f"{name}_heel"]] = ankle - forward * 0.04 * h - UP * 0.025 * h
        points[INDEX[f"{name}_foot_index"]] = ankle + forward * 0.11 * h - UP * 0.03 * h
        shoulder = shoulders + way * build.shoulder_width / 2
        points[INDEX[f"{name}_shoulder"]] = shoulder
        swing = (pose.swing if name == "left" else -pose.swing) if not pose.aid else 0.5
        bend = 0.2 if not pose.aid else 0.9
        hang = -trunk
        elbow = shoulder + 0.186 * h * (hang * math.cos(swing) + forward * math.sin(swing))
        wrist = elbow + 0.146 * h * (hang * math.cos(swing + bend) + forward * math.sin(swing + bend))
        points[INDEX[f"{name}_elbow"]] = elbow
        points[INDEX[f"{name}_wrist"]] = wrist
        hand = (wrist - elbow) / np.linalg.norm(wrist - elbow)
        points[INDEX[f"{name}_pinky"]] = wrist + hand * 0.07 * h - way * 0.02 * h
        points[INDEX[f"{name}_index"]] = wrist + hand * 0.08 * h + way * 0.01 * h
        points[INDEX[f"{name}_thumb"]] = wrist + hand * 0.04 * h + way * 0.025 * h
        points[INDEX[f"{name}_eye_inner"]] = head + forward * 0.055 * h + way * 0.012 * h
        points[INDEX[f"{name}_eye"]] = head + forward * 0.052 * h + way * 0.02 * h
        points[INDEX[f"{name}_eye_outer"]] = head + forward * 0.048 * h + way * 0.028 * h
        points[INDEX[f"{name}_ear"]] = head + way * 0.045 * h
        points[INDEX[f"mouth_{name}"]] = head + forward * 0.05 * h + way * 0.015 * h - trunk * 0.045 * h
    points[INDEX["nose"]] = head + forward * 0.065 * h - trunk * 0.02 * h
    return points


def _knee(hip: np.ndarray, ankle: np.ndarray, thigh: float, shank: float, forward: np.ndarray) -> np.ndarray:
    reach = ankle - hip
    distance = float(np.linalg.norm(reach))
    along = reach / distance
    distance = min(distance, (thigh + shank) * 0.9999)
    cos_hip = (thigh**2 + distance**2 - shank**2) / (2 * thigh * distance)
    bend = forward - np.dot(forward, along) * along
    size = float(np.linalg.norm(bend))
    bend = bend / size if size > 1e-6 else UP
    return hip + thigh * (cos_hip * along + math.sqrt(max(0.0, 1 - cos_hip**2)) * bend)


@record
class Camera:
    """A pinhole camera at ``position`` looking along ``yaw`` (radians on the floor) tipped by
    ``pitch`` (radians, positive down), ``fov`` the horizontal field of view (radians)."""

    position: np.ndarray
    yaw: float
    pitch: float
    fov: float
    width: int
    height: int

    def project(self, points: np.ndarray) -> np.ndarray:
        """(33 x 3) image x, y as fractions and MediaPipe's z (hips' depth 0, scaled as x)."""
        look = np.array(
            [
                math.cos(self.yaw) * math.cos(self.pitch),
                -math.sin(self.pitch),
                math.sin(self.yaw) * math.cos(self.pitch),
            ]
        )
        right = np.array([-look[2], 0.0, look[0]])  # look x UP
        right /= np.linalg.norm(right)
        up = np.array(
            [
                right[1] * look[2] - right[2] * look[1],
                right[2] * look[0] - right[0] * look[2],
                right[0] * look[1] - right[1] * look[0],
            ]
        )
        rel = points - self.position
        xc, yc, zc = rel @ right, rel @ up, rel @ look
        focal = self.width / (2 * math.tan(self.fov / 2))
        u = self.width / 2 + focal * xc / zc
        v = self.height / 2 - focal * yc / zc
        hips = (zc[INDEX["left_hip"]] + zc[INDEX["right_hip"]]) / 2
        z = (zc - hips) * focal / (hips * self.width)
        return np.stack([u / self.width, v / self.height, z], axis=1)

    def depth(self, points: np.ndarray) -> np.ndarray:
        """How far along the view each point is (metres)."""
        look = np.array([math.cos(self.yaw), 0.0, math.sin(self.yaw)])
        return (points - self.position) @ look
