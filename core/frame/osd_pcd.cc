#include "core/frame/osd_pcd.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <new>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"
#include "core/frame/frame_decode.h"
#include "core/frame/pcd_reader.h"

namespace fovea {

cv::Mat ObjectIdImage(const cv::Mat& labels) {
  cv::Mat ids(labels.size(), CV_32SC1);
  for (int v = 0; v < labels.rows; ++v) {
    const int* in = labels.ptr<int>(v);
    int* out = ids.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) out[u] = ObjectId(in[u]);
  }
  return ids;
}
namespace {

// Colour of a pixel whose colour is unknown: the file has no rgb/rgba
// field, or (unorganized clouds) no point landed there.
constexpr unsigned char kUnknownGrey = 128;
// Largest image side accepted from a file or for re-organizing; keeps
// every cv::Mat byte count inside an int.
constexpr int kMaxImageSide = 1 << 15;

// Where one scalar of every point lives and how it is stored.
struct FieldReader {
  size_t offset = 0;
  PcdType type = PcdType::kFloat32;
};

struct CloudFields {
  FieldReader x, y, z;
  std::optional<FieldReader> label;
  std::optional<FieldReader> color;  // packed 0x00RRGGBB in 4 bytes
};

// One point, whatever its storage.
struct Point {
  float x = 0.0f;
  float y = 0.0f;
  float z = 0.0f;
  int32_t label = 0;
  uint32_t rgb = 0;
};

template <typename T>
T Load(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

float ReadFloat(const uint8_t* point, const FieldReader& field) {
  const uint8_t* p = point + field.offset;
  return field.type == PcdType::kFloat32 ? Load<float>(p)
                                         : static_cast<float>(Load<double>(p));
}

int32_t ReadInteger(const uint8_t* point, const FieldReader& field) {
  const uint8_t* p = point + field.offset;
  switch (field.type) {
    case PcdType::kInt8:
      return Load<int8_t>(p);
    case PcdType::kUint8:
      return Load<uint8_t>(p);
    case PcdType::kInt16:
      return Load<int16_t>(p);
    case PcdType::kUint16:
      return Load<uint16_t>(p);
    case PcdType::kInt32:
      return Load<int32_t>(p);
    case PcdType::kUint32:
      return static_cast<int32_t>(Load<uint32_t>(p));
    case PcdType::kInt64:
      return static_cast<int32_t>(Load<int64_t>(p));
    case PcdType::kUint64:
      return static_cast<int32_t>(Load<uint64_t>(p));
    default:
      FOVEA_CHECK(false);  // ResolveFields admits integer labels only
      return 0;
  }
}

Point ReadPoint(const uint8_t* point, const CloudFields& fields) {
  Point result;
  result.x = ReadFloat(point, fields.x);
  result.y = ReadFloat(point, fields.y);
  result.z = ReadFloat(point, fields.z);
  if (fields.label) result.label = ReadInteger(point, *fields.label);
  if (fields.color) result.rgb = Load<uint32_t>(point + fields.color->offset);
  return result;
}

// Finds the fields LoadOsdPcd reads and checks they fit in a point.
absl::StatusOr<CloudFields> ResolveFields(const PcdCloud& cloud,
                                          const std::string& path) {
  auto resolve = [&](const PcdField& field, bool (*type_ok)(PcdType),
                     absl::string_view wanted) -> absl::StatusOr<FieldReader> {
    // ReadPcd packs every field inside its point.
    FOVEA_CHECK(field.offset + PcdTypeSize(field.type) <= cloud.point_step);
    if (!type_ok(field.type)) {
      return absl::InvalidArgumentError(absl::StrCat(
          path, ": field '", field.name, "' has type ",
          static_cast<int>(field.type), " of ", PcdTypeSize(field.type),
          " bytes; not readable (", wanted, " expected)"));
    }
    return FieldReader{field.offset, field.type};
  };
  auto is_float = [](PcdType t) {
    return t == PcdType::kFloat32 || t == PcdType::kFloat64;
  };
  auto is_integer = [](PcdType t) {
    return t != PcdType::kFloat32 && t != PcdType::kFloat64;
  };
  auto is_four_bytes = [](PcdType t) { return PcdTypeSize(t) == 4; };

  CloudFields fields;
  FieldReader* xyz[] = {&fields.x, &fields.y, &fields.z};
  const char* xyz_names[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    const PcdField* field = FindPcdField(cloud, xyz_names[i]);
    if (field == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat(path, ": no '", xyz_names[i], "' field"));
    }
    FOVEA_ASSIGN_OR_RETURN(FieldReader reader,
                           resolve(*field, is_float, "TYPE F"));
    *xyz[i] = reader;
  }
  if (const PcdField* label = FindPcdField(cloud, "label")) {
    FOVEA_ASSIGN_OR_RETURN(FieldReader reader,
                           resolve(*label, is_integer, "TYPE I or U"));
    fields.label = reader;
  }
  const PcdField* color = FindPcdField(cloud, "rgba");
  if (color == nullptr) color = FindPcdField(cloud, "rgb");
  if (color != nullptr) {
    FOVEA_ASSIGN_OR_RETURN(FieldReader reader,
                           resolve(*color, is_four_bytes, "SIZE 4"));
    fields.color = reader;
  }
  return fields;
}

// Reads the cloud and checks that an organized one fits an image.
absl::StatusOr<PcdCloud> ReadCloud(const std::string& path) {
  FOVEA_ASSIGN_OR_RETURN(PcdCloud cloud, ReadPcd(path));
  // ReadPcd: width, height >= 1 and data of width x height points.
  FOVEA_CHECK(cloud.width >= 1 && cloud.height >= 1 &&
              cloud.data.size() ==
                  uint64_t{cloud.width} * cloud.height * cloud.point_step);
  if (cloud.height > 1 &&
      (cloud.width > kMaxImageSide || cloud.height > kMaxImageSide)) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": organized cloud of ", cloud.width, " x ",
                     cloud.height, " exceeds ", kMaxImageSide, " on a side"));
  }
  return cloud;
}

bool HasDepth(const Point& point) {
  return point.z > 0.0f && point.z < std::numeric_limits<float>::infinity();
}

void AllocateFrame(int width, int height, LabelledFrame& out) {
  out.frame.depth.create(height, width, CV_32FC1);
  out.frame.depth.setTo(std::numeric_limits<float>::quiet_NaN());
  out.frame.color.create(height, width, CV_8UC3);
  out.frame.color.setTo(cv::Scalar::all(kUnknownGrey));
  out.labels = cv::Mat::zeros(height, width, CV_32SC1);
}

// Organized cloud: point (u, v) becomes pixel (u, v).
void CopyOrganized(const PcdCloud& cloud, const CloudFields& fields,
                   LabelledFrame& out) {
  const int width = static_cast<int>(cloud.width);
  const int height = static_cast<int>(cloud.height);
  AllocateFrame(width, height, out);
  const bool has_color = fields.color.has_value();
  for (int v = 0; v < height; ++v) {
    const uint8_t* row =
        cloud.data.data() + size_t{cloud.point_step} * cloud.width * v;
    float* depth = out.frame.depth.ptr<float>(v);
    int32_t* labels = out.labels.ptr<int32_t>(v);
    unsigned char* color = out.frame.color.ptr<unsigned char>(v);
    for (int u = 0; u < width; ++u) {
      const Point point = ReadPoint(row + size_t{cloud.point_step} * u, fields);
      depth[u] =
          HasDepth(point) ? point.z : std::numeric_limits<float>::quiet_NaN();
      labels[u] = point.label;
      if (has_color) {
        color[3 * u] = static_cast<unsigned char>(point.rgb >> 16);
        color[3 * u + 1] = static_cast<unsigned char>(point.rgb >> 8);
        color[3 * u + 2] = static_cast<unsigned char>(point.rgb);
      }
    }
  }
}

// Unorganized cloud: each point is projected to its nearest pixel centre,
// the nearest point (smallest z) of a pixel winning.
void ProjectUnorganized(const PcdCloud& cloud, const CloudFields& fields,
                        const Intrinsics& intrinsics, int width, int height,
                        LabelledFrame& out) {
  AllocateFrame(width, height, out);
  const bool has_color = fields.color.has_value();
  // ReadCloud and LoadOsdPcd: unorganized means height 1.
  FOVEA_CHECK(cloud.height == 1);
  for (size_t i = 0; i < cloud.width; ++i) {
    const Point point =
        ReadPoint(cloud.data.data() + i * cloud.point_step, fields);
    if (!HasDepth(point) || !std::isfinite(point.x) ||
        !std::isfinite(point.y)) {
      continue;
    }
    const double u =
        std::floor(intrinsics.fx * point.x / point.z + intrinsics.cx + 0.5);
    const double v =
        std::floor(intrinsics.fy * point.y / point.z + intrinsics.cy + 0.5);
    if (!(u >= 0.0 && u < width && v >= 0.0 && v < height)) continue;
    const int pu = static_cast<int>(u);
    const int pv = static_cast<int>(v);
    float& depth = out.frame.depth.ptr<float>(pv)[pu];
    if (!std::isnan(depth) && depth <= point.z) continue;
    depth = point.z;
    out.labels.ptr<int32_t>(pv)[pu] = point.label;
    if (has_color) {
      unsigned char* color = out.frame.color.ptr<unsigned char>(pv) + 3 * pu;
      color[0] = static_cast<unsigned char>(point.rgb >> 16);
      color[1] = static_cast<unsigned char>(point.rgb >> 8);
      color[2] = static_cast<unsigned char>(point.rgb);
    }
  }
}

// Compares names with runs of digits taken as numbers: "learn2" <
// "learn10"; ties (e.g. "a01" vs "a1") fall back to plain comparison.
bool NaturalLess(const std::string& a, const std::string& b) {
  size_t i = 0;
  size_t j = 0;
  while (i < a.size() && j < b.size()) {
    if (absl::ascii_isdigit(a[i]) && absl::ascii_isdigit(b[j])) {
      size_t a_end = i;
      size_t b_end = j;
      while (a_end < a.size() && absl::ascii_isdigit(a[a_end])) ++a_end;
      while (b_end < b.size() && absl::ascii_isdigit(b[b_end])) ++b_end;
      size_t a_start = i;
      size_t b_start = j;
      while (a_start + 1 < a_end && a[a_start] == '0') ++a_start;
      while (b_start + 1 < b_end && b[b_start] == '0') ++b_start;
      const size_t a_digits = a_end - a_start;
      const size_t b_digits = b_end - b_start;
      if (a_digits != b_digits) return a_digits < b_digits;
      const int order = a.compare(a_start, a_digits, b, b_start, b_digits);
      if (order != 0) return order < 0;
      i = a_end;
      j = b_end;
      continue;
    }
    if (a[i] != b[j]) return a[i] < b[j];
    ++i;
    ++j;
  }
  if (a.size() - i != b.size() - j) return a.size() - i < b.size() - j;
  return a < b;
}

}  // namespace

absl::StatusOr<LabelledFrame> LoadOsdPcd(const std::string& path,
                                         const Intrinsics& intrinsics,
                                         int width, int height) {
  absl::Status status = ValidateIntrinsics(intrinsics, "intrinsics");
  if (!status.ok()) return status;
  FOVEA_ASSIGN_OR_RETURN(PcdCloud cloud, ReadCloud(path));
  FOVEA_ASSIGN_OR_RETURN(CloudFields fields, ResolveFields(cloud, path));

  LabelledFrame out;
  out.name = std::filesystem::path(path).stem().string();
  out.frame.intrinsics = intrinsics;
  if (cloud.height > 1) {
    CopyOrganized(cloud, fields, out);
    return out;
  }
  if (width < 1 || height < 1 || width > kMaxImageSide ||
      height > kMaxImageSide) {
    return absl::InvalidArgumentError(absl::StrCat(
        "width x height: ", width, " x ", height, " is not in [1, ",
        kMaxImageSide, "] for re-organizing ", path));
  }
  ProjectUnorganized(cloud, fields, intrinsics, width, height, out);
  return out;
}

absl::StatusOr<std::vector<std::string>> ListPcdFiles(const std::string& dir) {
  std::error_code error;
  const std::filesystem::file_status status =
      std::filesystem::status(dir, error);
  if (!std::filesystem::exists(status)) {
    return absl::NotFoundError(absl::StrCat(dir, ": no such folder"));
  }
  if (!std::filesystem::is_directory(status)) {
    return absl::InvalidArgumentError(absl::StrCat(dir, ": not a folder"));
  }
  std::vector<std::string> names;
  std::filesystem::directory_iterator it(dir, error);
  for (; !error && it != std::filesystem::directory_iterator();
       it.increment(error)) {
    const std::filesystem::path& entry = it->path();
    if (absl::AsciiStrToLower(entry.extension().string()) != ".pcd") continue;
    if (!it->is_regular_file(error)) continue;
    names.push_back(entry.filename().string());
  }
  if (error) {
    return absl::UnavailableError(
        absl::StrCat(dir, ": cannot list: ", error.message()));
  }
  std::sort(names.begin(), names.end(), NaturalLess);
  std::vector<std::string> paths;
  paths.reserve(names.size());
  for (const std::string& name : names) {
    paths.push_back((std::filesystem::path(dir) / name).string());
  }
  return paths;
}

}  // namespace fovea
