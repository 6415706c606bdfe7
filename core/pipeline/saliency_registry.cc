#include "core/pipeline/saliency_registry.h"

#include "absl/strings/str_join.h"
#include "core/saliency/harel.h"
#include "core/saliency/hou.h"
#include "core/saliency/itti.h"
#include "core/saliency/kootstra.h"
#include "core/saliency/ph.h"
#include "core/saliency/rso.h"
#include "core/saliency/sh.h"
#include "core/saliency/sym3d.h"
#include "core/saliency/top_down.h"

namespace fovea {
namespace {

absl::StatusOr<cv::Mat> Ph(const OperatorInput& in) {
  return ComputePhSaliency(in.table, in.options.ph);
}
absl::StatusOr<cv::Mat> Sh(const OperatorInput& in) {
  return ComputeShSaliency(in.cloud, in.plane, in.table, in.options.sh);
}
absl::StatusOr<cv::Mat> Rso(const OperatorInput& in) {
  return ComputeRsoSaliency(in.cloud, in.plane, in.table, in.options.rso);
}
absl::StatusOr<cv::Mat> Sym3d(const OperatorInput& in) {
  return ComputeSym3dSaliency(in.cloud, in.table, in.options.sym3d);
}
// SYM3D's k x k kernel must span an object: without a pyramid it runs on a
// coarser level.
int Sym3dLevel(const DetectOptions& options) { return options.sym3d_level; }
absl::StatusOr<cv::Mat> Itti(const OperatorInput& in) {
  return ComputeIttiSaliency(in.cloud.color, in.options.itti);
}
absl::StatusOr<cv::Mat> Harel(const OperatorInput& in) {
  return ComputeHarelSaliency(in.cloud.color, in.options.harel);
}
absl::StatusOr<cv::Mat> Hou(const OperatorInput& in) {
  return ComputeHouSaliency(in.cloud.color, in.options.hou);
}
absl::StatusOr<cv::Mat> Kootstra(const OperatorInput& in) {
  return ComputeKootstraSaliency(in.cloud.color, in.options.kootstra);
}
absl::StatusOr<cv::Mat> TargetColor(const OperatorInput& in) {
  return ComputeTargetColorSaliency(in.cloud.color, in.options.target_color);
}
absl::StatusOr<cv::Mat> LocationPrior(const OperatorInput& in) {
  return ComputeLocationPrior(in.cloud.color.cols, in.cloud.color.rows,
                              in.options.location_prior);
}

constexpr OperatorDomain kGeometry = OperatorDomain::kGeometry;
constexpr OperatorDomain kImage = OperatorDomain::kImage;

constexpr SaliencyOperator kOperators[] = {
    {SaliencyOp::kPh, "ph", kGeometry, &Ph},
    {SaliencyOp::kSh, "sh", kGeometry, &Sh},
    {SaliencyOp::kRso, "rso", kGeometry, &Rso},
    {SaliencyOp::kSym3d, "sym3d", kGeometry, &Sym3d, &Sym3dLevel},
    {SaliencyOp::kItti, "itti", kImage, &Itti},
    {SaliencyOp::kHarel, "harel", kImage, &Harel},
    {SaliencyOp::kHou, "hou", kImage, &Hou},
    {SaliencyOp::kKootstra, "kootstra", kImage, &Kootstra},
    {SaliencyOp::kTargetColor, "target_color", kImage, &TargetColor},
    {SaliencyOp::kLocationPrior, "location_prior", kImage, &LocationPrior},
};

}  // namespace

absl::Span<const SaliencyOperator> SaliencyOperators() { return kOperators; }

const SaliencyOperator* FindSaliencyOperator(SaliencyOp op) {
  for (const SaliencyOperator& row : kOperators) {
    if (row.op == op) return &row;
  }
  return nullptr;
}

const SaliencyOperator* FindSaliencyOperator(std::string_view name) {
  for (const SaliencyOperator& row : kOperators) {
    if (row.name == name) return &row;
  }
  return nullptr;
}

std::string SaliencyOperatorNames() {
  return absl::StrJoin(kOperators, " ",
                       [](std::string* out, const SaliencyOperator& row) {
                         out->append(row.name);
                       });
}

}  // namespace fovea
