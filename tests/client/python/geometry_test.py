"""object_box / object_points / quaternion_to_matrix
(client/python/fovea_client/geometry.py) on hand-made ObjectResults whose
right answers follow from their numbers. Exits 77 (ctest
SKIP_RETURN_CODE) when the generated stubs or numpy cannot be imported."""

import math
import struct
import sys
import unittest

try:
    import numpy as np
    from fovea.v1 import segment_pb2
    from fovea_client import (ObjectBox, object_box, object_points,
                              quaternion_to_matrix)
except ImportError as e:
    print(f"skipped: {e}")
    sys.exit(77)


def yaw_quaternion(deg):
    h = math.radians(deg) / 2
    return segment_pb2.Quaternion(x=0, y=0, z=math.sin(h), w=math.cos(h))


class GeometryTest(unittest.TestCase):
    def test_quaternion_columns_are_the_rotated_axes(self):
        r = quaternion_to_matrix(yaw_quaternion(90))
        np.testing.assert_allclose(r[:, 0], [0, 1, 0], atol=1e-12)
        np.testing.assert_allclose(r[:, 1], [-1, 0, 0], atol=1e-12)
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(
            quaternion_to_matrix(segment_pb2.Quaternion(w=1)), np.eye(3))

    def test_box_arrays_and_corners(self):
        obj = segment_pb2.ObjectResult()
        obj.oriented_box.center.x, obj.oriented_box.center.z = 0.1, 0.9
        obj.oriented_box.orientation.CopyFrom(yaw_quaternion(90))
        obj.oriented_box.size.x = 0.2
        obj.oriented_box.size.y = 0.1
        obj.oriented_box.size.z = 0.05
        obj.support_frame.orientation.w = 1.0
        obj.box_in_support.orientation.w = 1.0
        obj.box_in_support.center.z = 0.025
        obj.height_above_support = 0.05
        obj.footprint_area = 0.02
        box = object_box(obj)
        self.assertIsInstance(box, ObjectBox)
        np.testing.assert_allclose(box.center, [0.1, 0, 0.9])
        np.testing.assert_allclose(box.size, [0.2, 0.1, 0.05])
        self.assertAlmostEqual(box.footprint_area, 0.02)
        corners = box.corners()
        self.assertEqual(corners.shape, (8, 3))
        # Yawed by 90 degrees: the 20 cm length lies along camera y.
        np.testing.assert_allclose(np.ptp(corners, axis=0), [0.1, 0.2, 0.05],
                                   atol=1e-12)
        np.testing.assert_allclose(corners.mean(axis=0), box.center,
                                   atol=1e-12)

    def test_no_box_is_none(self):
        self.assertIsNone(object_box(segment_pb2.ObjectResult()))

    def test_points_xyz_and_indices(self):
        obj = segment_pb2.ObjectResult()
        obj.points.xyz = struct.pack("<6f", 0.1, 0.2, 0.9, -0.1, 0.0, 1.1)
        obj.points.count = 2
        xyz = object_points(obj)
        self.assertEqual(xyz.shape, (2, 3))
        self.assertEqual(xyz.dtype, np.float32)
        np.testing.assert_allclose(xyz[1], [-0.1, 0.0, 1.1], rtol=1e-6)
        obj = segment_pb2.ObjectResult()
        obj.points.indices.extend([641, 642])
        indices = object_points(obj)
        np.testing.assert_array_equal(indices, [641, 642])
        self.assertEqual(indices.dtype, np.uint32)
        self.assertIsNone(object_points(segment_pb2.ObjectResult()))


if __name__ == "__main__":
    unittest.main()
