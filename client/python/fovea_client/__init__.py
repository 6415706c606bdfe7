"""Python client for Fovea's perception service (fovea.v1.Perception).

Needs the generated stubs (the build's fovea_python_stubs target, in
build/python) on the path, plus grpcio, protobuf and numpy:

    PYTHONPATH=build/python:client/python /usr/bin/python3 ...

    from fovea_client import FoveaClient, decode_rle
    # "127.0.0.1:50051", replicas "10.0.0.5:50051,10.0.0.6:50051" or
    # one DNS name for all of them "dns:///fovea.ns.svc:50051"
    with FoveaClient("127.0.0.1:50051") as client:
        for response in client.segment(rgb, depth_m, 525, 525, 319.5, 239.5):
            if response.HasField("object"):
                mask = decode_rle(response.object.mask)  # (H, W) bool
"""

from fovea_client.channel import channel_target
from fovea_client.client import FoveaClient, detect_options
from fovea_client.frame import frame_from_files, frame_from_numpy
from fovea_client.rle import decode_rle, encode_rle

__all__ = [
    "FoveaClient",
    "channel_target",
    "decode_rle",
    "detect_options",
    "encode_rle",
    "frame_from_files",
    "frame_from_numpy",
]
