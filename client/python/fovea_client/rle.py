"""COCO run-length encoding of binary masks (segment.proto RleMask).

Run lengths go over the mask in column-major order (down the first column,
then the next), alternating zeros and ones, starting with a run of zeros
that may have length 0. The same format as client/rle.h.
"""

import numpy as np

from fovea.v1 import segment_pb2


def decode_rle(rle: segment_pb2.RleMask) -> np.ndarray:
    """Decodes an RleMask into a boolean array of shape (height, width).

    Raises ValueError when the runs do not cover height * width pixels
    exactly.
    """
    height, width = int(rle.height), int(rle.width)
    counts = np.asarray(rle.counts, dtype=np.int64)
    total = height * width
    covered = int(counts.sum()) if counts.size else 0
    if covered != total:
        raise ValueError(
            f"rle.counts: runs cover {covered} pixels, mask is "
            f"{height}x{width} = {total}")
    # Run i holds value i % 2: repeat each run's value by its length.
    values = (np.arange(counts.size) % 2).astype(bool)
    flat = np.repeat(values, counts)
    return flat.reshape((width, height)).T.copy()


def encode_rle(mask: np.ndarray) -> segment_pb2.RleMask:
    """Encodes a 2-D mask (any dtype; non-zero is inside) as an RleMask.

    The inverse of decode_rle. Raises ValueError for an array that is not
    2-D.
    """
    mask = np.asarray(mask)
    if mask.ndim != 2:
        raise ValueError(f"mask: expected a 2-D array, got shape {mask.shape}")
    height, width = mask.shape
    rle = segment_pb2.RleMask(height=height, width=width)
    if mask.size == 0:
        return rle
    flat = (mask.T.reshape(-1) != 0).astype(np.int8)
    # Positions where the value changes, with a leading change from 0.
    changes = np.flatnonzero(np.diff(np.concatenate(([0], flat))))
    bounds = np.concatenate(([0], changes, [flat.size]))
    rle.counts.extend(int(n) for n in np.diff(bounds))
    return rle
