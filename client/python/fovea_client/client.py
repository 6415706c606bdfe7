"""A small blocking client for fovea.v1.Perception (perception.proto)."""

from typing import Any, Iterable, Iterator, Optional, Sequence, Tuple

import grpc
import numpy as np

from fovea.health.v1 import health_pb2
from fovea.v1 import (detect_pb2, perception_pb2, perception_pb2_grpc,
                      segment_pb2, track_pb2)

from fovea_client.channel import channel_options, channel_target
from fovea_client.frame import frame_from_numpy

_HEALTH_CHECK = "/grpc.health.v1.Health/Check"
# The gRPC default is 4 MiB; a 640x480 frame with float depth is ~2.2 MB,
# larger frames need more. The server's own limit is in GetCapabilities.
_MAX_MESSAGE_BYTES = 64 * 1024 * 1024


def _enum_prefix(enum_descriptor) -> str:
    """SALIENCY_OPERATOR_ for SaliencyOperator (proto/enum_names.h)."""
    name = enum_descriptor.name
    out = []
    for i, c in enumerate(name):
        if i > 0 and c.isupper() and not name[i - 1].isupper():
            out.append("_")
        out.append(c.upper())
    return "".join(out) + "_"


def _enum_value(enum_descriptor, value):
    """An enum value given as a number, its full name or its short name
    ("msr", "MSR" or "EXTRACTION_MSR"); ValueError naming the known ones
    otherwise."""
    if not isinstance(value, str):
        return value
    by_name = enum_descriptor.values_by_name
    for candidate in (value.upper(), _enum_prefix(enum_descriptor) + value.upper()):
        if candidate in by_name:
            return by_name[candidate].number
    known = ", ".join(v.name[len(_enum_prefix(enum_descriptor)):].lower()
                      for v in enum_descriptor.values if v.number != 0)
    raise ValueError(f"{enum_descriptor.name}: unknown value {value!r} "
                     f"(known: {known})")


def _with_enum_values(descriptor, fields: dict) -> dict:
    """`fields` with enum names turned into numbers, nested dicts too."""
    out = {}
    for key, value in fields.items():
        field = descriptor.fields_by_name.get(key)
        if field is None:
            raise ValueError(f"{descriptor.name} has no field {key!r}")
        if field.enum_type is not None:
            if isinstance(value, (list, tuple)):
                value = [_enum_value(field.enum_type, v) for v in value]
            else:
                value = _enum_value(field.enum_type, value)
        elif field.message_type is not None and isinstance(value, dict):
            value = _with_enum_values(field.message_type, value)
        out[key] = value
    return out


def detect_options(**options: Any) -> detect_pb2.DetectOptions:
    """DetectOptions (detect.proto) from keyword arguments.

    Fields are named as in the proto: max_points=5, extraction="msr",
    pyramid="simple", split_at_surface_edges=False, ... Enum values may be
    given by their short name (any case, without the enum's prefix) or
    their full one ("EXTRACTION_MSR"). `saliency` may be a list of operator names ("rso", "ph")
    or of (name, weight) pairs. Messages may be dicts, e.g. what the robot
    knows of the scene: scene={"gravity": {"x": 0, "y": 0.7, "z": 0.7},
    "sensor": "SENSOR_MODEL_ACTIVE_STEREO", "workspace": {"max_depth_m":
    2.0}}. Raises ValueError for an unknown field.
    """
    saliency = options.pop("saliency", None)
    message = detect_pb2.DetectOptions(
        **_with_enum_values(detect_pb2.DetectOptions.DESCRIPTOR, options))
    operators = detect_pb2.SaliencyOperator.DESCRIPTOR
    for entry in saliency or ():
        name, weight = (entry, 0.0) if isinstance(entry, str) else entry
        message.saliency.add(op=_enum_value(operators, name), weight=weight)
    return message


def _points_options(object_points: Optional[str],
                    max_points: int) -> segment_pb2.ObjectPointsOptions:
    """ObjectPointsOptions from "xyz", "indices" or None."""
    formats = {None: "FORMAT_UNSPECIFIED", "xyz": "FORMAT_XYZ",
               "indices": "FORMAT_INDICES"}
    if object_points not in formats:
        raise ValueError(f"object_points: {object_points!r} is not 'xyz', "
                         "'indices' or None")
    return segment_pb2.ObjectPointsOptions(format=formats[object_points],
                                           max_points=max_points)


class FoveaClient:
    """Channels to a Fovea server or its replicas.

    FoveaClient("127.0.0.1:50051"), FoveaClient("10.0.0.5:50051,
    10.0.0.6:50051") or FoveaClient("dns:///fovea.ns.svc:50051") (see
    fovea_client.channel): calls go round robin to the replicas that report
    SERVING and are retried on UNAVAILABLE (up to `max_attempts` in all);
    health() asks the next reachable replica, NOT_SERVING or not. Raises
    ValueError for a bad `target`. Calls raise grpc.RpcError on failure
    (e.code(), e.details()); the server names the offending field in
    INVALID_ARGUMENT details. `timeout` arguments are seconds (None = no
    deadline). With `channel`, every call goes through it as it is.
    """

    def __init__(self, target: str, channel: Optional[grpc.Channel] = None,
                 max_attempts: int = 4, tls_ca: Optional[bytes] = None,
                 tls_cert: Optional[bytes] = None,
                 tls_key: Optional[bytes] = None) -> None:
        """tls_ca: PEM bytes of the CAs to trust; given, the channel uses
        TLS. tls_cert, tls_key: PEM bytes of a client certificate and its
        key, for a server that requires one (mutual TLS)."""
        if channel is not None:
            self._channel = self._health_channel = channel
        else:
            target = channel_target(target)
            if (tls_cert is None) != (tls_key is None):
                raise ValueError("tls_cert, tls_key: give both or neither")
            if tls_cert is not None and tls_ca is None:
                raise ValueError("tls_ca: needed with a client certificate")

            def make(options):
                if tls_ca is None:
                    return grpc.insecure_channel(target, options=options)
                credentials = grpc.ssl_channel_credentials(
                    root_certificates=tls_ca, private_key=tls_key,
                    certificate_chain=tls_cert)
                return grpc.secure_channel(target, credentials,
                                           options=options)

            self._channel = make(channel_options(_MAX_MESSAGE_BYTES,
                                                 max_attempts))
            self._health_channel = make(channel_options(_MAX_MESSAGE_BYTES,
                                                        balanced=False))
        self._stub = perception_pb2_grpc.PerceptionStub(self._channel)
        self._health = self._health_channel.unary_unary(
            _HEALTH_CHECK,
            request_serializer=health_pb2.HealthCheckRequest.SerializeToString,
            response_deserializer=health_pb2.HealthCheckResponse.FromString)

    def close(self) -> None:
        self._channel.close()
        if self._health_channel is not self._channel:
            self._health_channel.close()

    def __enter__(self) -> "FoveaClient":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def health(self, service: str = "fovea.v1.Perception",
               timeout: Optional[float] = 5.0) -> str:
        """The grpc.health.v1 status name, e.g. "SERVING"."""
        response = self._health(
            health_pb2.HealthCheckRequest(service=service), timeout=timeout)
        return health_pb2.HealthCheckResponse.ServingStatus.Name(response.status)

    def capabilities(self, timeout: Optional[float] = None
                     ) -> perception_pb2.GetCapabilitiesResponse:
        """The server's Capabilities (perception.proto)."""
        return self._stub.GetCapabilities(
            perception_pb2.GetCapabilitiesRequest(), timeout=timeout)

    def detect(self, color_rgb: np.ndarray, depth_m: np.ndarray, fx: float,
               fy: float, cx: float, cy: float,
               timeout: Optional[float] = None, request_id: str = "",
               **options: Any) -> detect_pb2.DetectResponse:
        """Attention points for one frame: a DetectResponse (detect.proto).

        color_rgb: (H, W, 3) uint8 RGB; depth_m: (H, W) float32 metres
        (NaN or 0 = no data) or uint16 millimetres; see frame_from_numpy.
        `options` are DetectOptions fields (see detect_options).
        """
        request = detect_pb2.DetectRequest(
            request_id=request_id,
            frame=frame_from_numpy(color_rgb, depth_m, fx, fy, cx, cy),
            options=detect_options(**options))
        return self.detect_request(request, timeout=timeout)

    def detect_request(self, request: detect_pb2.DetectRequest,
                       timeout: Optional[float] = None
                       ) -> detect_pb2.DetectResponse:
        """Detect with a ready DetectRequest (e.g. a frame_from_files one)."""
        return self._stub.Detect(request, timeout=timeout)

    def segment(self, color_rgb: np.ndarray, depth_m: np.ndarray, fx: float,
                fy: float, cx: float, cy: float, method: str = "COS",
                max_objects: int = 0,
                seeds: Sequence[Tuple[int, int]] = (),
                timeout: Optional[float] = None, request_id: str = "",
                cover_scene: Optional[bool] = None,
                object_points: Optional[str] = None, max_points: int = 0,
                **options: Any) -> Iterator[segment_pb2.SegmentResponse]:
        """Object masks for one frame, as a generator of SegmentResponse.

        Messages are yielded as they arrive: first the attention points,
        then one per object (`response.object`, mask as COCO RLE; see
        decode_rle), then one with `last` set and a summary. method: "COS"
        or "EBS". seeds: (u, v) pixels to use instead of attention points.
        cover_scene: after the seeds, seed what no mask holds yet (None:
        the server's default, on without seeds, off with them).
        object_points: "xyz" or "indices" for each object's points (see
        object_points()), at most max_points of them (0: all); every
        object carries its box on the support either way (object_box()).
        `options` are DetectOptions fields for the attention points.
        Breaking out of the loop early cancels the call.
        """
        request = segment_pb2.SegmentRequest(
            request_id=request_id,
            frame=frame_from_numpy(color_rgb, depth_m, fx, fy, cx, cy),
            method=_enum_value(segment_pb2.SegmentationMethod.DESCRIPTOR,
                               method),
            max_objects=max_objects,
            seeds=[detect_pb2.AttentionPixel(u=u, v=v) for u, v in seeds],
            detect_options=detect_options(**options),
            object_points=_points_options(object_points, max_points))
        if cover_scene is not None:
            request.cover_scene = cover_scene
        return self.segment_request(request, timeout=timeout)

    def segment_request(self, request: segment_pb2.SegmentRequest,
                        timeout: Optional[float] = None
                        ) -> Iterator[segment_pb2.SegmentResponse]:
        """Segment with a ready SegmentRequest; a generator as segment()."""
        return self._stream(self._stub.Segment(request, timeout=timeout))

    def segment_incremental(self, color_rgb: np.ndarray, depth_m: np.ndarray,
                            fx: float, fy: float, cx: float, cy: float,
                            max_objects: int = 0,
                            time_budget_seconds: float = 0.0,
                            timeout: Optional[float] = None,
                            request_id: str = "",
                            object_points: Optional[str] = None,
                            max_points: int = 0, **options: Any
                            ) -> Iterator[segment_pb2.SegmentResponse]:
        """Anytime incremental segmentation (INC); a generator as segment()
        (object_points and max_points as there)."""
        request = segment_pb2.SegmentIncrementalRequest(
            request_id=request_id,
            frame=frame_from_numpy(color_rgb, depth_m, fx, fy, cx, cy),
            max_objects=max_objects, time_budget_seconds=time_budget_seconds,
            detect_options=detect_options(**options),
            object_points=_points_options(object_points, max_points))
        return self._stream(
            self._stub.SegmentIncremental(request, timeout=timeout))

    def track(self, frames: Iterable[Tuple[np.ndarray, np.ndarray]],
              fx: float, fy: float, cx: float, cy: float,
              poses: Optional[Iterable[Optional[Tuple[Sequence[float],
                                                      Sequence[float]]]]] = None,
              max_objects: int = 0, time_budget_seconds: float = 0.0,
              timeout: Optional[float] = None, request_id: str = "",
              **options: Any) -> Iterator[track_pb2.TrackResponse]:
        """A Track stream: objects with identities that persist.

        frames: an iterable of (colour RGB uint8 HxWx3, depth float32
        metres HxW), consumed as the stream sends them (a generator reading
        a camera works: the server answers the freshest frame and skips the
        ones that came while it was busy). poses: optional, one per frame,
        (position xyz in metres, quaternion xyzw) camera-to-world, or None
        for a frame without one. Yields one TrackResponse per processed
        frame: response.objects, each with track_id, state (APPEARED, KEPT,
        MOVED, GONE), object (mask as COCO RLE, see decode_rle) and
        world_centroid. `options` are DetectOptions fields. Breaking out of
        the loop early cancels the stream.
        """
        pose_iter = iter(poses) if poses is not None else None

        def requests():
            yield track_pb2.TrackRequest(options=track_pb2.TrackOptions(
                request_id=request_id, max_objects=max_objects,
                time_budget_seconds=time_budget_seconds,
                detect_options=detect_options(**options)))
            for n, (color_rgb, depth_m) in enumerate(frames):
                message = track_pb2.TrackFrame(
                    frame=frame_from_numpy(color_rgb, depth_m, fx, fy, cx, cy),
                    sequence=n)
                pose = next(pose_iter, None) if pose_iter is not None else None
                if pose is not None:
                    (px, py, pz), (qx, qy, qz, qw) = pose
                    message.camera_to_world.position.x = px
                    message.camera_to_world.position.y = py
                    message.camera_to_world.position.z = pz
                    message.camera_to_world.orientation.x = qx
                    message.camera_to_world.orientation.y = qy
                    message.camera_to_world.orientation.z = qz
                    message.camera_to_world.orientation.w = qw
                yield track_pb2.TrackRequest(frame=message)

        return self._stream(self._stub.Track(requests(), timeout=timeout))

    @staticmethod
    def _stream(call: Any) -> Iterator[segment_pb2.SegmentResponse]:
        try:
            yield from call
        finally:
            call.cancel()  # a no-op when the stream has ended
