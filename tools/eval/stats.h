#ifndef FOVEA_TOOLS_EVAL_STATS_H_
#define FOVEA_TOOLS_EVAL_STATS_H_

#include <algorithm>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace fovea::eval {

// The median; the mean of the two middle values for an even count; 0 for
// none.
inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  double m = values[mid];
  if (values.size() % 2 == 0) {
    m = (m + *std::max_element(values.begin(), values.begin() + mid)) / 2.0;
  }
  return m;
}

// `status` with the scene's name in front of its message.
inline absl::Status InScene(const std::string& scene,
                            const absl::Status& status) {
  return absl::Status(status.code(),
                      absl::StrCat(scene, ": ", status.message()));
}

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_STATS_H_
