#!/usr/bin/python3
"""Sends one RGB-D frame to a Fovea server, then prints Detect's attention
points and each Segment object as it arrives, decoding every mask.

    PYTHONPATH=build/python:client/python /usr/bin/python3 \\
        client/python/example.py --server 127.0.0.1:50051 \\
        [--color C.png --depth D_mm.png] [--method COS|EBS] [--max_objects N]

Without --color/--depth the frame is a synthetic table scene made with
NumPy (render_table_scene). Exits 1 when a decoded mask's area differs from
the object's `area` or Segment returns no object, 2 when a call fails.
"""

import argparse
import sys

import grpc
import numpy as np

from fovea_client import FoveaClient, decode_rle, frame_from_files, object_box
from fovea.v1 import detect_pb2, segment_pb2

# Intrinsics of a 640x480 Kinect-like camera, pixels.
FX, FY, CX, CY = 525.0, 525.0, 319.5, 239.5


def render_table_scene(width=640, height=480, camera_height_m=0.8,
                       pitch_deg=50.0, boxes=None, seed=0):
    """A camera looking down at an endless table with boxes on it.

    World frame: z up, the table is z = 0, the camera sits at
    (0, 0, camera_height_m) and looks along +y, pitched down by pitch_deg.
    boxes: (x0, x1, y0, y1, height, rgb) in metres, axis-aligned on the
    table. Returns colour (H, W, 3) uint8 RGB and depth (H, W) float32
    metres along the optical axis (NaN where a ray misses everything).
    """
    if boxes is None:
        boxes = [(-0.20, -0.05, 0.85, 1.00, 0.12, (200, 40, 40)),
                 (0.06, 0.18, 0.80, 0.92, 0.08, (40, 60, 200))]
    pitch = np.radians(pitch_deg)
    # Camera axes in the world: x right, y down in the image, z forward.
    axes = np.array([[1.0, 0.0, 0.0],
                     [0.0, -np.sin(pitch), -np.cos(pitch)],
                     [0.0, np.cos(pitch), -np.sin(pitch)]]).T
    u, v = np.meshgrid(np.arange(width), np.arange(height))
    rays = np.stack([(u - CX) / FX, (v - CY) / FY, np.ones(u.shape)], axis=-1)
    d = rays @ axes.T  # world direction per pixel; camera depth = t
    origin = np.array([0.0, 0.0, camera_height_m])

    with np.errstate(divide="ignore", invalid="ignore"):
        depth = np.where(d[..., 2] < 0, -origin[2] / d[..., 2], np.inf)
        color = np.empty((height, width, 3))
        color[:] = (150, 120, 90)  # wood
        for x0, x1, y0, y1, box_h, rgb in boxes:
            low, high = np.array([x0, y0, 0.0]), np.array([x1, y1, box_h])
            t0, t1 = (low - origin) / d, (high - origin) / d
            near = np.nanmax(np.minimum(t0, t1), axis=-1)
            far = np.nanmin(np.maximum(t0, t1), axis=-1)
            hit = (near <= far) & (near > 0) & (near < depth)
            depth[hit] = near[hit]
            color[hit] = rgb
    rng = np.random.default_rng(seed)
    color = np.clip(color + rng.normal(0, 4, color.shape), 0, 255).astype(np.uint8)
    depth[~np.isfinite(depth) | (depth > 4.0)] = np.nan
    depth = (depth + rng.normal(0, 0.0005, depth.shape)).astype(np.float32)
    return color, depth


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--server", default="127.0.0.1:50051",
                        help="HOST:PORT, replicas IP:PORT,IP:PORT,... or "
                        "dns:///NAME:PORT")
    parser.add_argument("--color", help="PNG/JPEG colour image")
    parser.add_argument("--depth", help="16-bit PNG depth, millimetres")
    parser.add_argument("--method", default="COS", choices=["COS", "EBS"])
    parser.add_argument("--max_objects", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds")
    args = parser.parse_args(argv)
    if bool(args.color) != bool(args.depth):
        parser.error("--color and --depth go together")

    if args.color:
        with open(args.color, "rb") as c, open(args.depth, "rb") as d:
            frame = frame_from_files(c.read(), d.read(), FX, FY, CX, CY)
        height = width = None  # read by the server from the files
    else:
        color, depth = render_table_scene()
        height, width = depth.shape
        print(f"synthetic scene {width}x{height}, "
              f"{np.count_nonzero(np.isfinite(depth))} pixels with depth")

    mismatches = 0
    objects = 0
    try:
        with FoveaClient(args.server) as client:
            print("health:", client.health())
            if args.color:
                detect = client.detect_request(
                    detect_pb2.DetectRequest(frame=frame), timeout=args.timeout)
                stream = client.segment_request(
                    segment_pb2.SegmentRequest(
                        frame=frame,
                        # The contract's enum values carry their prefix.
                        method=segment_pb2.SegmentationMethod.Value(
                            "SEGMENTATION_METHOD_" + args.method),
                        max_objects=args.max_objects),
                    timeout=args.timeout)
            else:
                detect = client.detect(color, depth, FX, FY, CX, CY,
                                       timeout=args.timeout)
                stream = client.segment(color, depth, FX, FY, CX, CY,
                                        method=args.method,
                                        max_objects=args.max_objects,
                                        timeout=args.timeout)
            n = detect.support_plane.normal
            print(f"detect: {len(detect.points)} attention points, support "
                  f"plane n=({n.x:.3f}, {n.y:.3f}, {n.z:.3f}) "
                  f"d={detect.support_plane.d:.3f}")
            for p in detect.points:
                print(f"  point {p.rank}: ({p.u}, {p.v}) saliency {p.saliency:.3f}")

            for response in stream:
                if response.attention_points:
                    print(f"segment: {len(response.attention_points)} seeds")
                if response.HasField("object"):
                    objects += 1
                    o = response.object
                    mask = decode_rle(o.mask)
                    area = int(np.count_nonzero(mask))
                    ok = area == o.area and (width is None or
                                             mask.shape == (height, width))
                    mismatches += not ok
                    b, c = o.box, o.centroid
                    print(f"object {o.index}: area {o.area} (decoded {area}"
                          f"{'' if ok else ', MISMATCH'}), box {b.u},{b.v} "
                          f"{b.width}x{b.height}, centroid ({c.x:.3f}, "
                          f"{c.y:.3f}, {c.z:.3f}) m, score {o.score:.2f}, "
                          f"{o.seconds_since_request:.3f} s")
                    box = object_box(o)
                    if box is not None:
                        yaw = np.degrees(np.arctan2(
                            box.rotation_in_support[1, 0],
                            box.rotation_in_support[0, 0]))
                        print(f"  box on the support: {box.size[0]:.3f} x "
                              f"{box.size[1]:.3f} x {box.size[2]:.3f} m, "
                              f"yaw {yaw:.0f} deg, top "
                              f"{box.height_above_support:.3f} m above it")
                if response.last:
                    s = response.summary
                    print(f"done: {s.object_count} objects, stop "
                          f"{segment_pb2.StopReason.Name(s.stop_reason)}, "
                          f"coverage {s.scene_coverage:.2f}, "
                          f"{s.seconds_total:.3f} s")
    except grpc.RpcError as e:
        print(f"error: {e.code().name}: {e.details()}", file=sys.stderr)
        return 2
    if objects == 0:
        print("error: Segment returned no object", file=sys.stderr)
        return 1
    if mismatches:
        print(f"error: {mismatches} masks disagree with their area",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
