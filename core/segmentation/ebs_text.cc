// The text form of EbsModel: Serialize, Parse and Version (ebs.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/segmentation/ebs.h"

namespace fovea {
namespace {

constexpr char kMagic[] = "fovea-ebs-model";
constexpr int kFormatVersion = 1;

std::string FormatFloat(float value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.9g", static_cast<double>(value));
  return buffer;
}

uint32_t Fnv1a(std::string_view text) {
  uint32_t hash = 2166136261u;
  for (const char c : text) {
    hash ^= static_cast<uint8_t>(c);
    hash *= 16777619u;
  }
  return hash;
}

// Reads the text form line by line; errors name the line.
class LineReader {
 public:
  explicit LineReader(std::string_view text) {
    for (absl::string_view line : absl::StrSplit(AbslView(text), '\n')) {
      lines_.emplace_back(line.data(), line.size());
    }
    // One final newline is allowed.
    if (!lines_.empty() && lines_.back().empty()) lines_.pop_back();
  }

  // The next line's tokens (split at spaces), its first token `keyword`.
  absl::StatusOr<std::vector<std::string_view>> Next(std::string_view keyword) {
    if (next_ >= lines_.size()) {
      return Error(absl::StrCat("expected \"", AbslView(keyword),
                                "\" but the text ends (truncated?)"));
    }
    const std::string_view line = lines_[next_++];
    std::vector<std::string_view> tokens;
    for (absl::string_view t :
         absl::StrSplit(AbslView(line), ' ', absl::SkipEmpty())) {
      tokens.emplace_back(t.data(), t.size());
    }
    if (tokens.empty() || tokens[0] != keyword) {
      return Error(
          absl::StrCat("expected a line starting \"", AbslView(keyword), "\""));
    }
    return tokens;
  }

  // Reads "keyword k1 v1 k2 v2 ..." with exactly `keys`, in order, and
  // returns the values.
  absl::StatusOr<std::vector<std::string_view>> NextFields(
      std::string_view keyword, const std::vector<std::string_view>& keys) {
    FOVEA_ASSIGN_OR_RETURN(std::vector<std::string_view> tokens, Next(keyword));
    if (tokens.size() != 1 + 2 * keys.size()) {
      return Error(absl::StrCat("expected ", keys.size(), " fields"));
    }
    std::vector<std::string_view> values;
    for (size_t i = 0; i < keys.size(); ++i) {
      if ((tokens)[1 + 2 * i] != keys[i]) {
        return Error(
            absl::StrCat("expected field \"", AbslView(keys[i]), "\""));
      }
      values.push_back((tokens)[2 + 2 * i]);
    }
    return values;
  }

  bool AtEnd() const { return next_ >= lines_.size(); }

  // INVALID_ARGUMENT naming the line last read.
  absl::Status Error(std::string_view what) const {
    return absl::InvalidArgumentError(
        absl::StrCat("ebs model, line ", next_, ": ", AbslView(what)));
  }

 private:
  std::vector<std::string_view> lines_;
  size_t next_ = 0;
};

absl::Status ParseInt(const LineReader& in, std::string_view text,
                      std::string_view what, int& out) {
  if (!absl::SimpleAtoi(AbslView(text), &out)) {
    return in.Error(absl::StrCat(AbslView(what), ": \"", AbslView(text),
                                 "\" is not a whole number"));
  }
  return absl::OkStatus();
}

absl::Status ParseFloat(const LineReader& in, std::string_view text,
                        std::string_view what, float& out) {
  if (!absl::SimpleAtof(AbslView(text), &out) || !std::isfinite(out)) {
    return in.Error(absl::StrCat(AbslView(what), ": \"", AbslView(text),
                                 "\" is not a finite number"));
  }
  return absl::OkStatus();
}

absl::Status ParseBool(const LineReader& in, std::string_view text,
                       std::string_view what, bool& out) {
  if (text != "0" && text != "1") {
    return in.Error(absl::StrCat(AbslView(what), ": expected 0 or 1, got \"",
                                 AbslView(text), "\""));
  }
  out = text == "1";
  return absl::OkStatus();
}

// One histogram line "keyword c_0 ... c_{bins-1}".
absl::Status ParseCounts(LineReader& in, std::string_view keyword, int bins,
                         std::vector<int64_t>& counts) {
  FOVEA_ASSIGN_OR_RETURN(std::vector<std::string_view> tokens,
                         in.Next(keyword));
  if (tokens.size() != static_cast<size_t>(bins) + 1) {
    return in.Error(absl::StrCat(AbslView(keyword), ": expected ", bins,
                                 " counts, got ", tokens.size() - 1));
  }
  counts.assign(bins, 0);
  for (int i = 0; i < bins; ++i) {
    const std::string_view t = (tokens)[i + 1];
    if (t[0] == '-') {
      return in.Error(
          absl::StrCat(AbslView(keyword), " count ", i, " is negative"));
    }
    // Digits only: no sign, no exponent, no NaN.
    const bool digits = std::all_of(
        t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits || !absl::SimpleAtoi(AbslView(t), &counts[i])) {
      return in.Error(absl::StrCat(AbslView(keyword), " count ", i, ": \"",
                                   AbslView(t), "\" is not a whole number"));
    }
  }
  return absl::OkStatus();
}

}  // namespace

std::string EbsModel::Serialize() const {
  const EdgeMapOptions& e = options_.edge_maps;
  const NormalOptions& n = options_.normals;
  std::string out = absl::StrCat(kMagic, "\nversion ", kFormatVersion, "\n");
  absl::StrAppend(&out, "edge_maps color_blur_sigma_px ",
                  FormatFloat(e.color_blur_sigma_px), " sobel_aperture ",
                  e.sobel_aperture, " depth_radius_px ", e.depth_radius_px,
                  " curvature_radius_px ", e.curvature_radius_px,
                  " signed_curvature ", e.signed_curvature ? 1 : 0, "\n");
  absl::StrAppend(&out, "normals baseline_m ", FormatFloat(n.baseline_m),
                  " min_half_window ", n.min_half_window, " max_half_window ",
                  n.max_half_window, " smoothing_half_window ",
                  n.smoothing_half_window, " max_depth_change_factor ",
                  FormatFloat(n.max_depth_change_factor), "\n");
  absl::StrAppend(&out, "labels boundary_band_px ", options_.boundary_band_px,
                  " ignore_band_px ", options_.ignore_band_px, "\n");
  for (int c = 0; c < kCues; ++c) {
    const Cue& cue = cues_[c];
    absl::StrAppend(&out, "cue ", EbsModel::kCueNames[c], " bins ",
                    cue.bins.bins, " max_value ",
                    FormatFloat(cue.bins.max_value), " signed ",
                    cue.bins.signed_cue ? 1 : 0, "\n");
    for (const auto& [name, counts] :
         {std::pair<const char*, const std::vector<int64_t>*>{"edge",
                                                              &cue.edge},
          {"no_edge", &cue.no_edge}}) {
      absl::StrAppend(&out, name);
      for (const int64_t x : *counts) absl::StrAppend(&out, " ", x);
      absl::StrAppend(&out, "\n");
    }
  }
  absl::StrAppend(&out, "end\n");
  return out;
}

absl::StatusOr<EbsModel> EbsModel::Parse(std::string_view text) {
  LineReader in(text);
  if (absl::StatusOr<std::vector<std::string_view>> magic = in.Next(kMagic);
      !magic.ok() || magic->size() != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("ebs model: the first line must be \"", kMagic,
                     "\"; this is not an EBS model"));
  }
  FOVEA_ASSIGN_OR_RETURN(std::vector<std::string_view> version,
                         in.Next("version"));
  if (version.size() != 2 || (version)[1] != "1") {
    return in.Error(
        absl::StrCat("unsupported format version; this reads "
                     "version ",
                     kFormatVersion));
  }

  EbsTrainOptions options;
  absl::StatusOr<std::vector<std::string_view>> f = in.NextFields(
      "edge_maps", {"color_blur_sigma_px", "sobel_aperture", "depth_radius_px",
                    "curvature_radius_px", "signed_curvature"});
  if (!f.ok()) return f.status();
  EdgeMapOptions& e = options.edge_maps;
  for (absl::Status s :
       {ParseFloat(in, (*f)[0], "color_blur_sigma_px", e.color_blur_sigma_px),
        ParseInt(in, (*f)[1], "sobel_aperture", e.sobel_aperture),
        ParseInt(in, (*f)[2], "depth_radius_px", e.depth_radius_px),
        ParseInt(in, (*f)[3], "curvature_radius_px", e.curvature_radius_px),
        ParseBool(in, (*f)[4], "signed_curvature", e.signed_curvature)}) {
    if (!s.ok()) return s;
  }
  f = in.NextFields("normals",
                    {"baseline_m", "min_half_window", "max_half_window",
                     "smoothing_half_window", "max_depth_change_factor"});
  if (!f.ok()) return f.status();
  NormalOptions& n = options.normals;
  for (absl::Status s :
       {ParseFloat(in, (*f)[0], "baseline_m", n.baseline_m),
        ParseInt(in, (*f)[1], "min_half_window", n.min_half_window),
        ParseInt(in, (*f)[2], "max_half_window", n.max_half_window),
        ParseInt(in, (*f)[3], "smoothing_half_window", n.smoothing_half_window),
        ParseFloat(in, (*f)[4], "max_depth_change_factor",
                   n.max_depth_change_factor)}) {
    if (!s.ok()) return s;
  }
  f = in.NextFields("labels", {"boundary_band_px", "ignore_band_px"});
  if (!f.ok()) return f.status();
  for (absl::Status s :
       {ParseInt(in, (*f)[0], "boundary_band_px", options.boundary_band_px),
        ParseInt(in, (*f)[1], "ignore_band_px", options.ignore_band_px)}) {
    if (!s.ok()) return s;
  }

  std::array<Cue, kCues> cues;
  CueBins* option_bins[kCues] = {&options.color_bins, &options.depth_bins,
                                 &options.curvature_bins};
  for (int c = 0; c < kCues; ++c) {
    FOVEA_ASSIGN_OR_RETURN(std::vector<std::string_view> t, in.Next("cue"));
    if (t.size() != 8 || (t)[1] != EbsModel::kCueNames[c] || (t)[2] != "bins" ||
        (t)[4] != "max_value" || (t)[6] != "signed") {
      return in.Error(absl::StrCat("expected \"cue ", EbsModel::kCueNames[c],
                                   " bins <n> max_value <x> signed <0|1>\""));
    }
    CueBins& bins = cues[c].bins;
    for (absl::Status s : {ParseInt(in, (t)[3], "bins", bins.bins),
                           ParseFloat(in, (t)[5], "max_value", bins.max_value),
                           ParseBool(in, (t)[7], "signed", bins.signed_cue)}) {
      if (!s.ok()) return s;
    }
    if (absl::Status s = Validate(bins); !s.ok()) {
      return in.Error(absl::StrCat(EbsModel::kCueNames[c], " ", s.message()));
    }
    *option_bins[c] = bins;
    FOVEA_RETURN_IF_ERROR(ParseCounts(in, "edge", bins.bins, cues[c].edge));
    FOVEA_RETURN_IF_ERROR(
        ParseCounts(in, "no_edge", bins.bins, cues[c].no_edge));
  }
  FOVEA_ASSIGN_OR_RETURN(std::vector<std::string_view> end, in.Next("end"));
  if (end.size() != 1 || !in.AtEnd()) {
    return in.Error("text after \"end\"");
  }
  absl::StatusOr<EbsModel> model = FromCounts(options, cues);
  if (!model.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("ebs model: ", model.status().message()));
  }
  return model;
}

std::string EbsModel::Version() const {
  char hex[9];
  std::snprintf(hex, sizeof(hex), "%08x", Fnv1a(Serialize()));
  return absl::StrCat("ebs-v", kFormatVersion, "-", hex);
}

}  // namespace fovea
