"""frame_from_numpy (client/python/fovea_client/frame.py): raw little-endian
rgb8 / 32FC1 / 16UC1 images with step set, and ValueErrors naming the
argument. Exits 77 (ctest SKIP_RETURN_CODE) when imports fail."""

import sys
import unittest

try:
    import numpy as np
    from fovea_client import frame_from_numpy
except ImportError as e:
    print(f"skipped: {e}")
    sys.exit(77)


class FrameFromNumpyTest(unittest.TestCase):
    def test_float_depth_is_32fc1_little_endian_with_step(self):
        color = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
        depth = np.array([[0.5, np.nan, 0], [1, 2, 3]], dtype=np.float32)
        frame = frame_from_numpy(color[:, :, :], depth, 525, 526, 1.5, 0.5)
        self.assertEqual((frame.color.width, frame.color.height), (3, 2))
        self.assertEqual((frame.color.encoding, frame.color.step), ("rgb8", 9))
        self.assertEqual(frame.color.data, color.tobytes())
        self.assertEqual((frame.depth.encoding, frame.depth.step), ("32FC1", 12))
        self.assertFalse(frame.depth.is_bigendian)
        decoded = np.frombuffer(frame.depth.data, dtype="<f4").reshape(2, 3)
        np.testing.assert_array_equal(decoded, depth)
        self.assertEqual(frame.intrinsics.fy, 526)

    def test_non_contiguous_views_are_packed(self):
        color = np.zeros((4, 6, 3), dtype=np.uint8)[::2, ::2]
        depth = np.ones((4, 6), dtype=np.float32)[::2, ::2]
        frame = frame_from_numpy(color, depth, 1, 1, 1, 1)
        self.assertEqual(frame.color.step, 9)
        self.assertEqual(len(frame.depth.data), 2 * 3 * 4)

    def test_uint16_depth_is_16uc1_with_scale(self):
        depth = np.array([[1000, 0]], dtype=np.uint16)
        frame = frame_from_numpy(np.zeros((1, 2, 3), np.uint8), depth, 1, 1, 0, 0)
        self.assertEqual((frame.depth.encoding, frame.depth.step), ("16UC1", 4))
        self.assertEqual(frame.depth.data, b"\xe8\x03\x00\x00")
        self.assertAlmostEqual(frame.depth_scale, 0.001)

    def test_wrong_shapes_and_dtypes_name_the_argument(self):
        rgb = np.zeros((2, 3, 3), np.uint8)
        depth = np.zeros((2, 3), np.float32)
        cases = [
            (np.zeros((2, 3), np.uint8), depth, "color_rgb: expected shape"),
            (rgb.astype(np.float32), depth, "color_rgb: expected dtype uint8"),
            (rgb, np.zeros((2, 3, 1), np.float32), "depth: expected shape"),
            (rgb, np.zeros((3, 2), np.float32), "depth: shape"),
            (rgb, depth.astype(np.float64), "depth: expected dtype"),
        ]
        for color, d, message in cases:
            with self.assertRaisesRegex(ValueError, message):
                frame_from_numpy(color, d, 1, 1, 1, 1)


if __name__ == "__main__":
    unittest.main()
