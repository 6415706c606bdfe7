#ifndef FOVEA_CORE_SEGMENTATION_SVM_COMMON_H_
#define FOVEA_CORE_SEGMENTATION_SVM_COMMON_H_

// What LinearSvm and RbfSvm share: the pieces of their text formats (their
// training shares svm_train_common.h).

#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/segmentation/linear_svm.h"

namespace fovea::svm_internal {

// FNV-1a, 64 bits: a stable content hash for model versions.
uint64_t Fnv1a(std::string_view text);

// A finite number, or INVALID_ARGUMENT naming the line.
absl::StatusOr<double> ParseNumber(std::string_view text, int line);

}  // namespace fovea::svm_internal

#endif  // FOVEA_CORE_SEGMENTATION_SVM_COMMON_H_
