#include "core/eval/realism.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/frame/osd_pcd.h"

namespace fovea {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / M_PI;

// Indices into RealismSet::statistics (RealismStatisticNames() order).
enum Statistic {
  kPlaneNoise,
  kPlaneNoiseDepth,
  kMissingFraction,
  kMissingAtEdges,
  kMissingOnDark,
  kNormalAngle,
  kTableShare,
  kObjectInScene,
  kObjectStanding,
  kObjectBottom,
  kStatisticCount,
};

double Median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(),
                         [](double x) { return std::isnan(x); }),
          v.end());
  if (v.empty()) return kNaN;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

int CountValid(const std::vector<double>& v) {
  return static_cast<int>(std::count_if(
      v.begin(), v.end(), [](double x) { return !std::isnan(x); }));
}

// Residual standard deviation / z^2 of the support points of each cell
// whose pixels are mostly on the support (RealismOptions::cell_px).
void SamplePlaneNoise(const OrganizedCloud& cloud, const cv::Mat& inliers,
                      const RealismOptions& o, RealismSamples& out) {
  const int cell = std::max(2, o.cell_px * cloud.width() / 640);
  const int needed = static_cast<int>(std::ceil(o.cell_fill * cell * cell));
  for (int v0 = 0; v0 + cell <= cloud.height(); v0 += cell) {
    for (int u0 = 0; u0 + cell <= cloud.width(); u0 += cell) {
      std::vector<Eigen::Vector3d> points;
      for (int v = v0; v < v0 + cell; ++v) {
        const uint8_t* in = inliers.ptr<uint8_t>(v);
        const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
        for (int u = u0; u < u0 + cell; ++u) {
          if (in[u] == 0 || std::isnan(p[u][2])) continue;
          points.emplace_back(p[u][0], p[u][1], p[u][2]);
        }
      }
      if (static_cast<int>(points.size()) < needed) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const auto& p : points) mean += p;
      mean /= static_cast<double>(points.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const auto& p : points) cov += (p - mean) * (p - mean).transpose();
      cov /= static_cast<double>(points.size());
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      const double sigma = std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
      out.plane_noise.push_back(sigma / (mean.z() * mean.z()));
      out.plane_noise_depth.push_back(mean.z());
    }
  }
}

// The table as the camera sees it: the filled convex hull of the support
// region's pixels, eroded.
cv::Mat SupportImageHull(const cv::Mat& inliers, int erode_px) {
  cv::Mat hull_mask(inliers.size(), CV_8UC1, cv::Scalar(0));
  std::vector<cv::Point> pixels;
  cv::findNonZero(inliers, pixels);
  if (pixels.size() < 3) return hull_mask;
  std::vector<cv::Point> hull;
  cv::convexHull(pixels, hull);
  cv::fillConvexPoly(hull_mask, hull, cv::Scalar(255));
  if (erode_px > 0) {
    cv::erode(
        hull_mask, hull_mask,
        cv::getStructuringElement(
            cv::MORPH_RECT, cv::Size(2 * erode_px + 1, 2 * erode_px + 1)));
  }
  return hull_mask;
}

// Missing depth inside the hull: its share, the share of it in holes whose
// rim spans a depth jump, and the missing share of the dark pixels.
void SampleMissingDepth(const OrganizedCloud& cloud, const cv::Mat& hull,
                        const RealismOptions& o, RealismSamples& out) {
  const int w = cloud.width(), h = cloud.height();
  cv::Mat missing(h, w, CV_8UC1, cv::Scalar(0));
  // Without a colour image of the cloud's size, no pixel counts as dark.
  const bool have_color =
      cloud.color.type() == CV_8UC3 && cloud.color.size() == cloud.xyz.size();
  int inside = 0, missing_count = 0, dark = 0, dark_missing = 0;
  for (int v = 0; v < h; ++v) {
    const uint8_t* in = hull.ptr<uint8_t>(v);
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const cv::Vec3b* c = have_color ? cloud.color.ptr<cv::Vec3b>(v) : nullptr;
    uint8_t* m = missing.ptr<uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      if (in[u] == 0) continue;
      ++inside;
      const bool hole = std::isnan(p[u][2]);
      if (hole) {
        m[u] = 255;
        ++missing_count;
      }
      if (c != nullptr && (c[u][0] + c[u][1] + c[u][2]) < 3 * o.dark_grey) {
        ++dark;
        if (hole) ++dark_missing;
      }
    }
  }
  out.missing_fraction =
      inside > 0 ? static_cast<double>(missing_count) / inside : kNaN;
  out.missing_on_dark =
      dark > 0 ? static_cast<double>(dark_missing) / dark : kNaN;
  if (missing_count == 0) {
    out.missing_at_edges = kNaN;
    return;
  }
  // Each hole's rim: the valid pixels 4-adjacent to it.
  cv::Mat components;
  const int count = cv::connectedComponents(missing, components, 4, CV_32S);
  std::vector<float> near(count, std::numeric_limits<float>::infinity());
  std::vector<float> far(count, -std::numeric_limits<float>::infinity());
  std::vector<int> size(count, 0);
  const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
  for (int v = 0; v < h; ++v) {
    const int* id = components.ptr<int>(v);
    for (int u = 0; u < w; ++u) {
      if (id[u] == 0) continue;
      ++size[id[u]];
      for (int k = 0; k < 4; ++k) {
        const int uu = u + du[k], vv = v + dv[k];
        if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
        const float z = cloud.xyz.at<cv::Vec3f>(vv, uu)[2];
        if (std::isnan(z)) continue;
        near[id[u]] = std::min(near[id[u]], z);
        far[id[u]] = std::max(far[id[u]], z);
      }
    }
  }
  int at_edges = 0;
  for (int k = 1; k < count; ++k) {
    if (!(far[k] >= near[k])) continue;
    const double jump = std::max(o.edge_jump_m, o.edge_jump_fraction * near[k]);
    if (far[k] - near[k] > jump) at_edges += size[k];
  }
  out.missing_at_edges = static_cast<double>(at_edges) / missing_count;
}

// Angle between the support points' normals and the plane's, an even
// sample of at most max_point_samples.
void SampleNormals(const OrganizedCloud& cloud, const SupportPlane& plane,
                   const RealismOptions& o, RealismSamples& out) {
  std::vector<double> angles;
  for (int v = 0; v < cloud.height(); ++v) {
    const uint8_t* in = plane.inliers.ptr<uint8_t>(v);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      if (in[u] == 0 || std::isnan(n[u][2])) continue;
      const double c =
          std::abs(plane.normal.x() * n[u][0] + plane.normal.y() * n[u][1] +
                   plane.normal.z() * n[u][2]);
      angles.push_back(std::acos(std::min(1.0, c)) * kRadToDeg);
    }
  }
  const size_t most = static_cast<size_t>(std::max(1, o.max_point_samples));
  const size_t stride = std::max<size_t>(1, (angles.size() + most - 1) / most);
  for (size_t k = 0; k < angles.size(); k += stride) {
    out.normal_angle.push_back(angles[k]);
  }
}

// Per labelled object: the share of its pixels in the table scene and
// marked standing, and its bottom's height.
void SampleObjects(const TableScene& table, const cv::Mat& labels,
                   RealismSamples& out) {
  struct Counts {
    int pixels = 0, in_scene = 0, standing = 0;
    std::vector<double> heights;
  };
  std::vector<Counts> objects;
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    const uint8_t* region = table.region.ptr<uint8_t>(v);
    const uint8_t* standing = table.standing.ptr<uint8_t>(v);
    const float* height = table.height.ptr<float>(v);
    for (int u = 0; u < labels.cols; ++u) {
      const int id = ObjectId(l[u]);
      if (id <= 0) continue;
      if (id >= static_cast<int>(objects.size())) objects.resize(id + 1);
      Counts& c = objects[id];
      ++c.pixels;
      if (region[u] != 0) ++c.in_scene;
      if (standing[u] != 0) ++c.standing;
      if (!std::isnan(height[u])) c.heights.push_back(height[u]);
    }
  }
  constexpr int kMinObjectPixels = 50;  // as the scorecard's objects
  for (Counts& c : objects) {
    if (c.pixels < kMinObjectPixels) continue;
    out.object_in_scene.push_back(static_cast<double>(c.in_scene) / c.pixels);
    out.object_standing.push_back(static_cast<double>(c.standing) / c.pixels);
    if (c.heights.empty()) continue;
    const size_t k = c.heights.size() / 50;  // the 2nd percentile
    std::nth_element(c.heights.begin(), c.heights.begin() + k, c.heights.end());
    out.object_bottom.push_back(c.heights[k]);
  }
}

}  // namespace

double KolmogorovSmirnov(std::vector<double> a, std::vector<double> b) {
  const auto drop_nan = [](std::vector<double>& v) {
    v.erase(std::remove_if(v.begin(), v.end(),
                           [](double x) { return std::isnan(x); }),
            v.end());
    std::sort(v.begin(), v.end());
  };
  drop_nan(a);
  drop_nan(b);
  if (a.empty() || b.empty()) return kNaN;
  size_t i = 0, j = 0;
  double best = 0.0;
  while (i < a.size() && j < b.size()) {
    // Step past every copy of the smaller value on both sides at once, so
    // that ties do not open a gap that is not there.
    const double x = std::min(a[i], b[j]);
    while (i < a.size() && a[i] == x) ++i;
    while (j < b.size() && b[j] == x) ++j;
    const double fa = static_cast<double>(i) / a.size();
    const double fb = static_cast<double>(j) / b.size();
    best = std::max(best, std::abs(fa - fb));
  }
  return best;
}

RealismSamples CollectRealismSamples(const OrganizedCloud& cloud,
                                     const SupportPlane& plane,
                                     const TableScene& table,
                                     const cv::Mat& labels,
                                     const RealismOptions& options) {
  RealismSamples out;
  const bool have_inliers = plane.inliers.size() == cloud.xyz.size();
  if (have_inliers) {
    SamplePlaneNoise(cloud, plane.inliers, options, out);
    SampleMissingDepth(cloud,
                       SupportImageHull(plane.inliers, options.hull_erode_px),
                       options, out);
    SampleNormals(cloud, plane, options, out);
  }
  const int region = table.region.empty() ? 0 : cv::countNonZero(table.region);
  out.table_share = region > 0 && have_inliers
                        ? static_cast<double>(plane.inlier_count) / region
                        : kNaN;
  if (labels.type() == CV_32SC1 && labels.size() == cloud.xyz.size() &&
      table.region.size() == labels.size()) {
    SampleObjects(table, labels, out);
  }
  return out;
}

const std::vector<std::string>& RealismStatisticNames() {
  static const std::vector<std::string>* names = new std::vector<std::string>{
      "plane_noise",      "plane_noise_depth", "missing_fraction",
      "missing_at_edges", "missing_on_dark",   "normal_angle",
      "table_share",      "object_in_scene",   "object_standing",
      "object_bottom"};
  return *names;
}

void AddToSet(const RealismSamples& samples, RealismSet& set) {
  set.statistics.resize(kStatisticCount);
  auto append = [&set](Statistic s, const std::vector<double>& values) {
    set.statistics[s].insert(set.statistics[s].end(), values.begin(),
                             values.end());
  };
  append(kPlaneNoise, samples.plane_noise);
  append(kPlaneNoiseDepth, samples.plane_noise_depth);
  set.statistics[kMissingFraction].push_back(samples.missing_fraction);
  set.statistics[kMissingAtEdges].push_back(samples.missing_at_edges);
  set.statistics[kMissingOnDark].push_back(samples.missing_on_dark);
  append(kNormalAngle, samples.normal_angle);
  set.statistics[kTableShare].push_back(samples.table_share);
  append(kObjectInScene, samples.object_in_scene);
  append(kObjectStanding, samples.object_standing);
  append(kObjectBottom, samples.object_bottom);
  ++set.frames;
}

std::vector<RealismDistance> CompareRealism(
    const RealismSet& real, const RealismSet& synthetic,
    const std::vector<std::string>& relation_names) {
  std::vector<RealismDistance> rows;
  auto add = [&rows](const std::string& name, const std::vector<double>& a,
                     const std::vector<double>& b) {
    RealismDistance d;
    d.statistic = name;
    d.real_samples = CountValid(a);
    d.synthetic_samples = CountValid(b);
    d.real_median = Median(a);
    d.synthetic_median = Median(b);
    d.ks = KolmogorovSmirnov(a, b);
    rows.push_back(d);
  };
  static const std::vector<double> kNone;
  const auto stat = [](const RealismSet& s,
                       size_t k) -> const std::vector<double>& {
    return k < s.statistics.size() ? s.statistics[k] : kNone;
  };
  const std::vector<std::string>& names = RealismStatisticNames();
  for (size_t k = 0; k < names.size(); ++k) {
    add(names[k], stat(real, k), stat(synthetic, k));
  }
  add("patches_per_object", real.patches_per_object,
      synthetic.patches_per_object);
  const auto column = [](const std::vector<std::vector<double>>& pairs,
                         size_t f) {
    std::vector<double> values;
    values.reserve(pairs.size());
    for (const auto& x : pairs) {
      if (f < x.size()) values.push_back(x[f]);
    }
    return values;
  };
  for (size_t f = 0; f < relation_names.size(); ++f) {
    add("same." + relation_names[f], column(real.same_relations, f),
        column(synthetic.same_relations, f));
  }
  for (size_t f = 0; f < relation_names.size(); ++f) {
    add("different." + relation_names[f], column(real.different_relations, f),
        column(synthetic.different_relations, f));
  }
  return rows;
}

RealismSummary SummarizeRealism(const std::vector<RealismDistance>& rows,
                                const std::string& prefix) {
  RealismSummary s;
  double sum = 0.0;
  s.max_ks = -1.0;
  for (const RealismDistance& r : rows) {
    if (r.statistic.compare(0, prefix.size(), prefix) != 0) continue;
    if (std::isnan(r.ks)) continue;
    ++s.rows;
    sum += r.ks;
    if (r.ks > s.max_ks) {
      s.max_ks = r.ks;
      s.worst = r.statistic;
    }
  }
  if (s.rows == 0) {
    s.mean_ks = s.max_ks = kNaN;
    return s;
  }
  s.mean_ks = sum / s.rows;
  return s;
}

}  // namespace fovea
