// fovea-client: calls a Fovea server from the command line.
//
//   fovea-client --server HOST:PORT health
//   fovea-client --server HOST:PORT capabilities [--json]
//   fovea-client --server HOST:PORT detect FRAME [options] [--json] [--out DIR]
//   fovea-client --server HOST:PORT segment FRAME [--method cos|ebs] ...
//   fovea-client --server HOST:PORT segment-incremental FRAME ...
// where --server may also list replicas, IP:PORT,IP:PORT,..., or name them
// all with one DNS name, dns:///NAME:PORT (client/channel.h), and
// FRAME is --color C.png --depth D.png [--fx .. --fy .. --cx .. --cy ..]
// or --pcd scene.pcd or --synthetic SEED.
//
// Exit codes: 0 success (health: SERVING), 1 health not SERVING or a local
// failure (unreadable file, cannot write --out), 2 the call failed (the gRPC
// code name and message go to stderr), 64 usage error.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "client/cli_frame.h"
#include "client/cli_output.h"
#include "client/fovea_client.h"
#include "client/option_names.h"
#include "core/base/status_macros.h"

ABSL_FLAG(std::string, server, "127.0.0.1:50051",
          "gRPC server: HOST:PORT, replicas as IP:PORT,IP:PORT,... or one "
          "DNS name for all of them, dns:///NAME:PORT; calls go round robin "
          "to the replicas whose health is SERVING and are retried on "
          "UNAVAILABLE");
ABSL_FLAG(int64_t, deadline_ms, 30000,
          "deadline of the call, milliseconds from its start");
ABSL_FLAG(std::string, tls_ca, "",
          "PEM CA certificates to trust: connect with TLS (empty: plaintext)");
ABSL_FLAG(std::string, tls_cert, "",
          "PEM client certificate chain for mutual TLS (with --tls_key)");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(bool, wait_for_ready, false,
          "wait (within the deadline) for the server to come up instead of "
          "failing with UNAVAILABLE at once");
ABSL_FLAG(bool, json, false,
          "print responses as protobuf JSON, one object per line (per stream "
          "message)");
ABSL_FLAG(std::string, out, "",
          "directory for response JSON and PNGs (overlay, saliency maps, "
          "masks); asks the server for the master saliency map");
ABSL_FLAG(std::string, service, "",
          "health: service to check (\"\" = the server, or "
          "fovea.v1.Perception)");

// The frame.
ABSL_FLAG(std::string, color, "", "colour image file, PNG or JPEG, sent as is");
ABSL_FLAG(std::string, depth, "",
          "depth image file, 16-bit grey PNG in --depth_scale units, sent as "
          "is");
ABSL_FLAG(std::string, pcd, "",
          "OSD PCD file, sent raw as rgb8 + 32FC1 (OSD Kinect intrinsics "
          "unless --fx/--fy/--cx/--cy)");
ABSL_FLAG(std::optional<uint64_t>, synthetic, std::nullopt,
          "seed of a built-in synthetic table scene, sent raw");
ABSL_FLAG(std::optional<double>, fx, std::nullopt,
          "focal length x, pixels (default 525, OSD Kinect v1)");
ABSL_FLAG(std::optional<double>, fy, std::nullopt,
          "focal length y, pixels (default 525)");
ABSL_FLAG(std::optional<double>, cx, std::nullopt,
          "principal point column, pixels (default 319.5)");
ABSL_FLAG(std::optional<double>, cy, std::nullopt,
          "principal point row, pixels (default 239.5)");
ABSL_FLAG(double, depth_scale, 0.001, "metres per unit of a 16-bit depth PNG");
ABSL_FLAG(std::string, frame_id, "", "camera frame id, echoed back");
ABSL_FLAG(std::string, request_id, "",
          "request id, echoed back (default: generated)");

// Detect options (empty = the server's default).
ABSL_FLAG(std::string, saliency, "",
          "saliency channels: ph, sh, rso, sym3d, itti, harel, hou, "
          "kootstra, target_color, location_prior; combine with '+' (equal "
          "weights) or give weights as name:w, e.g. ph+sh+rso, ph:2+rso:1");
ABSL_FLAG(std::string, extract, "", "attention points: msr | wta | tj");
ABSL_FLAG(std::string, pyramid, "", "pyramid: none | simple | itti");
ABSL_FLAG(std::string, norm, "", "map normalisation: lin | nms | nlm");
ABSL_FLAG(std::string, combine, "", "pyramid level combination: sum | max");
ABSL_FLAG(std::string, fusion, "", "channel fusion: sum | max");
ABSL_FLAG(bool, maps, false, "ask for each channel's saliency map");
ABSL_FLAG(std::string, target_color, "",
          "target_color operator: the colour looked for, R,G,B (0-255), "
          "e.g. 200,30,30");
ABSL_FLAG(std::string, location_prior, "",
          "location_prior operator: the pixel the prior is centred on, U,V "
          "(column,row)");
ABSL_FLAG(double, location_sigma, 0.0,
          "location_prior operator: its standard deviation, pixels (0: the "
          "server's default)");
ABSL_FLAG(std::optional<bool>, split_edges, std::nullopt,
          "split the master map at surface edges before extraction "
          "(unset: the server's default; false: the thesis's map)");
ABSL_FLAG(int32_t, points, 0,
          "number of attention points at most, 0 = the server's default "
          "(one per salient region, at most 100)");

// Segmentation.
// The scene.
ABSL_FLAG(std::string, sensor, "",
          "depth noise model: generic (chosen from the intrinsics, the "
          "default) | kinect_v1 | active_stereo");
ABSL_FLAG(int32_t, processing_width, 0,
          "frames wider than this are processed reduced, pixels (0: the "
          "server's 640)");
ABSL_FLAG(std::string, gravity, "",
          "X,Y,Z: unit vector pointing down in the camera frame");
ABSL_FLAG(std::string, support_plane, "",
          "NX,NY,NZ,D: the support plane n . p + d = 0 (camera frame, "
          "metres), given instead of searched");
ABSL_FLAG(std::string, workspace_box, "",
          "MINX,MINY,MINZ,MAXX,MAXY,MAXZ: only points inside this camera-frame "
          "box, metres");
ABSL_FLAG(double, min_depth, 0.0,
          "nearest depth considered, metres (0: the sensor's)");
ABSL_FLAG(double, max_depth, 0.0,
          "farthest depth considered, metres (0: the sensor's)");

ABSL_FLAG(std::string, method, "", "segment: cos | ebs");
ABSL_FLAG(int32_t, max_objects, 0, "segment: most objects, 0 = no limit");
ABSL_FLAG(std::string, seeds, "",
          "segment: seed pixels 'u,v;u,v;...' used in this order instead of "
          "the server's attention points (e.g. where a person pointed); "
          "segment-incremental: attention points, a Gaussian of saliency at "
          "each, the first the most salient");
ABSL_FLAG(double, time_budget_ms, 0.0,
          "segment-incremental: time budget, milliseconds, 0 = none");

namespace fovea::client {
namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitCallFailed = 2;
constexpr int kExitUsage = 64;  // EX_USAGE

constexpr char kUsage[] =
    R"(calls a Fovea perception server.

usage: fovea-client [--server SERVERS] COMMAND [flags]

SERVERS is HOST:PORT (default 127.0.0.1:50051), a list of replicas
IP:PORT,IP:PORT,... or one DNS name resolving to all of them,
dns:///NAME:PORT. Calls go round robin to the replicas that report
SERVING; one that fails with UNAVAILABLE before replying is retried on the
next. health asks one replica (the next reachable one).

commands:
  health                 print the serving status; exit 0 when SERVING
  capabilities           what the server accepts and offers
  detect FRAME           attention points, most salient first
  segment FRAME          object masks, streamed as each completes
  segment-incremental FRAME
                         anytime incremental segmentation, streamed

FRAME is one of
  --color C.png --depth D.png [--fx F --fy F --cx C --cy C] [--depth_scale S]
  --pcd scene.pcd        (OSD Kinect intrinsics unless given)
  --synthetic SEED       (a built-in synthetic table scene)

examples:
  fovea-client --server 127.0.0.1:50051 detect --synthetic 1 --out out/demo
  fovea-client detect --pcd learn6.pcd --saliency ph+sh+rso --extract msr --json
  fovea-client --server 10.0.0.5:50051,10.0.0.6:50051 detect --synthetic 1

exit codes: 0 ok, 1 not SERVING or a local failure, 2 the call failed (gRPC
code and message on stderr), 64 usage error. The flags: fovea-client --help)";

int Fail(int code, const absl::Status& status) {
  std::cerr << "fovea-client: " << absl::StatusCodeToString(status.code())
            << ": " << status.message() << "\n";
  return code;
}

// Exit code of a local error: bad flags are usage errors, the rest local
// failures.
int FailLocal(const absl::Status& status) {
  return Fail(status.code() == absl::StatusCode::kInvalidArgument
                  ? kExitUsage
                  : kExitFailure,
              status);
}

absl::Duration Deadline() {
  return absl::Milliseconds(absl::GetFlag(FLAGS_deadline_ms));
}

// The whole file at `path` ("" for an empty path); `flag` names it.
absl::StatusOr<std::string> ReadFileFlag(const std::string& path,
                                         const char* flag) {
  if (path.empty()) return std::string();
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", flag, ": cannot read '", path, "'"));
  }
  return std::string((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
}

absl::StatusOr<std::unique_ptr<FoveaClient>> MakeClient() {
  ClientOptions options;
  options.wait_for_ready = absl::GetFlag(FLAGS_wait_for_ready);
  for (const auto& [flag, value, out] :
       {std::tuple<const char*, std::string, std::string*>{
            "tls_ca", absl::GetFlag(FLAGS_tls_ca), &options.tls_root_certs},
        {"tls_cert", absl::GetFlag(FLAGS_tls_cert), &options.tls_cert_chain},
        {"tls_key", absl::GetFlag(FLAGS_tls_key), &options.tls_private_key}}) {
    FOVEA_ASSIGN_OR_RETURN(std::string text, ReadFileFlag(value, flag));
    *out = std::move(text);
  }
  return FoveaClient::Connect(absl::GetFlag(FLAGS_server), options);
}

std::string RequestId() {
  std::string id = absl::GetFlag(FLAGS_request_id);
  if (id.empty()) id = absl::StrCat("cli-", absl::ToUnixMicros(absl::Now()));
  return id;
}

absl::StatusOr<LoadedFrame> FrameFromFlags() {
  FrameSource source;
  source.color_path = absl::GetFlag(FLAGS_color);
  source.depth_path = absl::GetFlag(FLAGS_depth);
  source.pcd_path = absl::GetFlag(FLAGS_pcd);
  source.synthetic_seed = absl::GetFlag(FLAGS_synthetic);
  source.fx = absl::GetFlag(FLAGS_fx);
  source.fy = absl::GetFlag(FLAGS_fy);
  source.cx = absl::GetFlag(FLAGS_cx);
  source.cy = absl::GetFlag(FLAGS_cy);
  source.depth_scale = absl::GetFlag(FLAGS_depth_scale);
  source.frame_id = absl::GetFlag(FLAGS_frame_id);
  return LoadFrame(source);
}

// `count` comma-separated numbers of flag `name`; INVALID_ARGUMENT naming
// it otherwise.
absl::StatusOr<std::vector<double>> Numbers(const std::string& name,
                                            const std::string& text,
                                            size_t count) {
  std::vector<double> values;
  for (absl::string_view part : absl::StrSplit(text, ',')) {
    double value = 0.0;
    if (!absl::SimpleAtod(part, &value)) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": '", part, "' is not a number"));
    }
    values.push_back(value);
  }
  if (values.size() != count) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": expected ", count,
                     " comma-separated numbers, got ", values.size()));
  }
  return values;
}

// The scene options of the flags (the server validates the values).
absl::Status SceneFromFlags(fovea::v1::SceneOptions& scene) {
  const std::string sensor = absl::GetFlag(FLAGS_sensor);
  if (sensor == "generic") {
    scene.set_sensor(fovea::v1::SENSOR_MODEL_GENERIC);
  } else if (sensor == "kinect_v1") {
    scene.set_sensor(fovea::v1::SENSOR_MODEL_KINECT_V1);
  } else if (sensor == "active_stereo") {
    scene.set_sensor(fovea::v1::SENSOR_MODEL_ACTIVE_STEREO);
  } else if (!sensor.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("sensor: unknown model '", sensor,
                     "' (known: generic kinect_v1 active_stereo)"));
  }
  if (absl::GetFlag(FLAGS_processing_width) < 0) {
    return absl::InvalidArgumentError("processing_width: must be >= 0");
  }
  scene.set_processing_width(
      static_cast<uint32_t>(absl::GetFlag(FLAGS_processing_width)));
  if (const std::string g = absl::GetFlag(FLAGS_gravity); !g.empty()) {
    FOVEA_ASSIGN_OR_RETURN(std::vector<double> v, Numbers("gravity", g, 3));
    scene.mutable_gravity()->set_x((v)[0]);
    scene.mutable_gravity()->set_y((v)[1]);
    scene.mutable_gravity()->set_z((v)[2]);
  }
  if (const std::string p = absl::GetFlag(FLAGS_support_plane); !p.empty()) {
    FOVEA_ASSIGN_OR_RETURN(std::vector<double> v,
                           Numbers("support_plane", p, 4));
    fovea::v1::Plane* plane = scene.mutable_support_plane();
    plane->mutable_normal()->set_x((v)[0]);
    plane->mutable_normal()->set_y((v)[1]);
    plane->mutable_normal()->set_z((v)[2]);
    plane->set_d((v)[3]);
  }
  const std::string box = absl::GetFlag(FLAGS_workspace_box);
  const double min_depth = absl::GetFlag(FLAGS_min_depth);
  const double max_depth = absl::GetFlag(FLAGS_max_depth);
  if (!box.empty() || min_depth != 0.0 || max_depth != 0.0) {
    fovea::v1::Workspace* w = scene.mutable_workspace();
    w->set_min_depth_m(min_depth);
    w->set_max_depth_m(max_depth);
    if (!box.empty()) {
      FOVEA_ASSIGN_OR_RETURN(std::vector<double> v,
                             Numbers("workspace_box", box, 6));
      fovea::v1::Box* b = w->mutable_box();
      b->mutable_min()->set_x((v)[0]);
      b->mutable_min()->set_y((v)[1]);
      b->mutable_min()->set_z((v)[2]);
      b->mutable_max()->set_x((v)[3]);
      b->mutable_max()->set_y((v)[4]);
      b->mutable_max()->set_z((v)[5]);
    }
  }
  return absl::OkStatus();
}

// Detect options from the flags; INVALID_ARGUMENT naming a bad one.
absl::StatusOr<fovea::v1::DetectOptions> DetectOptionsFromFlags() {
  fovea::v1::DetectOptions options;
  FOVEA_ASSIGN_OR_RETURN(std::vector<fovea::v1::WeightedOperator> saliency,
                         ParseSaliency(absl::GetFlag(FLAGS_saliency)));
  for (fovea::v1::WeightedOperator& op : saliency) {
    *options.add_saliency() = std::move(op);
  }
  // Each enum flag: parse when given, leave UNSPECIFIED otherwise.
  auto set = [](const std::string& text, auto parse, auto setter) {
    if (text.empty()) return absl::OkStatus();
    FOVEA_ASSIGN_OR_RETURN(auto value, parse(text));
    setter(value);
    return absl::OkStatus();
  };
  for (absl::Status status : {
           set(absl::GetFlag(FLAGS_extract), ParseExtraction,
               [&](auto v) { options.set_extraction(v); }),
           set(absl::GetFlag(FLAGS_pyramid), ParsePyramid,
               [&](auto v) { options.set_pyramid(v); }),
           set(absl::GetFlag(FLAGS_norm), ParseNormalization,
               [&](auto v) { options.set_normalization(v); }),
           set(absl::GetFlag(FLAGS_combine), ParseLevelCombination,
               [&](auto v) { options.set_level_combination(v); }),
           set(absl::GetFlag(FLAGS_fusion), ParseFusion,
               [&](auto v) { options.set_fusion(v); }),
       }) {
    if (!status.ok()) return status;
  }
  const int32_t points = absl::GetFlag(FLAGS_points);
  if (points < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("points: must be >= 0, got ", points));
  }
  options.set_max_points(static_cast<uint32_t>(points));
  options.set_return_channel_maps(absl::GetFlag(FLAGS_maps));
  if (const std::string text = absl::GetFlag(FLAGS_target_color);
      !text.empty()) {
    FOVEA_ASSIGN_OR_RETURN(const auto rgb, ParseRgb("--target_color", text));
    for (const uint32_t value : rgb) options.add_target_color_rgb(value);
  }
  if (const std::string text = absl::GetFlag(FLAGS_location_prior);
      !text.empty()) {
    FOVEA_ASSIGN_OR_RETURN(*options.mutable_location_prior(),
                           ParsePixel("--location_prior", text));
  }
  if (const double sigma = absl::GetFlag(FLAGS_location_sigma); sigma != 0.0) {
    if (!(sigma > 0.0) || !std::isfinite(sigma)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "--location_sigma: ", sigma, " is not a number of pixels > 0"));
    }
    options.set_location_prior_sigma_px(sigma);
  }
  if (const std::optional<bool> split = absl::GetFlag(FLAGS_split_edges)) {
    options.set_split_at_surface_edges(*split);
  }
  options.set_return_saliency_map(!absl::GetFlag(FLAGS_out).empty());
  FOVEA_RETURN_IF_ERROR(SceneFromFlags(*options.mutable_scene()));
  return options;
}

int RunHealth() {
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());
  absl::StatusOr<grpc::health::v1::HealthCheckResponse::ServingStatus> status =
      (*client)->Health(absl::GetFlag(FLAGS_service), Deadline());
  if (!status.ok()) return Fail(kExitCallFailed, status.status());
  if (absl::GetFlag(FLAGS_json)) {
    grpc::health::v1::HealthCheckResponse response;
    response.set_status(*status);
    std::cout << ToJson(response) << std::endl;
  } else {
    std::cout << grpc::health::v1::HealthCheckResponse::ServingStatus_Name(
                     *status)
              << std::endl;
  }
  return *status == grpc::health::v1::HealthCheckResponse::SERVING
             ? kExitOk
             : kExitFailure;
}

int RunCapabilities() {
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());
  absl::StatusOr<fovea::v1::Capabilities> capabilities =
      (*client)->GetCapabilities(Deadline());
  if (!capabilities.ok()) return Fail(kExitCallFailed, capabilities.status());
  if (absl::GetFlag(FLAGS_json)) {
    std::cout << ToJson(*capabilities) << std::endl;
  } else {
    PrintCapabilities(*capabilities, std::cout);
  }
  return kExitOk;
}

int RunDetect() {
  absl::StatusOr<fovea::v1::DetectOptions> options = DetectOptionsFromFlags();
  if (!options.ok()) return Fail(kExitUsage, options.status());
  absl::StatusOr<LoadedFrame> frame = FrameFromFlags();
  if (!frame.ok()) return FailLocal(frame.status());
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());

  fovea::v1::DetectRequest request;
  request.set_request_id(RequestId());
  *request.mutable_options() = *std::move(options);
  const bool json = absl::GetFlag(FLAGS_json);
  if (!json) {
    std::cout << "detect on " << frame->description << " ("
              << frame->frame.ByteSizeLong() / 1024 << " KiB) at "
              << absl::GetFlag(FLAGS_server) << std::endl;
  }
  *request.mutable_frame() = std::move(frame->frame);

  const absl::Time start = absl::Now();
  absl::StatusOr<fovea::v1::DetectResponse> response =
      (*client)->Detect(request, Deadline());
  const absl::Duration round_trip = absl::Now() - start;
  if (!response.ok()) return Fail(kExitCallFailed, response.status());

  if (json) {
    std::cout << ToJson(*response) << std::endl;
  } else {
    PrintDetectTable(*response, round_trip, std::cout);
  }
  const std::string out = absl::GetFlag(FLAGS_out);
  if (!out.empty()) {
    absl::StatusOr<std::vector<std::string>> written =
        WriteDetectOutputs(out, *response, frame->color_bgr);
    if (!written.ok()) return Fail(kExitFailure, written.status());
    for (const std::string& path : *written)
      std::cerr << "wrote " << path << "\n";
  }
  return kExitOk;
}

// "u,v;u,v" into pixels; empty text is no seeds.
absl::StatusOr<std::vector<std::pair<uint32_t, uint32_t>>> ParseSeeds(
    const std::string& text) {
  std::vector<std::pair<uint32_t, uint32_t>> seeds;
  for (absl::string_view item : absl::StrSplit(text, ';', absl::SkipEmpty())) {
    const std::vector<absl::string_view> uv = absl::StrSplit(item, ',');
    uint32_t u = 0;
    uint32_t v = 0;
    if (uv.size() != 2 || !absl::SimpleAtoi(uv[0], &u) ||
        !absl::SimpleAtoi(uv[1], &v)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "seeds: '", item, "' is not a pixel 'u,v' (columns, rows)"));
    }
    seeds.emplace_back(u, v);
  }
  return seeds;
}

int RunSegment(bool incremental) {
  absl::StatusOr<fovea::v1::DetectOptions> options = DetectOptionsFromFlags();
  if (!options.ok()) return Fail(kExitUsage, options.status());
  fovea::v1::SegmentationMethod method =
      fovea::v1::SEGMENTATION_METHOD_UNSPECIFIED;
  if (!absl::GetFlag(FLAGS_method).empty()) {
    absl::StatusOr<fovea::v1::SegmentationMethod> parsed =
        ParseSegmentationMethod(absl::GetFlag(FLAGS_method));
    if (!parsed.ok()) return Fail(kExitUsage, parsed.status());
    method = *parsed;
  }
  const int32_t max_objects = absl::GetFlag(FLAGS_max_objects);
  const double time_budget_ms = absl::GetFlag(FLAGS_time_budget_ms);
  if (max_objects < 0 || time_budget_ms < 0.0) {
    return Fail(kExitUsage, absl::InvalidArgumentError(
                                "max_objects, time_budget_ms: must be >= 0"));
  }
  absl::StatusOr<std::vector<std::pair<uint32_t, uint32_t>>> seeds =
      ParseSeeds(absl::GetFlag(FLAGS_seeds));
  if (!seeds.ok()) return Fail(kExitUsage, seeds.status());
  absl::StatusOr<LoadedFrame> frame = FrameFromFlags();
  if (!frame.ok()) return FailLocal(frame.status());
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());

  const bool json = absl::GetFlag(FLAGS_json);
  const std::string out = absl::GetFlag(FLAGS_out);
  if (!json) {
    std::cout << (incremental ? "segment-incremental" : "segment") << " on "
              << frame->description << " at " << absl::GetFlag(FLAGS_server)
              << std::endl;
  }
  std::vector<fovea::v1::SegmentResponse> messages;  // kept for --out
  int message_count = 0;
  absl::Time start;
  auto on_message = [&](const fovea::v1::SegmentResponse& message) {
    ++message_count;
    if (json) {
      std::cout << ToJson(message) << std::endl;
    } else {
      std::cout << DescribeSegmentMessage(message, absl::Now() - start)
                << std::endl;
    }
    if (!out.empty()) {
      messages.push_back(message);
      if (message.has_object()) {
        absl::StatusOr<std::string> path =
            WriteObjectMask(out, message.object());
        if (path.ok()) {
          std::cerr << "wrote " << *path << "\n";
        } else {
          std::cerr << "fovea-client: " << path.status() << "\n";
        }
      }
    }
  };

  absl::Status status;
  if (incremental) {
    fovea::v1::SegmentIncrementalRequest request;
    request.set_request_id(RequestId());
    *request.mutable_frame() = std::move(frame->frame);
    *request.mutable_detect_options() = *std::move(options);
    request.set_max_objects(static_cast<uint32_t>(max_objects));
    request.set_time_budget_seconds(time_budget_ms / 1e3);
    for (const auto& [u, v] : *seeds) {
      fovea::v1::AttentionPixel* point = request.add_attention_points();
      point->set_u(u);
      point->set_v(v);
    }
    start = absl::Now();
    status = (*client)->SegmentIncremental(request, Deadline(), on_message);
  } else {
    fovea::v1::SegmentRequest request;
    request.set_request_id(RequestId());
    *request.mutable_frame() = std::move(frame->frame);
    *request.mutable_detect_options() = *std::move(options);
    request.set_method(method);
    request.set_max_objects(static_cast<uint32_t>(max_objects));
    for (const auto& [u, v] : *seeds) {
      fovea::v1::AttentionPixel* seed = request.add_seeds();
      seed->set_u(u);
      seed->set_v(v);
    }
    start = absl::Now();
    status = (*client)->Segment(request, Deadline(), on_message);
  }
  if (!json) {
    std::cout << absl::StrFormat(
                     "stream closed after %.1f ms, %d messages",
                     absl::ToDoubleMilliseconds(absl::Now() - start),
                     message_count)
              << std::endl;
  }
  if (!out.empty() && !messages.empty()) {
    absl::StatusOr<std::vector<std::string>> written =
        WriteSegmentOutputs(out, messages, frame->color_bgr);
    if (!written.ok()) {
      Fail(kExitFailure, written.status());
      if (status.ok()) return kExitFailure;
    } else {
      for (const std::string& path : *written)
        std::cerr << "wrote " << path << "\n";
    }
  }
  if (!status.ok()) return Fail(kExitCallFailed, status);
  return kExitOk;
}

bool IsClientFlagFile(absl::string_view file) {
  return absl::StrContains(file, "client/");
}

}  // namespace
}  // namespace fovea::client

int main(int argc, char** argv) {
  using namespace fovea::client;  // NOLINT: main only
  absl::SetProgramUsageMessage(kUsage);
  absl::FlagsUsageConfig usage_config;
  usage_config.contains_help_flags = IsClientFlagFile;
  usage_config.contains_helpshort_flags = IsClientFlagFile;
  usage_config.normalize_filename = [](absl::string_view file) {
    const size_t at = file.rfind("client/");
    return std::string(at == absl::string_view::npos ? file : file.substr(at));
  };
  absl::SetFlagsUsageConfig(usage_config);

  std::vector<char*> positional = absl::ParseCommandLine(argc, argv);
  if (positional.size() < 2) {
    std::cerr << "fovea-client " << kUsage << "\n";
    return kExitUsage;
  }
  const std::string command = positional[1];
  if (positional.size() > 2) {
    std::cerr << "fovea-client: unexpected argument \"" << positional[2]
              << "\" after " << command << "\n";
    return kExitUsage;
  }
  if (command == "health") return RunHealth();
  if (command == "capabilities") return RunCapabilities();
  if (command == "detect") return RunDetect();
  if (command == "segment") return RunSegment(/*incremental=*/false);
  if (command == "segment-incremental") return RunSegment(/*incremental=*/true);
  if (command == "help") {
    std::cout << "fovea-client " << kUsage << "\n";
    return kExitOk;
  }
  std::cerr << "fovea-client: unknown command \"" << command
            << "\" (health, capabilities, detect, segment, "
               "segment-incremental)\n";
  return kExitUsage;
}
