#include "tools/eval/scene_kind.h"

#include <charconv>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

#include "absl/strings/str_cat.h"

namespace fovea::eval {
namespace {

struct KindRange {
  std::string prefix;
  int first = 0;
  int last = 0;
  std::string kind;
};

constexpr int kEvery = 1 << 30;

std::vector<KindRange>& Table() {
  static std::vector<KindRange>* table = new std::vector<KindRange>{
      {"learn", 0, 16, "boxes"},     {"learn", 17, 24, "stacked"},
      {"learn", 25, 32, "occluded"}, {"learn", 33, 44, "cylindric"},
      {"test", 0, 15, "boxes"},      {"test", 16, 23, "stacked"},
      {"test", 24, 30, "occluded"},  {"test", 31, 42, "cylindric"},
      {"test", 43, 54, "mixed"},     {"test", 55, 64, "complex"},
      {"pile-", 0, kEvery, "pile"},
  };
  return *table;
}
std::mutex& TableMutex() {
  static std::mutex* mu = new std::mutex;
  return *mu;
}

// The name's number after `prefix`, or -1.
int NumberAfter(std::string_view name, std::string_view prefix) {
  if (name.substr(0, prefix.size()) != prefix) return -1;
  const std::string_view digits = name.substr(prefix.size());
  int index = -1;
  const auto [ptr, ec] =
      std::from_chars(digits.data(), digits.data() + digits.size(), index);
  if (ec != std::errc() || ptr != digits.data() + digits.size()) return -1;
  return index;
}

}  // namespace

std::string SceneKind(std::string_view name) {
  if (name.substr(0, 5) == "room-") return "room";
  const std::lock_guard<std::mutex> lock(TableMutex());
  for (const KindRange& k : Table()) {
    const int n = NumberAfter(name, k.prefix);
    if (n >= k.first && n <= k.last) return k.kind;
  }
  return "other";
}

absl::Status LoadKinds(const std::string& path) {
  std::ifstream in(path);
  if (!in) return absl::NotFoundError(absl::StrCat("kinds: no file ", path));
  std::vector<KindRange> loaded;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string prefix, range, kind;
    if (!(words >> prefix)) continue;  // blank
    int first = 0, last = 0;
    char dash = 0;
    if (!(words >> range >> kind) ||
        !(std::istringstream(range) >> first >> dash >> last) || dash != '-' ||
        first < 0 || last < first) {
      return absl::InvalidArgumentError(absl::StrCat(
          path, ":", number, ": expected \"PREFIX FIRST-LAST KIND\", got \"",
          line, "\""));
    }
    loaded.push_back({prefix, first, last, kind});
  }
  const std::lock_guard<std::mutex> lock(TableMutex());
  Table().insert(Table().begin(), loaded.begin(), loaded.end());
  return absl::OkStatus();
}

}  // namespace fovea::eval
