"""An object's geometry (segment.proto's ObjectResult) as NumPy arrays."""

from dataclasses import dataclass
from typing import Optional

import numpy as np

from fovea.v1 import segment_pb2


def quaternion_to_matrix(q: segment_pb2.Quaternion) -> np.ndarray:
    """The (3, 3) rotation matrix of a fovea.v1.Quaternion (x, y, z, w):
    its columns are the rotated frame's axes in the camera frame."""
    x, y, z, w = q.x, q.y, q.z, q.w
    n = x * x + y * y + z * z + w * w
    if n == 0.0:
        return np.eye(3)
    s = 2.0 / n
    return np.array([
        [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
        [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
        [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
    ])


def _vector(v) -> np.ndarray:
    return np.array([v.x, v.y, v.z], dtype=np.float64)


@dataclass
class ObjectBox:
    """The box standing on the support that holds an object (metres).

    center, rotation, size: in the camera frame (x right, y down, z
    forward); rotation's columns are the box's axes (x along its length, y
    its width, z up the support normal); size along them, size[0] >=
    size[1]. support_position, support_rotation: the support frame in the
    camera frame (origin on the plane below the box, z up the normal).
    center_in_support, rotation_in_support: the same box in that frame
    (only a yaw about z). A point p in the support frame is
    support_rotation @ p + support_position in the camera frame.
    """
    center: np.ndarray
    rotation: np.ndarray
    size: np.ndarray
    support_position: np.ndarray
    support_rotation: np.ndarray
    center_in_support: np.ndarray
    rotation_in_support: np.ndarray
    height_above_support: float
    footprint_area: float

    def corners(self) -> np.ndarray:
        """The box's 8 corners in the camera frame, (8, 3)."""
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1)
                          for sz in (-1, 1)], dtype=np.float64)
        return self.center + (signs * (self.size / 2)) @ self.rotation.T


def object_box(obj: segment_pb2.ObjectResult) -> Optional[ObjectBox]:
    """An ObjectResult's box as arrays; None when the server sent none
    (fewer than 3 of the mask's pixels had depth)."""
    if not obj.HasField("oriented_box"):
        return None
    box, frame, local = obj.oriented_box, obj.support_frame, obj.box_in_support
    return ObjectBox(
        center=_vector(box.center),
        rotation=quaternion_to_matrix(box.orientation),
        size=_vector(box.size),
        support_position=_vector(frame.position),
        support_rotation=quaternion_to_matrix(frame.orientation),
        center_in_support=_vector(local.center),
        rotation_in_support=quaternion_to_matrix(local.orientation),
        height_above_support=obj.height_above_support,
        footprint_area=obj.footprint_area)


def object_points(obj: segment_pb2.ObjectResult) -> Optional[np.ndarray]:
    """An ObjectResult's points as the request asked: (N, 3) float32 x, y,
    z in metres (camera frame) for FORMAT_XYZ, (N,) uint32 organized
    indices v * width + u for FORMAT_INDICES; None when none came."""
    points = obj.points
    if points.xyz:
        return np.frombuffer(points.xyz, dtype="<f4").reshape(-1, 3)
    if len(points.indices):
        return np.asarray(points.indices, dtype=np.uint32)
    return None
