#ifndef FOVEA_CORE_BASE_NAME_TABLE_H_
#define FOVEA_CORE_BASE_NAME_TABLE_H_

#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/types/span.h"
#include "core/base/strings.h"

namespace fovea {

// One spelling of an enum's value. An option's names live in one table of
// these; its parser, its name function, the errors and the tools' help text
// are all read from the table, so a value added to it is known everywhere:
//
//   constexpr NamedValue<PyramidKind> kPyramids[] = {
//       {PyramidKind::kNone, "none"}, {PyramidKind::kItti, "itti"}};
//   ParseNamed<PyramidKind>(kPyramids, "pyramid", "kind", "itti");
template <typename Enum>
struct NamedValue {
  Enum value;
  std::string_view name;
};

// The names of `table`, in order, joined by `separator`: "none simple itti".
template <typename Enum>
std::string NameList(absl::Span<const NamedValue<Enum>> table,
                     std::string_view separator = " ") {
  std::string names;
  for (const NamedValue<Enum>& row : table) {
    if (!names.empty()) absl::StrAppend(&names, AbslView(separator));
    absl::StrAppend(&names, AbslView(row.name));
  }
  return names;
}

// The name of `value`; "unknown" when the table has none.
template <typename Enum>
std::string_view NameOf(absl::Span<const NamedValue<Enum>> table, Enum value) {
  for (const NamedValue<Enum>& row : table) {
    if (row.value == value) return row.name;
  }
  return "unknown";
}

// The value named `text` (exact spelling); otherwise INVALID_ARGUMENT
// "<field>: unknown <what> '<text>' (known: <names>)", without "<field>: "
// when `field` is empty (for a caller that names the field itself).
template <typename Enum>
absl::StatusOr<Enum> ParseNamed(absl::Span<const NamedValue<Enum>> table,
                                std::string_view field, std::string_view what,
                                std::string_view text) {
  for (const NamedValue<Enum>& row : table) {
    if (row.name == text) return row.value;
  }
  return absl::InvalidArgumentError(absl::StrCat(
      AbslView(field), field.empty() ? "" : ": ", "unknown ", AbslView(what),
      " '", AbslView(text), "' (known: ", NameList(table), ")"));
}

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_NAME_TABLE_H_
