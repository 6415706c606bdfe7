#ifndef FOVEA_CORE_ATTENTION_ATTENTION_POINT_H_
#define FOVEA_CORE_ATTENTION_ATTENTION_POINT_H_

#include <Eigen/Core>
#include <limits>

namespace fovea {

// A point of attention on a saliency map.
struct AttentionPoint {
  int u = 0;              // column, pixels
  int v = 0;              // row, pixels
  float saliency = 0.0f;  // map value that ranked it, [0, 1]
  // 3D point at (u, v), metres, camera frame; NaN without depth. Filled by
  // the pipeline, not by the extractors.
  Eigen::Vector3f point =
      Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
};

}  // namespace fovea

#endif  // FOVEA_CORE_ATTENTION_ATTENTION_POINT_H_
