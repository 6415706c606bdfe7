#include "core/frame/sensor_model.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/base/name_table.h"
#include "core/base/strings.h"

namespace fovea {
namespace {

// Kinect v1: Khoshelham & Elberink 2012, sigma = 1.43e-3 z^2; OSD's scenes
// lie within 0.5-2 m, and beyond 3.5 m the quantisation steps exceed 3 cm.
constexpr float kKinectSigmaPerZ2 = 1.43e-3f;
constexpr float kKinectMaxRange = 3.5f;
constexpr float kKinectMinRange = 0.4f;
// Active stereo (RealSense D4xx-like): RMS error about 2 % at 2 m for a
// 5 cm baseline, i.e. 2.5e-3 / m, with the millimetre floor measured on the
// table tops of shared/data/realsense; usable to about 3 m for a table.
constexpr float kStereoSigma0 = 0.001f;
constexpr float kStereoSigmaPerZ2 = 2.5e-3f;
constexpr float kStereoMaxRange = 3.0f;
constexpr float kStereoMinRange = 0.2f;
// Time of flight (Kinect v2, Azure Kinect NFOV): about 1.5 mm at 1 m and 3
// mm at 2 m on matte surfaces (Fankhauser et al. 2015; Tolgyessy et al.
// 2021), usable from 0.4 m (below 0.5 m the Azure Kinect's narrow mode
// reports nothing, its wide mode 0.25 m) to 3.5 m.
constexpr float kTofSigma0 = 0.001f;
constexpr float kTofSigmaPerZ2 = 0.5e-3f;
constexpr float kTofMaxRange = 3.5f;
constexpr float kTofMinRange = 0.25f;
// A frame at most this much longer than wide is a time-of-flight camera's
// (10:9, 1:1, Kinect v2's 512x424 at 1.21); 4:3 is 1.33, and still 1.26
// with its principal point 8 px off centre both ways.
constexpr double kTofMaxAspect = 1.22;
// Generic: the structured-light PrimeSense family (Kinect v1, Xtion,
// Carmine, Astra) registers depth to a colour camera of 525-580 px focal
// length at 640 pixels wide; other cameras (RealSense D4xx colour at
// 600-640, depth streams at 380-430, time of flight) get the active-stereo
// model, the noisier of the two, with a 3 m range.
constexpr double kPrimeSenseFx640Min = 500.0;
constexpr double kPrimeSenseFx640Max = 590.0;
constexpr float kGenericMaxRange = 3.0f;

}  // namespace

absl::Span<const NamedValue<SensorKind>> SensorKinds() {
  static constexpr NamedValue<SensorKind> kTable[] = {
      {SensorKind::kGeneric, "generic"},
      {SensorKind::kKinectV1, "kinect_v1"},
      {SensorKind::kActiveStereo, "active_stereo"},
      {SensorKind::kTimeOfFlight, "time_of_flight"},
  };
  return kTable;
}

std::string_view SensorKindName(SensorKind kind) {
  return NameOf(SensorKinds(), kind);
}

absl::StatusOr<SensorKind> ParseSensorKind(std::string_view text) {
  return ParseNamed(SensorKinds(), "sensor", "model", text);
}

SensorModel SensorModelFor(SensorKind kind, const Intrinsics& intrinsics) {
  SensorModel model;
  model.kind = kind;
  switch (kind) {
    case SensorKind::kKinectV1:
      model.sigma0_m = 0.0f;
      model.sigma_per_z2 = kKinectSigmaPerZ2;
      model.max_range_m = kKinectMaxRange;
      model.min_range_m = kKinectMinRange;
      break;
    case SensorKind::kActiveStereo:
      model.sigma0_m = kStereoSigma0;
      model.sigma_per_z2 = kStereoSigmaPerZ2;
      model.max_range_m = kStereoMaxRange;
      model.min_range_m = kStereoMinRange;
      break;
    case SensorKind::kTimeOfFlight:
      model.sigma0_m = kTofSigma0;
      model.sigma_per_z2 = kTofSigmaPerZ2;
      model.max_range_m = kTofMaxRange;
      model.min_range_m = kTofMinRange;
      break;
    case SensorKind::kGeneric:
      model = SensorModelFor(NoiseKind(kind, intrinsics), intrinsics);
      if (model.kind == SensorKind::kActiveStereo) {
        model.max_range_m = kGenericMaxRange;
      }
      model.kind = SensorKind::kGeneric;
      break;
  }
  return model;
}

SensorKind NoiseKind(SensorKind kind, const Intrinsics& intrinsics) {
  if (kind != SensorKind::kGeneric) return kind;
  // The focal length a 640-pixel-wide frame of this camera would have, the
  // width being the longer side (a camera rolled a quarter turn sends its
  // 640 pixels as rows).
  const double width = 2.0 * (std::max(intrinsics.cx, intrinsics.cy) + 0.5);
  const double height = 2.0 * (std::min(intrinsics.cx, intrinsics.cy) + 0.5);
  if (height > 0.0 && width / height <= kTofMaxAspect) {
    return SensorKind::kTimeOfFlight;
  }
  const double fx640 =
      width > 0.0 && intrinsics.fx > 0.0 ? intrinsics.fx * 640.0 / width : 0.0;
  return fx640 >= kPrimeSenseFx640Min && fx640 <= kPrimeSenseFx640Max
             ? SensorKind::kKinectV1
             : SensorKind::kActiveStereo;
}

}  // namespace fovea
