#include "core/frame/pcd_reader.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <optional>
#include <set>
#include <string>
#include <system_error>
#include <type_traits>
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
#include "core/base/status_macros.h"
#include "core/frame/lzf.h"

namespace fovea {
namespace {

static_assert(std::endian::native == std::endian::little,
              "PCD data is little-endian; this reader copies it as is");

// Sanity limits: a real header is a few hundred bytes and an OSD scene
// holds 6 MB of points.
constexpr size_t kMaxPcdHeaderBytes = 64 * 1024;
constexpr uint64_t kMaxPcdFields = 1024;
constexpr uint64_t kMaxPcdFieldCount = 1 << 20;
constexpr uint64_t kMaxPcdDataBytes = uint64_t{1} << 30;
constexpr uint64_t kMaxPcdAsciiBytes = uint64_t{4} << 30;
// binary_compressed: uint32 compressed size and uint32 uncompressed size.
constexpr size_t kCompressedSizesBytes = 8;
// Longest ASCII token quoted in an error message.
constexpr size_t kMaxQuotedToken = 32;

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

// What the header says; every size in it checked against the limits.
struct PcdHeader {
  std::vector<PcdField> fields;
  uint64_t width = 0;
  uint64_t height = 0;
  uint64_t points = 0;      // width x height
  uint64_t point_step = 0;  // bytes per point
  uint64_t values = 0;      // scalars per point: the sum of COUNT
  PcdEncoding encoding = PcdEncoding::kAscii;
  uint64_t body_offset = 0;  // file byte after the DATA line
};

absl::Status PcdError(const std::string& path, absl::string_view what) {
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": not a readable PCD file (", what, ")"));
}

std::optional<PcdType> ParseType(absl::string_view letter, uint64_t size) {
  if (letter == "F") {
    if (size == 4) return PcdType::kFloat32;
    if (size == 8) return PcdType::kFloat64;
  } else if (letter == "I" || letter == "U") {
    const bool is_signed = letter == "I";
    switch (size) {
      case 1:
        return is_signed ? PcdType::kInt8 : PcdType::kUint8;
      case 2:
        return is_signed ? PcdType::kInt16 : PcdType::kUint16;
      case 4:
        return is_signed ? PcdType::kInt32 : PcdType::kUint32;
      case 8:
        return is_signed ? PcdType::kInt64 : PcdType::kUint64;
    }
  }
  return std::nullopt;
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

// Parses the header lines up to DATA in `head` (the file's first bytes)
// and checks that they describe a cloud within the limits.
absl::StatusOr<PcdHeader> ParseHeader(absl::string_view head,
                                      const std::string& path) {
  std::vector<std::string> names;
  std::vector<uint64_t> sizes, counts;
  std::vector<PcdType> types;
  uint64_t width = 0, height = 1, points = 0;
  bool has_width = false, has_points = false;
  std::optional<PcdEncoding> encoding;
  std::set<std::string> seen_keys;
  size_t pos = 0;
  while (!encoding.has_value()) {
    const size_t end = head.find('\n', pos);
    if (end == absl::string_view::npos) return PcdError(path, "no DATA line");
    const absl::string_view line = head.substr(pos, end - pos);
    pos = end + 1;
    const std::vector<absl::string_view> tokens =
        absl::StrSplit(line, absl::ByAnyChar(" \t\r"), absl::SkipEmpty());
    if (line.empty()) continue;
    if (tokens.empty()) {
      // PCL's reader ends its header at such a line and reads on with what
      // it has.
      return PcdError(path, "a header line of only white space");
    }
    if (absl::StartsWith(tokens[0], "#")) continue;
    const absl::string_view key = tokens[0];
    const size_t values = tokens.size() - 1;
    // Each line once: a second SIZE after TYPE would leave the types
    // (derived from the first) disagreeing with the point layout.
    if (!seen_keys.insert(std::string(key.substr(0, 16))).second) {
      return PcdError(path, absl::StrCat("header line '",
                                         absl::CHexEscape(key.substr(0, 16)),
                                         "' appears twice"));
    }
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS") {
      if (values == 0 || values > kMaxPcdFields) {
        return PcdError(path, "bad FIELDS");
      }
      names.clear();
      for (size_t i = 1; i < tokens.size(); ++i) {
        names.push_back(std::string(tokens[i]));
      }
      counts.assign(values, 1);
    } else if (key == "SIZE") {
      if (values != names.size() || !ParseCounts(tokens, 8, sizes)) {
        return PcdError(path, "SIZE does not match FIELDS");
      }
    } else if (key == "TYPE") {
      if (values != names.size() || sizes.size() != names.size()) {
        return PcdError(path, "TYPE does not match FIELDS and SIZE");
      }
      types.clear();
      for (size_t i = 0; i < values; ++i) {
        const std::optional<PcdType> type = ParseType(tokens[i + 1], sizes[i]);
        if (!type.has_value()) {
          return PcdError(
              path, absl::StrCat("unsupported TYPE '",
                                 absl::CHexEscape(tokens[i + 1].substr(0, 8)),
                                 "' and SIZE ", sizes[i], " of field '",
                                 absl::CHexEscape(names[i]), "'"));
        }
        types.push_back(*type);
      }
    } else if (key == "COUNT") {
      if (values != names.size() ||
          !ParseCounts(tokens, kMaxPcdFieldCount, counts)) {
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
      if (values == 1 && tokens[1] == "ascii") {
        encoding = PcdEncoding::kAscii;
      } else if (values == 1 && tokens[1] == "binary") {
        encoding = PcdEncoding::kBinary;
      } else if (values == 1 && tokens[1] == "binary_compressed") {
        encoding = PcdEncoding::kBinaryCompressed;
      } else {
        return PcdError(path, "DATA is not ascii, binary or binary_compressed");
      }
    } else {
      return PcdError(path,
                      absl::StrCat("unknown header line '",
                                   absl::CHexEscape(key.substr(0, 16)), "'"));
    }
  }
  const size_t fields = names.size();
  if (fields == 0 || sizes.size() != fields || types.size() != fields) {
    return PcdError(path, "FIELDS, SIZE or TYPE missing");
  }
  if (!has_width || !has_points || width == 0 || height == 0 ||
      width > kMaxPcdDataBytes || height > kMaxPcdDataBytes ||
      width * height != points) {
    return PcdError(path, absl::StrCat("WIDTH ", width, " x HEIGHT ", height,
                                       " is not POINTS ", points));
  }
  // At most 1024 fields x 8 bytes x 2^20: no overflow.
  uint64_t point_step = 0;
  for (size_t i = 0; i < fields; ++i) point_step += sizes[i] * counts[i];
  if (point_step > kMaxPcdDataBytes / points) {
    return PcdError(path, absl::StrCat("POINTS ", points, " of ", point_step,
                                       " bytes exceed the limit of ",
                                       kMaxPcdDataBytes, " bytes"));
  }
  PcdHeader header;
  header.width = width;
  header.height = height;
  header.points = points;
  header.point_step = point_step;
  header.encoding = *encoding;
  header.body_offset = pos;
  header.fields.resize(fields);
  uint64_t offset = 0;
  for (size_t i = 0; i < fields; ++i) {
    header.fields[i].name = std::move(names[i]);
    header.fields[i].type = types[i];
    header.fields[i].count = static_cast<uint32_t>(counts[i]);
    header.fields[i].offset = static_cast<uint32_t>(offset);
    offset += sizes[i] * counts[i];
    header.values += counts[i];
  }
  return header;
}

// PCL's PCDReader::readHeader goes on reading header lines after DATA:
// empty lines and comments are skipped and a line whose first word starts
// with a keyword ("FIELDSx" counts) is taken as header, until any other
// line. Such a file re-declares its cloud for PCL (whose ASCII reader then
// read freed memory) but not for ReadPcd; it is refused rather than read
// differently. `body` holds the bytes from where the line after DATA
// starts.
absl::Status CheckNoHeaderAfterData(absl::string_view body,
                                    const std::string& path) {
  static constexpr absl::string_view kKeywords[] = {
      "VERSION", "FIELDS", "COLUMNS",   "SIZE",   "TYPE", "COUNT",
      "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
  size_t pos = 0;
  while (pos < body.size()) {
    size_t end = body.find('\n', pos);
    if (end == absl::string_view::npos) end = body.size();
    const absl::string_view line = body.substr(pos, end - pos);
    pos = end + 1;
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

// Reads `size` bytes at byte `offset` of `in` into `out`.
bool ReadBytes(std::ifstream& in, uint64_t offset, size_t size, void* out) {
  in.clear();
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(static_cast<char*>(out), static_cast<std::streamsize>(size));
  return in && static_cast<size_t>(in.gcount()) == size;
}

// ASCII value `token` as a T, strtod-style for floating point (overflow
// gives infinity, underflow zero) and exact for integers; "nan" in any case
// is NaN, or 0 in an integer field, as PCL has it.
template <typename T>
bool ParseValue(absl::string_view token, T& value) {
  if (absl::EqualsIgnoreCase(token, "nan")) {
    value = std::numeric_limits<T>::quiet_NaN();
    return true;
  }
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' &&
      token[1] != '+') {
    token.remove_prefix(1);  // from_chars takes no '+'; strtod does
  }
  const char* first = token.data();
  const char* last = token.data() + token.size();
  std::from_chars_result result;
  if constexpr (std::is_floating_point_v<T>) {
    result = std::from_chars(first, last, value);
    if (result.ec == std::errc::result_out_of_range && result.ptr == last) {
      const std::string copy(token);
      char* end = nullptr;
      value = std::is_same_v<T, float> ? std::strtof(copy.c_str(), &end)
                                       : std::strtod(copy.c_str(), &end);
      return end == copy.c_str() + copy.size();
    }
  } else {
    result = std::from_chars(first, last, value);
  }
  return result.ec == std::errc() && result.ptr == last;
}

bool ParseValueAs(absl::string_view token, PcdType type, uint8_t* out) {
  auto parse = [&](auto value) {
    if (!ParseValue(token, value)) return false;
    std::memcpy(out, &value, sizeof(value));
    return true;
  };
  switch (type) {
    case PcdType::kInt8:
      return parse(int8_t{});
    case PcdType::kUint8:
      return parse(uint8_t{});
    case PcdType::kInt16:
      return parse(int16_t{});
    case PcdType::kUint16:
      return parse(uint16_t{});
    case PcdType::kInt32:
      return parse(int32_t{});
    case PcdType::kUint32:
      return parse(uint32_t{});
    case PcdType::kFloat32:
      return parse(float{});
    case PcdType::kFloat64:
      return parse(double{});
    case PcdType::kInt64:
      return parse(int64_t{});
    case PcdType::kUint64:
      return parse(uint64_t{});
  }
  return false;
}

bool IsAsciiSeparator(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// The next token of `line` from `pos` (advanced past it); empty at the end.
absl::string_view NextToken(absl::string_view line, size_t& pos) {
  while (pos < line.size() && IsAsciiSeparator(line[pos])) ++pos;
  const size_t start = pos;
  while (pos < line.size() && !IsAsciiSeparator(line[pos])) ++pos;
  return line.substr(start, pos - start);
}

// Decodes an ASCII body, the file's bytes from `header.body_offset` on.
absl::StatusOr<std::vector<uint8_t>> DecodeAscii(absl::string_view body,
                                                 const PcdHeader& header,
                                                 const std::string& path) {
  std::vector<uint8_t> data(header.points * header.point_step);
  uint64_t point = 0;
  size_t pos = 0;
  while (point < header.points && pos < body.size()) {
    const size_t line_start = pos;
    size_t end = body.find('\n', pos);
    if (end == absl::string_view::npos) end = body.size();
    const absl::string_view line = body.substr(pos, end - pos);
    pos = end + 1;
    size_t cursor = 0;
    const absl::string_view first = NextToken(line, cursor);
    if (first.empty() || first[0] == '#') continue;
    uint64_t tokens = 1;
    while (!NextToken(line, cursor).empty()) ++tokens;
    if (tokens != header.values) {
      return PcdError(
          path, absl::StrCat("ASCII line at byte ",
                             header.body_offset + line_start, " has ", tokens,
                             " values, ", header.values, " expected"));
    }
    uint8_t* out = data.data() + point * header.point_step;
    cursor = 0;
    for (const PcdField& field : header.fields) {
      const size_t size = PcdTypeSize(field.type);
      for (uint32_t c = 0; c < field.count; ++c) {
        const absl::string_view token = NextToken(line, cursor);
        if (field.name == "_") continue;  // padding: PCL leaves it 0
        if (!ParseValueAs(token, field.type, out + field.offset + c * size)) {
          const uint64_t at = header.body_offset + line_start +
                              static_cast<uint64_t>(token.data() - line.data());
          return PcdError(
              path, absl::StrCat(
                        "ASCII value '",
                        absl::CHexEscape(token.substr(0, kMaxQuotedToken)),
                        "' at byte ", at, " is not a number of field '",
                        absl::CHexEscape(field.name), "' (", size, " bytes)"));
        }
      }
    }
    ++point;
  }
  if (point < header.points) {
    return PcdError(path, absl::StrCat("ASCII data ends after ", point, " of ",
                                       header.points, " points"));
  }
  return data;
}

// Copies one field of `points` points from consecutive `bytes`-sized
// slots of `from` into slots `step` bytes apart at `to`.
template <size_t kBytes>
void ScatterFixed(const uint8_t* from, uint64_t points, uint64_t step,
                  uint8_t* to) {
  for (uint64_t i = 0; i < points; ++i) {
    std::memcpy(to + i * step, from + i * kBytes, kBytes);
  }
}

void Scatter(const uint8_t* from, uint64_t points, size_t bytes, uint64_t step,
             uint8_t* to) {
  switch (bytes) {
    case 1:
      return ScatterFixed<1>(from, points, step, to);
    case 2:
      return ScatterFixed<2>(from, points, step, to);
    case 4:
      return ScatterFixed<4>(from, points, step, to);
    case 8:
      return ScatterFixed<8>(from, points, step, to);
    default:
      for (uint64_t i = 0; i < points; ++i) {
        std::memcpy(to + i * step, from + i * bytes, bytes);
      }
  }
}

// Decodes LZF data holding the fields one after the other (structure of
// arrays) into points (array of structures). `compressed_offset` is the
// file byte where the LZF data starts.
absl::StatusOr<std::vector<uint8_t>> DecodeCompressed(
    absl::string_view compressed, uint64_t compressed_offset,
    const PcdHeader& header, const std::string& path) {
  const uint64_t data_bytes = header.points * header.point_step;
  absl::StatusOr<std::vector<uint8_t>> fields =
      LzfDecompress(compressed, data_bytes);
  if (!fields.ok()) {
    return PcdError(
        path, absl::StrCat("binary_compressed data at byte ", compressed_offset,
                           ": ", fields.status().message()));
  }
  std::vector<uint8_t> data(data_bytes);
  for (const PcdField& field : header.fields) {
    // The fields before this one fill `offset` bytes for every point.
    Scatter(fields->data() + header.points * field.offset, header.points,
            PcdTypeSize(field.type) * field.count, header.point_step,
            data.data() + field.offset);
  }
  return data;
}

}  // namespace

absl::StatusOr<PcdCloud> ReadPcd(const std::string& path) {
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
  std::ifstream in(path, std::ios::binary);
  if (!in) return PcdError(path, "cannot open");
  std::string head(std::min<uint64_t>(file_size, kMaxPcdHeaderBytes), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  FOVEA_ASSIGN_OR_RETURN(PcdHeader header, ParseHeader(head, path));

  PcdCloud cloud;
  cloud.width = static_cast<uint32_t>(header.width);
  cloud.height = static_cast<uint32_t>(header.height);
  cloud.point_step = static_cast<uint32_t>(header.point_step);
  const uint64_t points = header.points;
  const uint64_t data_bytes = points * header.point_step;
  const uint64_t body_offset = header.body_offset;
  const uint64_t body = file_size - std::min(body_offset, file_size);
  switch (header.encoding) {
    case PcdEncoding::kAscii: {
      // Each value takes at least one character and a separator.
      if (body + 1 < 2 * header.values * points) {
        return PcdError(path,
                        absl::StrCat(body, " bytes of ASCII data for ", points,
                                     " points of ", header.values, " values"));
      }
      if (body > kMaxPcdAsciiBytes) {
        return PcdError(path, absl::StrCat(body, " bytes of ASCII data exceed ",
                                           kMaxPcdAsciiBytes));
      }
      std::string text(body, '\0');
      if (!ReadBytes(in, body_offset, text.size(), text.data())) {
        return PcdError(path, "ASCII data truncated while reading");
      }
      absl::Status after_data = CheckNoHeaderAfterData(text, path);
      if (!after_data.ok()) return after_data;
      FOVEA_ASSIGN_OR_RETURN(std::vector<uint8_t> data,
                             DecodeAscii(text, header, path));
      cloud.data = std::move(data);
      break;
    }
    case PcdEncoding::kBinary: {
      if (body < data_bytes) {
        return PcdError(path, absl::StrCat(body, " bytes of binary data, ",
                                           data_bytes, " expected"));
      }
      cloud.data.resize(data_bytes);
      if (!ReadBytes(in, body_offset, data_bytes, cloud.data.data())) {
        return PcdError(path, "binary data truncated while reading");
      }
      absl::Status after_data = CheckNoHeaderAfterData(
          absl::string_view(reinterpret_cast<const char*>(cloud.data.data()),
                            cloud.data.size()),
          path);
      if (!after_data.ok()) return after_data;
      break;
    }
    case PcdEncoding::kBinaryCompressed: {
      unsigned char sizes_le[kCompressedSizesBytes] = {};
      if (body < sizeof(sizes_le) ||
          !ReadBytes(in, body_offset, sizeof(sizes_le), sizes_le)) {
        return PcdError(path, "truncated compressed data");
      }
      uint32_t compressed = 0, uncompressed = 0;
      std::memcpy(&compressed, sizes_le, 4);
      std::memcpy(&uncompressed, sizes_le + 4, 4);
      const uint64_t available = body - sizeof(sizes_le);
      if (uncompressed != data_bytes || compressed == 0 ||
          compressed > available ||
          uncompressed > LzfMaxExpansion(compressed)) {
        return PcdError(
            path, absl::StrCat("compressed data of ", compressed, " -> ",
                               uncompressed, " bytes; ", data_bytes,
                               " expected from ", available, " available"));
      }
      std::string bytes(sizeof(sizes_le) + compressed, '\0');
      if (!ReadBytes(in, body_offset, bytes.size(), bytes.data())) {
        return PcdError(path, "compressed data truncated while reading");
      }
      absl::Status after_data = CheckNoHeaderAfterData(bytes, path);
      if (!after_data.ok()) return after_data;
      FOVEA_ASSIGN_OR_RETURN(
          std::vector<uint8_t> data,
          DecodeCompressed(absl::string_view(bytes).substr(sizeof(sizes_le)),
                           body_offset + sizeof(sizes_le), header, path));
      cloud.data = std::move(data);
      break;
    }
  }
  cloud.fields = std::move(header.fields);
  return cloud;
}

size_t PcdTypeSize(PcdType type) {
  switch (type) {
    case PcdType::kInt8:
    case PcdType::kUint8:
      return 1;
    case PcdType::kInt16:
    case PcdType::kUint16:
      return 2;
    case PcdType::kInt32:
    case PcdType::kUint32:
    case PcdType::kFloat32:
      return 4;
    case PcdType::kFloat64:
    case PcdType::kInt64:
    case PcdType::kUint64:
      return 8;
  }
  return 0;
}

const PcdField* FindPcdField(const PcdCloud& cloud, absl::string_view name) {
  for (const PcdField& field : cloud.fields) {
    if (field.name == name) return &field;
  }
  return nullptr;
}

}  // namespace fovea
