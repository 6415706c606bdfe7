"""Builds the wire form of an RGB-D frame (fovea.v1.Frame, frame.proto)
from NumPy arrays or from PNG/JPEG file bytes."""

import numpy as np

from fovea.v1 import frame_pb2


def _raw_image(array, encoding):
    """A raw, tightly packed, little-endian Image from a C-ordered array."""
    height, width = array.shape[:2]
    data = np.ascontiguousarray(array)
    return frame_pb2.Image(
        width=width, height=height, encoding=encoding, is_bigendian=False,
        step=data.strides[0], data=data.tobytes())


def frame_from_numpy(color_rgb: np.ndarray, depth: np.ndarray, fx: float,
                     fy: float, cx: float, cy: float,
                     depth_scale: float = 0.001, frame_id: str = "",
                     stamp_ns: int = 0) -> frame_pb2.Frame:
    """A Frame from a colour and a depth array of the same size.

    color_rgb: (H, W, 3) uint8, RGB order; sent as raw "rgb8".
    depth: (H, W) float32 metres, NaN or 0 = no data, sent as "32FC1"; or
        (H, W) uint16 in `depth_scale` metres per unit (default millimetres),
        0 = no data, sent as "16UC1".
    fx, fy, cx, cy: pinhole intrinsics of the colour camera, pixels; depth
        registered to colour.
    Raises ValueError naming the argument for a wrong shape or dtype.
    """
    color_rgb = np.asarray(color_rgb)
    depth = np.asarray(depth)
    if color_rgb.ndim != 3 or color_rgb.shape[2] != 3:
        raise ValueError(
            f"color_rgb: expected shape (H, W, 3), got {color_rgb.shape}")
    if color_rgb.dtype != np.uint8:
        raise ValueError(f"color_rgb: expected dtype uint8, got {color_rgb.dtype}")
    if depth.ndim != 2:
        raise ValueError(f"depth: expected shape (H, W), got {depth.shape}")
    if depth.shape != color_rgb.shape[:2]:
        raise ValueError(
            f"depth: shape {depth.shape} differs from color_rgb's "
            f"{color_rgb.shape[:2]}")
    if depth.dtype == np.float32:
        depth_image = _raw_image(depth.astype("<f4", copy=False), "32FC1")
    elif depth.dtype == np.uint16:
        depth_image = _raw_image(depth.astype("<u2", copy=False), "16UC1")
    else:
        raise ValueError(
            f"depth: expected dtype float32 (metres) or uint16, got {depth.dtype}")
    return frame_pb2.Frame(
        color=_raw_image(color_rgb, "rgb8"), depth=depth_image,
        intrinsics=frame_pb2.Intrinsics(fx=fx, fy=fy, cx=cx, cy=cy),
        depth_scale=depth_scale, frame_id=frame_id, stamp_ns=stamp_ns)


def frame_from_files(color_bytes: bytes, depth_bytes: bytes, fx: float,
                     fy: float, cx: float, cy: float,
                     depth_scale: float = 0.001, frame_id: str = "",
                     stamp_ns: int = 0) -> frame_pb2.Frame:
    """A Frame from whole PNG/JPEG files, sent as they are (compressed form).

    color_bytes: a PNG or JPEG colour image. depth_bytes: a 16-bit grey PNG
    in `depth_scale` metres per unit. The server reads sizes from the files.
    """
    return frame_pb2.Frame(
        color=frame_pb2.Image(compressed=color_bytes),
        depth=frame_pb2.Image(compressed=depth_bytes),
        intrinsics=frame_pb2.Intrinsics(fx=fx, fy=fy, cx=cx, cy=cy),
        depth_scale=depth_scale, frame_id=frame_id, stamp_ns=stamp_ns)
