#include "core/frame/osd_pcd.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/PCLPointField.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <new>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "core/base/check.h"
#include "core/frame/frame_decode.h"

namespace fovea {
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
  uint8_t datatype = 0;  // pcl::PCLPointField::PointFieldTypes
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

size_t TypeSize(uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
    case pcl::PCLPointField::UINT8:
      return 1;
    case pcl::PCLPointField::INT16:
    case pcl::PCLPointField::UINT16:
      return 2;
    case pcl::PCLPointField::INT32:
    case pcl::PCLPointField::UINT32:
    case pcl::PCLPointField::FLOAT32:
      return 4;
    case pcl::PCLPointField::FLOAT64:
      return 8;
    default:
      return 0;
  }
}

template <typename T>
T Load(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

float ReadFloat(const uint8_t* point, const FieldReader& field) {
  const uint8_t* p = point + field.offset;
  return field.datatype == pcl::PCLPointField::FLOAT32
             ? Load<float>(p)
             : static_cast<float>(Load<double>(p));
}

int32_t ReadInteger(const uint8_t* point, const FieldReader& field) {
  const uint8_t* p = point + field.offset;
  switch (field.datatype) {
    case pcl::PCLPointField::INT8:
      return Load<int8_t>(p);
    case pcl::PCLPointField::UINT8:
      return Load<uint8_t>(p);
    case pcl::PCLPointField::INT16:
      return Load<int16_t>(p);
    case pcl::PCLPointField::UINT16:
      return Load<uint16_t>(p);
    case pcl::PCLPointField::INT32:
      return Load<int32_t>(p);
    case pcl::PCLPointField::UINT32:
      return static_cast<int32_t>(Load<uint32_t>(p));
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

const pcl::PCLPointField* FindField(const pcl::PCLPointCloud2& cloud,
                                    const std::string& name) {
  for (const pcl::PCLPointField& field : cloud.fields) {
    if (field.name == name) return &field;
  }
  return nullptr;
}

// Finds the fields LoadOsdPcd reads and checks they fit in a point.
absl::StatusOr<CloudFields> ResolveFields(const pcl::PCLPointCloud2& cloud,
                                          const std::string& path) {
  auto resolve = [&](const pcl::PCLPointField& field,
                     bool (*type_ok)(uint8_t)) -> absl::StatusOr<FieldReader> {
    const size_t size = TypeSize(field.datatype);
    if (!type_ok(field.datatype) || field.count < 1 ||
        field.offset + size > cloud.point_step) {
      return absl::InvalidArgumentError(absl::StrCat(
          path, ": field '", field.name, "' has type ", field.datatype,
          ", count ", field.count, " at offset ", field.offset,
          " in a point of ", cloud.point_step, " bytes; not readable"));
    }
    return FieldReader{field.offset, field.datatype};
  };
  auto is_float = [](uint8_t t) {
    return t == pcl::PCLPointField::FLOAT32 || t == pcl::PCLPointField::FLOAT64;
  };
  auto is_integer = [](uint8_t t) {
    return t >= pcl::PCLPointField::INT8 && t <= pcl::PCLPointField::UINT32;
  };
  auto is_four_bytes = [](uint8_t t) { return TypeSize(t) == 4; };

  CloudFields fields;
  FieldReader* xyz[] = {&fields.x, &fields.y, &fields.z};
  const char* xyz_names[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    const pcl::PCLPointField* field = FindField(cloud, xyz_names[i]);
    if (field == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat(path, ": no '", xyz_names[i], "' field"));
    }
    absl::StatusOr<FieldReader> reader = resolve(*field, is_float);
    if (!reader.ok()) return reader.status();
    *xyz[i] = *reader;
  }
  if (const pcl::PCLPointField* label = FindField(cloud, "label")) {
    absl::StatusOr<FieldReader> reader = resolve(*label, is_integer);
    if (!reader.ok()) return reader.status();
    fields.label = *reader;
  }
  const pcl::PCLPointField* color = FindField(cloud, "rgba");
  if (color == nullptr) color = FindField(cloud, "rgb");
  if (color != nullptr) {
    absl::StatusOr<FieldReader> reader = resolve(*color, is_four_bytes);
    if (!reader.ok()) return reader.status();
    fields.color = *reader;
  }
  return fields;
}

// PCD header sanity limits: a real header is a few hundred bytes, and
// PCL's reader trusts the header, so everything it will index by is
// checked here first.
constexpr size_t kMaxPcdHeaderBytes = 64 * 1024;
constexpr uint64_t kMaxPcdFields = 1024;
constexpr uint64_t kMaxPcdFieldCount = 1 << 20;
constexpr uint64_t kMaxPcdDataBytes = uint64_t{1} << 30;

absl::Status PcdError(const std::string& path, absl::string_view what) {
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": not a readable PCD file (", what, ")"));
}

bool ParseCounts(const std::vector<absl::string_view>& tokens, uint64_t max,
                 std::vector<uint64_t>& out) {
  out.clear();
  for (size_t i = 1; i < tokens.size(); ++i) {
    uint64_t value = 0;
    if (!absl::SimpleAtoi(tokens[i], &value) || value == 0 || value > max) {
      return false;
    }
    out.push_back(value);
  }
  return true;
}

// PCL's PCDReader::readHeader goes on reading header lines after DATA:
// empty lines and comments are skipped and a line whose first word starts
// with a keyword ("FIELDSx" counts) is taken as header, until any other
// line. So a body starting e.g. "FIELDS a" re-declares the cloud behind
// CheckPcdFile's back, and PCL's ASCII reader then reads freed memory.
// Refuses such a body, reading `in` line by line from `pos`, where the line
// after DATA starts, as PCL does.
absl::Status CheckNoHeaderAfterData(const std::string& path, std::istream& in,
                                    size_t pos) {
  static constexpr absl::string_view kKeywords[] = {
      "VERSION", "FIELDS", "COLUMNS",   "SIZE",   "TYPE", "COUNT",
      "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
  in.clear();
  in.seekg(static_cast<std::streamoff>(pos));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    // PCL's first word: `stream >> word`, i.e. after leading white space.
    const absl::string_view rest = absl::StripLeadingAsciiWhitespace(line);
    const absl::string_view word =
        rest.substr(0, rest.find_first_of(" \t\n\v\f\r"));
    if (absl::StartsWith(word, "#")) continue;
    for (const absl::string_view keyword : kKeywords) {
      if (absl::StartsWith(word, keyword)) {
        return PcdError(path,
                        absl::StrCat("header line '", keyword, "' after DATA"));
      }
    }
    return absl::OkStatus();
  }
  return absl::OkStatus();
}

// Checks what PCL's PCDReader assumes without checking (it reads past its
// buffers on some malformed files): a complete v0.7 header whose field
// sizes, types and counts agree, WIDTH x HEIGHT = POINTS, no header line
// after DATA (CheckNoHeaderAfterData), and enough bytes
// after DATA for a binary or binary_compressed body.
absl::Status CheckPcdFile(const std::string& path, uint64_t file_size) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return PcdError(path, "cannot open");
  std::string head(std::min<uint64_t>(file_size, kMaxPcdHeaderBytes), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));

  size_t fields = 0;
  std::vector<uint64_t> sizes, counts;
  std::vector<char> types;
  uint64_t width = 0, height = 1, points = 0;
  bool has_width = false, has_points = false;
  std::string data_kind;
  size_t pos = 0;
  while (data_kind.empty()) {
    const size_t end = head.find('\n', pos);
    if (end == std::string::npos) return PcdError(path, "no DATA line");
    const absl::string_view line(head.data() + pos, end - pos);
    pos = end + 1;
    const std::vector<absl::string_view> tokens =
        absl::StrSplit(line, absl::ByAnyChar(" \t\r"), absl::SkipEmpty());
    if (line.empty()) continue;
    if (tokens.empty()) {
      // PCL's readHeader stops at such a line and reads on with what it
      // has (no POINTS: it dereferences a null pointer).
      return PcdError(path, "a header line of only white space");
    }
    if (absl::StartsWith(tokens[0], "#")) continue;
    const absl::string_view key = tokens[0];
    const size_t values = tokens.size() - 1;
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS") {
      fields = values;
      if (fields == 0 || fields > kMaxPcdFields) {
        return PcdError(path, "bad FIELDS");
      }
      counts.assign(fields, 1);
    } else if (key == "SIZE") {
      if (values != fields || !ParseCounts(tokens, 8, sizes)) {
        return PcdError(path, "SIZE does not match FIELDS");
      }
    } else if (key == "TYPE") {
      if (values != fields || sizes.size() != fields) {
        return PcdError(path, "TYPE does not match FIELDS and SIZE");
      }
      types.clear();
      for (size_t i = 0; i < fields; ++i) {
        const absl::string_view type = tokens[i + 1];
        const uint64_t size = sizes[i];
        const bool ok = (type == "F" && (size == 4 || size == 8)) ||
                        ((type == "I" || type == "U") &&
                         (size == 1 || size == 2 || size == 4));
        if (!ok) return PcdError(path, "unsupported TYPE and SIZE");
        types.push_back(type[0]);
      }
    } else if (key == "COUNT") {
      if (values != fields || !ParseCounts(tokens, kMaxPcdFieldCount, counts)) {
        return PcdError(path, "COUNT does not match FIELDS");
      }
    } else if (key == "WIDTH") {
      has_width = values == 1 && absl::SimpleAtoi(tokens[1], &width);
      if (!has_width) return PcdError(path, "bad WIDTH");
    } else if (key == "HEIGHT") {
      if (values != 1 || !absl::SimpleAtoi(tokens[1], &height)) {
        return PcdError(path, "bad HEIGHT");
      }
    } else if (key == "POINTS") {
      has_points = values == 1 && absl::SimpleAtoi(tokens[1], &points);
      if (!has_points) return PcdError(path, "bad POINTS");
    } else if (key == "DATA") {
      if (values != 1 || (tokens[1] != "ascii" && tokens[1] != "binary" &&
                          tokens[1] != "binary_compressed")) {
        return PcdError(path, "DATA is not ascii, binary or binary_compressed");
      }
      data_kind = std::string(tokens[1]);
    } else {
      return PcdError(path,
                      absl::StrCat("unknown header line '",
                                   absl::CHexEscape(key.substr(0, 16)), "'"));
    }
  }
  absl::Status after_data = CheckNoHeaderAfterData(path, in, pos);
  if (!after_data.ok()) return after_data;
  if (fields == 0 || sizes.size() != fields || types.size() != fields) {
    return PcdError(path, "FIELDS, SIZE or TYPE missing");
  }
  if (!has_width || !has_points || width == 0 || height == 0 ||
      width > kMaxPcdDataBytes || height > kMaxPcdDataBytes ||
      width * height != points) {
    return PcdError(path, absl::StrCat("WIDTH ", width, " x HEIGHT ", height,
                                       " is not POINTS ", points));
  }
  uint64_t point_step = 0;
  for (size_t i = 0; i < fields; ++i) point_step += sizes[i] * counts[i];
  if (point_step > kMaxPcdDataBytes / points) {
    return PcdError(path, "too large");
  }
  const uint64_t data_bytes = points * point_step;
  const uint64_t body = file_size - std::min<uint64_t>(pos, file_size);
  // PCL allocates POINTS x point step before reading an ASCII body; each
  // value there takes at least one character and a separator.
  uint64_t values = 0;
  for (size_t i = 0; i < fields; ++i) values += counts[i];
  if (data_kind == "ascii" && body + 1 < 2 * values * points) {
    return PcdError(path,
                    absl::StrCat(body, " bytes of ASCII data for ", points,
                                 " points of ", values, " values"));
  }
  if (data_kind == "binary" && body < data_bytes) {
    return PcdError(path, absl::StrCat(body, " bytes of binary data, ",
                                       data_bytes, " expected"));
  }
  if (data_kind == "binary_compressed") {
    unsigned char sizes_le[8] = {};
    in.clear();
    in.seekg(static_cast<std::streamoff>(pos));
    in.read(reinterpret_cast<char*>(sizes_le), sizeof(sizes_le));
    if (body < sizeof(sizes_le) || in.gcount() != sizeof(sizes_le)) {
      return PcdError(path, "truncated compressed data");
    }
    uint32_t compressed = 0, uncompressed = 0;
    for (int i = 3; i >= 0; --i) {
      compressed = (compressed << 8) | sizes_le[i];
      uncompressed = (uncompressed << 8) | sizes_le[4 + i];
    }
    if (uncompressed != data_bytes || compressed == 0 ||
        compressed > body - sizeof(sizes_le)) {
      return PcdError(
          path,
          absl::StrCat("compressed data of ", compressed, " -> ", uncompressed,
                       " bytes; ", data_bytes, " expected from ",
                       body - sizeof(sizes_le), " available"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<pcl::PCLPointCloud2> ReadCloud(const std::string& path) {
  std::error_code error;
  const std::filesystem::file_status status =
      std::filesystem::status(path, error);
  if (!std::filesystem::exists(status)) {
    return absl::NotFoundError(absl::StrCat(path, ": no such file"));
  }
  if (!std::filesystem::is_regular_file(status)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": not a file"));
  }
  const uint64_t file_size = std::filesystem::file_size(path, error);
  if (error) return PcdError(path, error.message());
  absl::Status header = CheckPcdFile(path, file_size);
  if (!header.ok()) return header;
  pcl::PCLPointCloud2 cloud;
  int result = -1;
  try {
    pcl::PCDReader reader;
    result = reader.read(path, cloud);
  } catch (const std::bad_alloc&) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": not a readable PCD file (out of memory)"));
  } catch (const std::exception& e) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": not a readable PCD file (", e.what(), ")"));
  }
  if (result < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": not a readable PCD file (PCL error ", result, ")"));
  }
  if (cloud.is_bigendian) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": big-endian clouds are not supported"));
  }
  const uint64_t width = cloud.width;
  const uint64_t height = cloud.height;
  if (width == 0 || height == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": the cloud has no points (", width, " x ", height, ")"));
  }
  if (height > 1 && (width > kMaxImageSide || height > kMaxImageSide)) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": organized cloud of ", width, " x ", height,
                     " exceeds ", kMaxImageSide, " on a side"));
  }
  if (cloud.row_step < width * cloud.point_step ||
      cloud.data.size() < uint64_t{cloud.row_step} * height) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": ", cloud.data.size(), " bytes of data for ",
                     width, " x ", height, " points of ", cloud.point_step,
                     " bytes (row step ", cloud.row_step, ")"));
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
void CopyOrganized(const pcl::PCLPointCloud2& cloud, const CloudFields& fields,
                   LabelledFrame& out) {
  const int width = static_cast<int>(cloud.width);
  const int height = static_cast<int>(cloud.height);
  AllocateFrame(width, height, out);
  const bool has_color = fields.color.has_value();
  for (int v = 0; v < height; ++v) {
    const uint8_t* row = cloud.data.data() + size_t{cloud.row_step} * v;
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
void ProjectUnorganized(const pcl::PCLPointCloud2& cloud,
                        const CloudFields& fields, const Intrinsics& intrinsics,
                        int width, int height, LabelledFrame& out) {
  AllocateFrame(width, height, out);
  const bool has_color = fields.color.has_value();
  // ReadCloud and LoadOsdPcdUnguarded: unorganized means height 1.
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

absl::StatusOr<LabelledFrame> LoadOsdPcdUnguarded(const std::string& path,
                                                  const Intrinsics& intrinsics,
                                                  int width, int height) {
  absl::Status status = ValidateIntrinsics(intrinsics, "intrinsics");
  if (!status.ok()) return status;
  absl::StatusOr<pcl::PCLPointCloud2> cloud = ReadCloud(path);
  if (!cloud.ok()) return cloud.status();
  absl::StatusOr<CloudFields> fields = ResolveFields(*cloud, path);
  if (!fields.ok()) return fields.status();

  LabelledFrame out;
  out.name = std::filesystem::path(path).stem().string();
  out.frame.intrinsics = intrinsics;
  if (cloud->height > 1) {
    CopyOrganized(*cloud, *fields, out);
    return out;
  }
  if (width < 1 || height < 1 || width > kMaxImageSide ||
      height > kMaxImageSide) {
    return absl::InvalidArgumentError(absl::StrCat(
        "width x height: ", width, " x ", height, " is not in [1, ",
        kMaxImageSide, "] for re-organizing ", path));
  }
  ProjectUnorganized(*cloud, *fields, intrinsics, width, height, out);
  return out;
}

}  // namespace

absl::StatusOr<LabelledFrame> LoadOsdPcd(const std::string& path,
                                         const Intrinsics& intrinsics,
                                         int width, int height) {
  try {
    return LoadOsdPcdUnguarded(path, intrinsics, width, height);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(
        absl::StrCat(path, ": out of memory loading the cloud"));
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat(path, ": ", e.what()));
  }
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
