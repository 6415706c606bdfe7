#include "core/base/name_table.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace fovea {
namespace {

enum class Shape { kBox, kCan, kBowl };

constexpr NamedValue<Shape> kShapes[] = {
    {Shape::kBox, "box"}, {Shape::kCan, "can"}, {Shape::kBowl, "bowl"}};

TEST(NameTable, ParsesNamesAndListsTheKnownOnesOtherwise) {
  EXPECT_EQ(*ParseNamed<Shape>(kShapes, "shape", "kind", "can"), Shape::kCan);
  EXPECT_EQ(NameOf<Shape>(kShapes, Shape::kBowl), "bowl");
  EXPECT_EQ(NameList<Shape>(kShapes), "box can bowl");
  EXPECT_EQ(NameList<Shape>(kShapes, "|"), "box|can|bowl");

  const absl::StatusOr<Shape> bad =
      ParseNamed<Shape>(kShapes, "shape", "kind", "Can");  // exact spelling
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(bad.status().message(),
            "shape: unknown kind 'Can' (known: box can bowl)");
  EXPECT_EQ(ParseNamed<Shape>(kShapes, "", "kind", "x").status().message(),
            "unknown kind 'x' (known: box can bowl)");
  EXPECT_EQ(NameOf<Shape>(absl::Span<const NamedValue<Shape>>(kShapes, 2),
                          Shape::kBowl),
            "unknown");
}

}  // namespace
}  // namespace fovea
