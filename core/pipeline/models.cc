#include "core/pipeline/models.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

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

// The SVM of `path` (LinearSvm or RbfSvm), checked to take the features
// this build computes: `what` names the kind in errors ("a COS model"),
// `tag` is its file tag and fovea-train command.
template <typename Svm>
absl::StatusOr<Svm> LoadSvm(const std::filesystem::path& path,
                            std::string_view tag, std::string_view what,
                            const std::vector<std::string>& features,
                            std::string_view how_to_make) {
  FOVEA_ASSIGN_OR_RETURN(std::string text, ReadModelFile(path, how_to_make));
  absl::StatusOr<Svm> svm = Svm::Parse(text, tag);
  if (!svm.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("model file ", path.string(), " is not ", AbslView(what),
                     ": ", svm.status().message()));
  }
  if (svm->feature_names() != features) {
    return absl::InvalidArgumentError(absl::StrCat(
        "model file ", path.string(),
        " was trained on other features than this build computes; retrain "
        "it with fovea-train ",
        AbslView(tag)));
  }
  return *std::move(svm);
}

}  // namespace

SegmentModels LoadedModels::View() const {
  SegmentModels models;
  models.cos = cos ? &*cos : nullptr;
  models.ebs = ebs ? &*ebs : nullptr;
  models.inc = inc ? &*inc : nullptr;
  for (size_t i = 0; i < inc_family.size(); ++i) {
    models.inc_family[i] = inc_family[i] ? &*inc_family[i] : nullptr;
  }
  return models;
}

absl::StatusOr<LoadedModels> LoadModels(const std::string& dir) {
  std::error_code error;
  if (!std::filesystem::is_directory(dir, error)) {
    return absl::NotFoundError(
        absl::StrCat("models folder '", dir, "' does not exist"));
  }
  LoadedModels models;
  FOVEA_ASSIGN_OR_RETURN(
      LinearSvm cos,
      LoadSvm<LinearSvm>(
          std::filesystem::path(dir) / kCosModelFile, "cos", "a COS model",
          CosFeatureNames(),
          "fovea-train cos --data DIR --out models/cos_svm.txt"));
  models.versions.emplace_back("cos_svm", cos.Version());
  models.cos = std::move(cos);

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

  FOVEA_ASSIGN_OR_RETURN(
      RbfSvm inc,
      LoadSvm<RbfSvm>(
          std::filesystem::path(dir) / kIncModelFile, "inc",
          "an INC relation model", RelationFeatureNames(),
          "fovea-train inc --data DIR --out models/inc_relations.txt"));
  models.versions.emplace_back("inc_relations", inc.Version());
  models.inc = std::move(inc);

  // A sensor family's folder, when there is one, must hold its model.
  for (size_t i = 0; i < std::size(kIncFamilies); ++i) {
    const std::string family(SensorKindName(kIncFamilies[i]));
    const std::filesystem::path family_dir =
        std::filesystem::path(dir) / family;
    if (!std::filesystem::exists(family_dir, error)) continue;
    FOVEA_ASSIGN_OR_RETURN(
        RbfSvm svm,
        LoadSvm<RbfSvm>(
            family_dir / kIncModelFile, "inc", "an INC relation model",
            RelationFeatureNames(),
            absl::StrCat("fovea-train inc --data DIR --sensor ", family,
                         " --piles 100 --stacked 60 --out "
                         "models/",
                         family, "/inc_relations.txt")));
    models.versions.emplace_back(absl::StrCat("inc_relations.", family),
                                 svm.Version());
    models.inc_family[i] = std::move(svm);
  }
  return models;
}

}  // namespace fovea
