#include "core/pipeline/models.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/segmentation/relations.h"

namespace fovea {
namespace {

// Model files are a few hundred bytes to a few kilobytes; anything much
// larger is not one.
constexpr std::uintmax_t kMaxModelFileBytes = 16 << 20;

absl::StatusOr<std::string> ReadModelFile(const std::filesystem::path& path,
                                          std::string_view how_to_make) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return absl::NotFoundError(
        absl::StrCat("model file ", path.string(),
                     " is missing; make it with `", AbslView(how_to_make),
                     "` or point --models_dir at a folder that has it"));
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error || size > kMaxModelFileBytes) {
    return absl::InvalidArgumentError(absl::StrCat(
        "model file ", path.string(), " is unreadable or too large"));
  }
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) {
    return absl::InvalidArgumentError(
        absl::StrCat("model file ", path.string(), " cannot be read"));
  }
  return text.str();
}

// INC's relation model at `path`, checked to compute this build's
// relations.
absl::StatusOr<RbfSvm> LoadIncModel(const std::filesystem::path& path,
                                    std::string_view how_to_make) {
  FOVEA_ASSIGN_OR_RETURN(std::string text, ReadModelFile(path, how_to_make));
  absl::StatusOr<RbfSvm> inc = RbfSvm::Parse(text, "inc");
  if (!inc.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "model file ", path.string(),
        " is not an INC relation model: ", inc.status().message()));
  }
  if (inc->feature_names() != RelationFeatureNames()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "model file ", path.string(),
        " was trained on other relations than this build computes; retrain "
        "it with fovea-train inc"));
  }
  return *std::move(inc);
}

}  // namespace

SegmentModels LoadedModels::View() const {
  SegmentModels models;
  models.cos = cos ? &*cos : nullptr;
  models.ebs = ebs ? &*ebs : nullptr;
  models.inc = inc ? &*inc : nullptr;
  models.inc_active_stereo = inc_active_stereo ? &*inc_active_stereo : nullptr;
  return models;
}

absl::StatusOr<LoadedModels> LoadModels(const std::string& dir) {
  std::error_code error;
  if (!std::filesystem::is_directory(dir, error)) {
    return absl::NotFoundError(
        absl::StrCat("models folder '", dir, "' does not exist"));
  }
  LoadedModels models;
  const std::filesystem::path cos_path =
      std::filesystem::path(dir) / kCosModelFile;
  FOVEA_ASSIGN_OR_RETURN(
      std::string cos_text,
      ReadModelFile(cos_path,
                    "fovea-train cos --data DIR --out models/cos_svm.txt"));
  absl::StatusOr<LinearSvm> cos = LinearSvm::Parse(cos_text, "cos");
  if (!cos.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("model file ", cos_path.string(),
                     " is not a COS model: ", cos.status().message()));
  }
  if (cos->feature_names() != CosFeatureNames()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "model file ", cos_path.string(),
        " was trained on other features than this build computes; retrain "
        "it with fovea-train cos"));
  }
  models.versions.emplace_back("cos_svm", cos->Version());
  models.cos = *std::move(cos);

  const std::filesystem::path ebs_path =
      std::filesystem::path(dir) / kEbsModelFile;
  FOVEA_ASSIGN_OR_RETURN(
      std::string ebs_text,
      ReadModelFile(ebs_path,
                    "fovea-train ebs --data DIR --out models/ebs_edges.txt"));
  absl::StatusOr<EbsModel> ebs = EbsModel::Parse(ebs_text);
  if (!ebs.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("model file ", ebs_path.string(),
                     " is not an EBS model: ", ebs.status().message()));
  }
  models.versions.emplace_back("ebs_edges", ebs->Version());
  models.ebs = *std::move(ebs);

  const std::filesystem::path inc_path =
      std::filesystem::path(dir) / kIncModelFile;
  FOVEA_ASSIGN_OR_RETURN(
      RbfSvm inc,
      LoadIncModel(
          inc_path,
          "fovea-train inc --data DIR --out models/inc_relations.txt"));
  models.versions.emplace_back("inc_relations", inc.Version());
  models.inc = std::move(inc);

  // A sensor family's folder, when there is one, must hold its model.
  const std::filesystem::path stereo_dir =
      std::filesystem::path(dir) / kActiveStereoModelsDir;
  if (std::filesystem::exists(stereo_dir, error)) {
    FOVEA_ASSIGN_OR_RETURN(
        RbfSvm stereo,
        LoadIncModel(stereo_dir / kIncModelFile,
                     "fovea-train inc --data DIR --sensor active_stereo "
                     "--piles 100 --stacked 30 --out "
                     "models/active_stereo/inc_relations.txt"));
    models.versions.emplace_back("inc_relations.active_stereo",
                                 stereo.Version());
    models.inc_active_stereo = std::move(stereo);
  }
  return models;
}

}  // namespace fovea
