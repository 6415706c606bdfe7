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
};

// The kinds' names (core/base/name_table.h): generic kinect_v1 active_stereo.
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
  // hence the millimetre floor.
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
// frame as sent). kGeneric chooses from the focal length a frame of the
// camera 640 pixels on its longer side would have
// (fx * 640 / (2 max(cx, cy) + 1), so that a camera rolled a quarter turn
// is still itself): 500-590 px is
// the structured-light PrimeSense family (Kinect v1, Xtion, Astra) and gets
// the Kinect v1 model; any other camera gets the active-stereo model, the
// noisier one, with a 3 m range.
SensorModel SensorModelFor(SensorKind kind, const Intrinsics& intrinsics);

// The kind whose noise SensorModelFor gives `kind` with these intrinsics:
// `kind` itself, or for kGeneric kKinectV1 or kActiveStereo as chosen
// above (whose range is then the generic 3 m, not the stereo one). For a
// part of the frame cut out (its principal point moved), whose own
// intrinsics would choose otherwise.
SensorKind NoiseKind(SensorKind kind, const Intrinsics& intrinsics);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_SENSOR_MODEL_H_
