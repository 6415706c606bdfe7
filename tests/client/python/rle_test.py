"""decode_rle / encode_rle (client/python/fovea_client/rle.py) against
hand-made COCO runs. Exits 77 (ctest SKIP_RETURN_CODE) when the generated
stubs or numpy cannot be imported."""

import sys
import unittest

try:
    import numpy as np
    from fovea.v1 import segment_pb2
    from fovea_client import decode_rle, encode_rle
except ImportError as e:
    print(f"skipped: {e}")
    sys.exit(77)


def rle(height, width, counts):
    return segment_pb2.RleMask(height=height, width=width, counts=counts)


class RleTest(unittest.TestCase):
    def test_runs_go_down_columns_starting_with_zeros(self):
        # 2x3, column-major: col 0 = (0, 1), col 1 = (1, 1), col 2 = (0, 0).
        mask = decode_rle(rle(2, 3, [1, 3, 2]))
        np.testing.assert_array_equal(
            mask, [[False, True, False], [True, True, False]])
        self.assertEqual(mask.dtype, bool)

    def test_leading_zero_run_may_be_empty(self):
        mask = decode_rle(rle(2, 2, [0, 1, 3]))
        np.testing.assert_array_equal(mask, [[True, False], [False, False]])

    def test_encode_matches_hand_made_runs(self):
        mask = np.array([[0, 1, 0], [1, 1, 0]], dtype=np.uint8)
        self.assertEqual(list(encode_rle(mask).counts), [1, 3, 2])
        self.assertEqual(list(encode_rle(np.ones((2, 2))).counts), [0, 4])

    def test_round_trip_of_random_masks(self):
        rng = np.random.default_rng(7)
        for height, width in [(1, 1), (3, 5), (48, 64), (17, 1)]:
            mask = rng.random((height, width)) < 0.3
            encoded = encode_rle(mask)
            self.assertEqual((encoded.height, encoded.width), (height, width))
            self.assertEqual(sum(encoded.counts), height * width)
            np.testing.assert_array_equal(decode_rle(encoded), mask)

    def test_empty_mask(self):
        encoded = encode_rle(np.zeros((0, 4), dtype=bool))
        self.assertEqual(list(encoded.counts), [])
        self.assertEqual(decode_rle(encoded).shape, (0, 4))

    def test_runs_not_covering_the_mask_are_rejected(self):
        with self.assertRaisesRegex(ValueError, "rle.counts: runs cover 5"):
            decode_rle(rle(2, 3, [1, 4]))
        with self.assertRaisesRegex(ValueError, "runs cover 7"):
            decode_rle(rle(2, 3, [1, 4, 2]))

    def test_encode_rejects_a_3d_array(self):
        with self.assertRaisesRegex(ValueError, "mask: expected a 2-D array"):
            encode_rle(np.zeros((2, 2, 3)))


if __name__ == "__main__":
    unittest.main()
