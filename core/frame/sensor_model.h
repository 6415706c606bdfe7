#ifndef FOVEA_CORE_FRAME_SENSOR_MODEL_H_
#define FOVEA_CORE_FRAME_SENSOR_MODEL_H_

#include <string_view>

#include "absl/status/statusor.h"
#include "core/base/name_table.h"
#include "core/frame/rgbd_frame.h"

namespace fovea {

// What an RGB-D sensor's depth looks like, for the thresholds that depend
// on it: axial noise growing with distance and the range it is usable
// over. Every stage
// threshold that depends on the sensor is derived from one of these
// (AdaptToSensor in core/pipeline/sensor_adaptation.h), so a frame from
// another camera gets thresholds that fit its noise rather than a Kinect's.

enum class SensorKind {
  // Chosen from the intrinsics (see SensorModelFor). The default, for a
  // camera nobody named.
  kGeneric,
  // Microsoft Kinect v1 / PrimeSense structured light (OSD's sensor).
  kKinectV1,
  // Active stereo in the manner of Intel RealSense D4xx: noisier with
  // distance than the Kinect, a floor of about a millimetre at short
  // range, and bands without depth beside foreground objects and at the
  // image's left edge.
  kActiveStereo,
  // Time of flight in the manner of Azure Kinect / Kinect v2: per-pixel
  // noise of a millimetre or two, growing slowly with distance; no
  // shadows (illuminator and sensor sit together), mixed ("flying")
  // pixels along depth edges, dark surfaces without depth.
  kTimeOfFlight,
};

// The kinds' names (core/base/name_table.h): generic kinect_v1
// active_stereo time_of_flight.
absl::Span<const NamedValue<SensorKind>> SensorKinds();
std::string_view SensorKindName(SensorKind kind);
// The inverse of SensorKindName; INVALID_ARGUMENT listing the known names.
absl::StatusOr<SensorKind> ParseSensorKind(std::string_view text);

struct SensorModel {
  SensorKind kind = SensorKind::kGeneric;
  // Axial depth noise (one standard deviation) at depth z:
  //   sigma(z) = sigma0_m + sigma_per_z2 * z^2, metres.
  // Kinect v1: 1.43e-3 / m (Khoshelham & Elberink 2012). Active stereo:
  // disparity noise of about 0.08 px over a 5 cm baseline and a focal length
  // near 600 px gives about 2.5e-3 / m; the four RealSense frames of
  // shared/data/realsense show 0.7-1.8 mm on their table tops at 0.45-1 m,
  // hence the millimetre floor. Time of flight: 1 mm + 0.5e-3 / m (about
  // 1.5 mm at 1 m and 3 mm at 2 m, as published for the Kinect v2 and
  // Azure Kinect on matte surfaces, Fankhauser et al. 2015, Tolgyessy et
  // al. 2021; no frames of one have been measured here).
  float sigma0_m = 0.0f;
  float sigma_per_z2 = 1.43e-3f;
  // Depth beyond which the sensor's data is not used by default, metres:
  // the workspace's default maximum range (core/scene/workspace.h).
  float max_range_m = 3.0f;
  // Nearest usable depth, metres.
  float min_range_m = 0.2f;
  // sigma(z) above, metres; z in metres.
  float DepthSigma(float z) const { return sigma0_m + sigma_per_z2 * z * z; }
};

// The model of `kind` for a frame with these intrinsics (pixels of the
// frame as sent). kGeneric chooses from the frame's shape, as its
// principal point gives it ((2 cx + 1) by (2 cy + 1), longer side over
// shorter, so that a camera rolled a quarter turn is still itself), then
// from the focal length a frame of the camera 640 pixels on its longer
// side would have (fx * 640 / (2 max(cx, cy) + 1)):
//   - nearly square, at most 1.22 to 1 (time-of-flight depth cameras:
//     Azure Kinect 640x576 and 512x512, Kinect v2 512x424, where 4:3 is
//     1.33 and 16:9 1.78): the time-of-flight model;
//   - 500-590 px: the structured-light PrimeSense family (Kinect v1,
//     Xtion, Astra), the Kinect v1 model;
//   - any other camera the active-stereo model, the noisier one, with a
//     3 m range.
// A time-of-flight frame registered to a wider colour camera looks like
// that camera: declare its sensor.
SensorModel SensorModelFor(SensorKind kind, const Intrinsics& intrinsics);

// The kind whose noise SensorModelFor gives `kind` with these intrinsics:
// `kind` itself, or for kGeneric kTimeOfFlight, kKinectV1 or
// kActiveStereo as chosen above (whose range is then the generic 3 m, not the
// stereo one). For a part of the frame cut out (its principal point moved),
// whose own intrinsics would choose otherwise.
SensorKind NoiseKind(SensorKind kind, const Intrinsics& intrinsics);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_SENSOR_MODEL_H_
