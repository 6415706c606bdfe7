"""Python client for Fovea's perception service (fovea.v1.Perception).

Install it (the stubs are generated as it installs) into a venv that sees
Debian's grpcio, protobuf and numpy:

    /usr/bin/python3 -m venv --system-site-packages .venv
    .venv/bin/pip install ./client/python

or, from a build tree, put the generated stubs (the fovea_python_stubs
target, in build/python) on the path:

    PYTHONPATH=build/python:client/python /usr/bin/python3 ...

    from fovea_client import FoveaClient, decode_rle
    # "127.0.0.1:50051", replicas "10.0.0.5:50051,10.0.0.6:50051" or
    # one DNS name for all of them "dns:///fovea.ns.svc:50051"
    with FoveaClient("127.0.0.1:50051") as client:
        for response in client.segment(rgb, depth_m, 525, 525, 319.5, 239.5):
            if response.HasField("object"):
                mask = decode_rle(response.object.mask)  # (H, W) bool
                box = object_box(response.object)  # arrays, metres
"""

from fovea_client.channel import channel_target
from fovea_client.client import FoveaClient, detect_options
from fovea_client.frame import frame_from_files, frame_from_numpy
from fovea_client.geometry import (ObjectBox, object_box, object_points,
                                   quaternion_to_matrix)
from fovea_client.rle import decode_rle, encode_rle

__all__ = [
    "FoveaClient",
    "ObjectBox",
    "channel_target",
    "decode_rle",
    "detect_options",
    "encode_rle",
    "frame_from_files",
    "frame_from_numpy",
    "object_box",
    "object_points",
    "quaternion_to_matrix",
]
