#include "core/segmentation/planar_patches.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <opencv2/imgproc.hpp>
#include <set>

#include "core/frame/organized_cloud.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

OrganizedCloud CloudOf(const synth::SynthScene& scene) {
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  EXPECT_TRUE(cloud.ok()) << cloud.status();
  return cloud.ok() ? *std::move(cloud) : OrganizedCloud{};
}

// Per patch, pixels of each ground-truth label.
std::vector<std::map<int, int>> LabelsPerPatch(const PlanarPatches& p,
                                               const cv::Mat& truth) {
  std::vector<std::map<int, int>> counts(p.patches.size());
  for (int v = 0; v < truth.rows; ++v) {
    for (int u = 0; u < truth.cols; ++u) {
      const int id = p.labels.at<int>(v, u);
      if (id >= 0) ++counts[id][truth.at<int>(v, u)];
    }
  }
  return counts;
}

// Fraction of patch pixels whose label is their patch's majority label.
double Purity(const PlanarPatches& p, const cv::Mat& truth) {
  long majority = 0, total = 0;
  for (const auto& c : LabelsPerPatch(p, truth)) {
    int best = 0;
    for (const auto& [label, pixels] : c) {
      best = std::max(best, pixels);
      total += pixels;
    }
    majority += best;
  }
  return total > 0 ? static_cast<double>(majority) / total : 0.0;
}

TEST(PlanarPatchesTest, ABoxsFacesAndTheTableAreOnePatchEach) {
  const synth::SynthScene scene =
      testing::BoxOnTable(Eigen::Vector3f(0.08f, 0.06f, 0.05f));
  const OrganizedCloud cloud = CloudOf(scene);
  absl::StatusOr<PlanarPatches> p = FindPlanarPatches(cloud, {}, {});
  ASSERT_TRUE(p.ok()) << p.status();
  const cv::Mat& truth = scene.frame.labels;
  EXPECT_GT(Purity(*p, truth), 0.99);
  // The two largest patches on the box (front and top face, seen from in
  // front and above) cover nearly all of it; the largest on the table all
  // of the table in view.
  std::vector<std::pair<int, int>> on_box, on_table;  // (pixels, id)
  const auto counts = LabelsPerPatch(*p, truth);
  for (size_t id = 0; id < counts.size(); ++id) {
    for (const auto& [label, pixels] : counts[id]) {
      if (label >= 20) on_box.emplace_back(pixels, static_cast<int>(id));
      if (label == 1) on_table.emplace_back(pixels, static_cast<int>(id));
    }
  }
  std::sort(on_box.rbegin(), on_box.rend());
  std::sort(on_table.rbegin(), on_table.rend());
  // Pixels on a silhouette have no normal (the normal estimator will not
  // difference across a depth step) and belong to no patch.
  cv::Mat has_normal(truth.size(), CV_8UC1);
  for (int v = 0; v < truth.rows; ++v) {
    for (int u = 0; u < truth.cols; ++u) {
      has_normal.at<uint8_t>(v, u) = cloud.HasNormal(u, v) ? 255 : 0;
    }
  }
  const int box_pixels = cv::countNonZero((truth >= 20) & has_normal);
  const int table_pixels = cv::countNonZero((truth == 1) & has_normal);
  ASSERT_GE(on_box.size(), 2u);
  EXPECT_GT(on_box[0].first + on_box[1].first, 0.9 * box_pixels);
  ASSERT_GE(on_table.size(), 1u);
  EXPECT_GT(on_table[0].first, 0.9 * table_pixels);
  // The faces meet at a right angle and touch; the front face touches the
  // table.
  const PlanarPatch& a = p->patches[on_box[0].second];
  const PlanarPatch& b = p->patches[on_box[1].second];
  EXPECT_NEAR(std::abs(a.normal.dot(b.normal)), 0.0f, 0.05f);
  auto adjacent = [&](int x, int y) {
    return std::binary_search(p->adjacency.begin(), p->adjacency.end(),
                              std::make_pair(std::min(x, y), std::max(x, y)));
  };
  EXPECT_TRUE(adjacent(on_box[0].second, on_box[1].second));
  EXPECT_TRUE(adjacent(on_box[0].second, on_table[0].second) ||
              adjacent(on_box[1].second, on_table[0].second));
  // Patch bookkeeping matches the label image.
  for (size_t id = 0; id < p->patches.size(); ++id) {
    const cv::Mat mine = p->labels == static_cast<int>(id);
    EXPECT_EQ(cv::countNonZero(mine), p->patches[id].points);
    EXPECT_EQ(cv::boundingRect(mine), p->patches[id].box);
  }
}

TEST(PlanarPatchesTest, PatchesOfNoisyClutterStayOnOneObject) {
  int scenes = 0;
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synth::SynthScene scene = synth::GenerateScene(seed);
    const OrganizedCloud cloud = CloudOf(scene);
    absl::StatusOr<PlanarPatches> p = FindPlanarPatches(cloud, {}, {});
    ASSERT_TRUE(p.ok()) << p.status();
    EXPECT_GT(Purity(*p, scene.frame.labels), 0.97) << "seed " << seed;
    ++scenes;
  }
  EXPECT_EQ(scenes, 4);
}

TEST(PlanarPatchesTest, TheMaskLimitsThePoints) {
  const synth::SynthScene scene =
      testing::BoxOnTable(Eigen::Vector3f(0.08f, 0.06f, 0.05f));
  const OrganizedCloud cloud = CloudOf(scene);
  const cv::Mat box = scene.frame.labels >= 20;
  absl::StatusOr<PlanarPatches> p = FindPlanarPatches(cloud, box, {});
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_EQ(cv::countNonZero((p->labels >= 0) & ~box), 0);
  EXPECT_GT(cv::countNonZero(p->labels >= 0), 0.8 * cv::countNonZero(box));
  EXPECT_FALSE(FindPlanarPatches(cloud, cv::Mat(3, 3, CV_8UC1), {}).ok());
}

// The support's pixels are taken as they are: every support pixel with a
// normal lies in one patch (its one connected part), fitted to the table's
// plane; the box's faces are grown as without the support, and the leftover
// rims still join them.
TEST(PlanarPatchesTest, SupportPixelsAreOnePatchAndTheBoxIsGrownAsBefore) {
  const synth::SynthScene scene =
      testing::BoxOnTable(Eigen::Vector3f(0.08f, 0.06f, 0.05f));
  const OrganizedCloud cloud = CloudOf(scene);
  cv::Mat support = scene.frame.labels == 1;
  for (int v = 0; v < support.rows; ++v) {
    for (int u = 0; u < support.cols; ++u) {
      if (!cloud.HasNormal(u, v)) support.at<uint8_t>(v, u) = 0;
    }
  }
  absl::StatusOr<PlanarPatches> with =
      FindPlanarPatches(cloud, {}, {}, support);
  absl::StatusOr<PlanarPatches> without = FindPlanarPatches(cloud, {}, {});
  ASSERT_TRUE(with.ok()) << with.status();
  ASSERT_TRUE(without.ok());
  // One label over all the support pixels.
  std::set<int> support_ids;
  for (int v = 0; v < support.rows; ++v) {
    for (int u = 0; u < support.cols; ++u) {
      if (support.at<uint8_t>(v, u)) {
        support_ids.insert(with->labels.at<int>(v, u));
      }
    }
  }
  ASSERT_EQ(support_ids.size(), 1u);
  const int table = *support_ids.begin();
  ASSERT_GE(table, 0);
  // Its plane is the table's: y = 0 in the scene's world, a plane facing
  // the camera with normal . p + d = 0 at every support pixel.
  const PlanarPatch& t = with->patches[table];
  double worst = 0.0;
  for (int v = 0; v < support.rows; v += 7) {
    for (int u = 0; u < support.cols; u += 7) {
      if (!support.at<uint8_t>(v, u)) continue;
      const cv::Vec3f q = cloud.xyz.at<cv::Vec3f>(v, u);
      worst = std::max<double>(
          worst,
          std::abs(t.normal.dot(Eigen::Vector3f(q[0], q[1], q[2])) + t.d));
    }
  }
  EXPECT_LT(worst, 0.01);
  // The box's pixels get the same patches either way (up to the ids).
  const cv::Mat box = scene.frame.labels >= 20;
  std::map<int, int> same;  // id without -> id with
  int box_pixels = 0, agreeing = 0;
  for (int v = 0; v < box.rows; ++v) {
    for (int u = 0; u < box.cols; ++u) {
      if (!box.at<uint8_t>(v, u)) continue;
      const int a = without->labels.at<int>(v, u);
      const int b = with->labels.at<int>(v, u);
      if (a < 0 && b < 0) continue;
      ++box_pixels;
      const auto [it, fresh] = same.emplace(a, b);
      agreeing += it->second == b;
    }
  }
  ASSERT_GT(box_pixels, 1000);
  EXPECT_GT(agreeing, 0.98 * box_pixels);
  // Bookkeeping matches the label image.
  for (size_t id = 0; id < with->patches.size(); ++id) {
    const cv::Mat mine = with->labels == static_cast<int>(id);
    EXPECT_EQ(cv::countNonZero(mine), with->patches[id].points);
    EXPECT_EQ(cv::boundingRect(mine), with->patches[id].box);
  }
  EXPECT_FALSE(FindPlanarPatches(cloud, {}, {}, cv::Mat(3, 3, CV_8UC1)).ok());
}

TEST(PlanarPatchesTest, RejectsBadOptionsNamingTheField) {
  PlanarPatchOptions o;
  o.max_normal_angle_deg = 95.0f;
  EXPECT_NE(Validate(o).message().find("max_normal_angle_deg"),
            std::string::npos);
  o = {};
  o.min_points = 0;
  EXPECT_NE(Validate(o).message().find("min_points"), std::string::npos);
  o = {};
  o.refit_growth = 0.5f;
  EXPECT_NE(Validate(o).message().find("refit_growth"), std::string::npos);
  EXPECT_TRUE(Validate(PlanarPatchOptions{}).ok());
}

}  // namespace
}  // namespace fovea
