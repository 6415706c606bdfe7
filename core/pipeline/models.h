#ifndef FOVEA_CORE_PIPELINE_MODELS_H_
#define FOVEA_CORE_PIPELINE_MODELS_H_

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/pipeline/segment.h"
#include "core/segmentation/ebs.h"
#include "core/segmentation/linear_svm.h"
#include "core/segmentation/rbf_svm.h"

namespace fovea {

// The trained models of a models folder (models/ in the repository; see
// its README for how each was made).
inline constexpr char kCosModelFile[] = "cos_svm.txt";
inline constexpr char kEbsModelFile[] = "ebs_edges.txt";
inline constexpr char kIncModelFile[] = "inc_relations.txt";
// A sensor family of kIncFamilies (core/pipeline/segment.h) may have a
// folder of its own models (INC's only, for now), named
// SensorKindName(kind): models/active_stereo/, models/time_of_flight/;
// frames of that sensor are segmented with them (SegmentModels::IncFor).

struct LoadedModels {
  std::optional<LinearSvm> cos;
  std::optional<EbsModel> ebs;
  std::optional<RbfSvm> inc;
  // Each of kIncFamilies' INC model, in its order, when its folder exists.
  std::array<std::optional<RbfSvm>, std::size(kIncFamilies)> inc_family;
  // (name, version) of each model, as GetCapabilities reports them.
  std::vector<std::pair<std::string, std::string>> versions;

  // Pointers into this struct: valid while it lives and is not moved.
  SegmentModels View() const;
};

// Reads every model of `dir`, and those of the family folders it has. Errors
// name the file and what is wrong, and say how to make it: NOT_FOUND for a
// missing folder or file, INVALID_ARGUMENT for a file that does not parse (the
// parser's message).
absl::StatusOr<LoadedModels> LoadModels(const std::string& dir);

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_MODELS_H_
