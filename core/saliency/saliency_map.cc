#include "core/saliency/saliency_map.h"

namespace fovea {

void NormalizeLinear(cv::Mat& map) {
  double max_value = 0.0;
  cv::minMaxLoc(map, nullptr, &max_value);
  if (max_value > 0.0) map *= 1.0 / max_value;
}

}  // namespace fovea
