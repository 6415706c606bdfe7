"""client/python/example.py against a live fovea-server: starts the server
on a free loopback port, waits for health SERVING, runs the example on its
synthetic NumPy scene and expects exit 0 with every decoded mask matching
its object's area. Exits 77 (ctest SKIP_RETURN_CODE) when the Python
modules are missing.

    example_test.py --server_binary build/bin/fovea-server \\
        --models_dir models --example client/python/example.py
"""

import argparse
import importlib.util
import os
import struct
import tempfile
import zlib
import subprocess
import sys
import time
import unittest

try:
    import grpc
    import numpy
    from fovea_client import FoveaClient
except ImportError as e:
    print(f"skipped: {e}")
    sys.exit(77)

import server_process  # noqa: E402  (beside this script)

ARGS = None  # set in __main__


def write_png(path, pixels, bit_depth, color_type):
    """A PNG of `pixels` (rows of big-endian samples as bytes), no filter."""
    height = len(pixels)
    width = {(8, 2): 3, (16, 0): 2}[(bit_depth, color_type)]
    width = len(pixels[0]) // width

    def chunk(kind, data):
        body = kind + data
        return (struct.pack(">I", len(data)) + body +
                struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF))

    raw = b"".join(b"\x00" + row for row in pixels)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height,
                                           bit_depth, color_type, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw)))
        f.write(chunk(b"IEND", b""))


class ExampleTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        def is_serving(target):
            # A fresh channel per attempt: one that tried before the server
            # listened may wait out gRPC's reconnect backoff.
            with FoveaClient(target) as client:
                try:
                    return client.health(timeout=1.0) == "SERVING"
                except grpc.RpcError:
                    return False

        cls.server, cls.target = server_process.start_serving(
            [ARGS.server_binary, "--metrics_listen=",
             f"--models_dir={ARGS.models_dir}", "--concurrency=1"],
            is_serving)

    @classmethod
    def tearDownClass(cls):
        server_process.stop(cls.server)

    def test_capabilities_list_cos(self):
        with FoveaClient(self.target) as client:
            capabilities = client.capabilities(timeout=10)
        self.assertIn("32FC1", capabilities.depth_encodings)
        self.assertIn(1, capabilities.segmentation_methods)  # COS

    def test_example_prints_objects_whose_masks_match_their_area(self):
        run = subprocess.run(
            [sys.executable, ARGS.example, "--server", self.target],
            capture_output=True, text=True, timeout=300, env=os.environ)
        sys.stdout.write(run.stdout)
        sys.stderr.write(run.stderr)
        self.assertEqual(run.returncode, 0, run.stderr)
        objects = [line for line in run.stdout.splitlines()
                   if line.startswith("object ")]
        self.assertGreaterEqual(len(objects), 1, run.stdout)
        self.assertNotIn("MISMATCH", run.stdout)
        self.assertIn("support plane", run.stdout)

    def test_example_on_its_own_frame_files(self):
        # The README's first path for a new user: --color C.png --depth D.png.
        spec = importlib.util.spec_from_file_location("example", ARGS.example)
        example = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(example)
        color, depth = example.render_table_scene()
        millimetres = numpy.where(numpy.isfinite(depth),
                                  numpy.round(depth * 1000.0), 0)
        millimetres = millimetres.astype(">u2")
        with tempfile.TemporaryDirectory() as folder:
            c = os.path.join(folder, "color.png")
            d = os.path.join(folder, "depth.png")
            write_png(c, [row.tobytes() for row in color], 8, 2)
            write_png(d, [row.tobytes() for row in millimetres], 16, 0)
            for method in ("COS", "EBS"):
                run = subprocess.run(
                    [sys.executable, ARGS.example, "--server", self.target,
                     "--color", c, "--depth", d, "--method", method],
                    capture_output=True, text=True, timeout=300,
                    env=os.environ)
                sys.stdout.write(run.stdout)
                sys.stderr.write(run.stderr)
                self.assertEqual(run.returncode, 0, run.stderr)
                self.assertNotIn("MISMATCH", run.stdout)
                self.assertTrue(any(line.startswith("object ")
                                    for line in run.stdout.splitlines()),
                                run.stdout)

    def test_track_yields_one_response_per_frame_with_lasting_ids(self):
        spec = importlib.util.spec_from_file_location("example", ARGS.example)
        example = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(example)
        color, depth = example.render_table_scene()
        # Lockstep: each frame only after the last answer, so none is
        # skipped; the same still frame three times.
        answered = []

        def frames():
            for _ in range(3):
                yield color, depth
                while len(answered) < _ + 1:
                    time.sleep(0.01)

        with FoveaClient(self.target) as client:
            for response in client.track(frames(), example.FX, example.FY,
                                         example.CX, example.CY, timeout=120,
                                         request_id="py"):
                answered.append(response)
        self.assertEqual(len(answered), 3)
        first = [o.track_id for o in answered[0].objects]
        self.assertGreaterEqual(len(first), 1)
        self.assertEqual([o.track_id for o in answered[2].objects], first)
        self.assertTrue(answered[2].reused)
        self.assertEqual(answered[2].request_id, "py")

    def test_replica_list_skips_one_that_is_down(self):
        # Port 1 on loopback has no listener: round robin skips it.
        with FoveaClient(f"127.0.0.1:1,{self.target}") as client:
            self.assertEqual(client.health(timeout=10), "SERVING")
            for _ in range(4):
                capabilities = client.capabilities(timeout=10)
                self.assertIn("32FC1", capabilities.depth_encodings)

    def test_scene_hints_go_as_dicts_and_bad_ones_are_named(self):
        # A table 0.75 m below a camera looking 45 degrees down.
        h, w, fx = 120, 160, 130.0
        v, u = numpy.mgrid[0:h, 0:w].astype(numpy.float64)
        ray_y, ray_z = (v - 59.5) / fx, numpy.ones_like(v)
        normal = numpy.array([0.0, -numpy.sqrt(0.5), -numpy.sqrt(0.5)])
        z = 0.75 / -(normal[1] * ray_y + normal[2] * ray_z)
        depth = numpy.where(z > 0, z, numpy.nan).astype(numpy.float32)
        rgb = numpy.full((h, w, 3), 128, numpy.uint8)
        down = {"x": 0.0, "y": numpy.sqrt(0.5), "z": numpy.sqrt(0.5)}
        with FoveaClient(self.target) as client:
            response = client.detect(
                rgb, depth, fx=fx, fy=fx, cx=79.5, cy=59.5, timeout=30,
                scene={"gravity": down, "sensor": "SENSOR_MODEL_KINECT_V1"})
            self.assertLess(response.support_plane.score.tilt_deg, 2.0)
            self.assertAlmostEqual(response.support_plane.d, 0.75, delta=0.01)
            with self.assertRaises(grpc.RpcError) as caught:
                client.detect(rgb, depth, fx=fx, fy=fx, cx=79.5, cy=59.5,
                              timeout=30, scene={"gravity": {"y": 2.0}})
        self.assertEqual(caught.exception.code(),
                         grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("options.scene.gravity", caught.exception.details())

    def test_cover_scene_adds_the_box_without_a_seed(self):
        sys.path.insert(0, os.path.dirname(os.path.abspath(ARGS.example)))
        from example import CX, CY, FX, FY, render_table_scene
        rgb, depth = render_table_scene()
        # A seed on the red box only (the left one, nearer the bottom).
        rows, cols = numpy.nonzero((rgb[..., 0] > 170) & (rgb[..., 1] < 80))
        seed = (int(numpy.median(cols)), int(numpy.median(rows)))

        def objects(**kwargs):
            with FoveaClient(self.target) as client:
                return [m.object for m in client.segment(
                    rgb, depth, FX, FY, CX, CY, seeds=[seed], timeout=60,
                    **kwargs) if m.HasField("object")]

        self.assertEqual(len(objects()), 1)  # seeds given: just theirs
        covered = objects(cover_scene=True)
        self.assertEqual(len(covered), 2)
        self.assertEqual((covered[0].seed.u, covered[0].seed.v), seed)

    def test_bad_frame_is_invalid_argument(self):
        rgb = numpy.zeros((4, 4, 3), numpy.uint8)
        depth = numpy.zeros((4, 4), numpy.float32)
        with FoveaClient(self.target) as client:
            with self.assertRaises(grpc.RpcError) as caught:
                client.detect(rgb, depth, fx=-1, fy=525, cx=2, cy=2, timeout=10)
        self.assertEqual(caught.exception.code(),
                         grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("fx", caught.exception.details())


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--server_binary", required=True)
    parser.add_argument("--models_dir", required=True)
    parser.add_argument("--example", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest)
