#ifndef FOVEA_SERVER_CAPABILITIES_H_
#define FOVEA_SERVER_CAPABILITIES_H_

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/frame/frame_decode.h"
#include "core/pipeline/detect.h"
#include "fovea/v1/perception.pb.h"

namespace fovea::server {

// The server's version: the CMake project version (FOVEA_VERSION).
std::string_view ServerVersion();

// What core's Validate(DetectOptions) accepts today, so the server never
// keeps a second list: each value is tried alone on otherwise default
// options (an operator as the only channel) and kept when Validate is OK.
std::vector<SaliencyOp> ImplementedSaliencyOps();
std::vector<PyramidKind> ImplementedPyramids();
std::vector<NormalizationKind> ImplementedNormalizations();
std::vector<ExtractionKind> ImplementedExtractions();

// GetCapabilities' answer: server version, raw encodings (rgb8, bgr8;
// 16UC1, 32FC1), compressed formats (png, jpeg), the frame limits and
// largest message, the implemented operators and strategies above, no
// segmentation methods or models yet, and core's default DetectOptions.
v1::GetCapabilitiesResponse BuildCapabilities(
    const FrameLimits& limits, uint64_t max_message_bytes,
    const std::vector<std::pair<std::string, std::string>>& model_versions =
        {});

}  // namespace fovea::server

#endif  // FOVEA_SERVER_CAPABILITIES_H_
