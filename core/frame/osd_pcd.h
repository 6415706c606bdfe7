#ifndef FOVEA_CORE_FRAME_OSD_PCD_H_
#define FOVEA_CORE_FRAME_OSD_PCD_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/rgbd_frame.h"

namespace fovea {

// A frame with per-pixel ground truth, from an OSD/mOSD PCD file or from
// core/synth.
//   labels: CV_32SC1, the file's `label` field: 0 no data, 1-9 table
//           parts, 10*k + j part j of object k (k >= 2). See ObjectId.
struct LabelledFrame {
  std::string name;  // file stem, e.g. "learn6"
  RgbdFrame frame;
  cv::Mat labels;
};

// Object id of a label (shared/data/README.md): label / 10 for labels >= 20,
// else 0 (no object: no data or table).
inline int ObjectId(int label) { return label >= 20 ? label / 10 : 0; }
inline bool IsTableLabel(int label) { return label >= 1 && label <= 9; }

// ObjectId of every pixel of `labels` (CV_32SC1): CV_32SC1, 0 where no
// object.
cv::Mat ObjectIdImage(const cv::Mat& labels);

// Loads an OSD PCD (fields label x y z rgba; any PCD with x y z and rgb or
// rgba also works, labels then 0). An organized cloud (height > 1) keeps
// its layout; an unorganized one (height 1) is re-organized by projecting
// each point through `intrinsics` into an image of `width` x `height`,
// nearest point winning; points behind the camera or outside the image are
// dropped. Depth is the points' z. Errors: NOT_FOUND for a missing file,
// INVALID_ARGUMENT for an unreadable or malformed one.
absl::StatusOr<LabelledFrame> LoadOsdPcd(
    const std::string& path, const Intrinsics& intrinsics = kKinectV1Intrinsics,
    int width = 640, int height = 480);

// The learn*.pcd (or any *.pcd) files of a folder, sorted by the number in
// their name ("learn2" before "learn10").
absl::StatusOr<std::vector<std::string>> ListPcdFiles(const std::string& dir);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_OSD_PCD_H_
