#include "core/frame/lzf.h"

#include <pcl/io/lzf.h>

#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace fovea {
namespace {

using ::testing::ElementsAreArray;
using ::testing::HasSubstr;

std::string Bytes(std::initializer_list<int> values) {
  std::string out;
  for (int value : values) out.push_back(static_cast<char>(value));
  return out;
}

std::vector<uint8_t> Expand(absl::string_view text) {
  return std::vector<uint8_t>(text.begin(), text.end());
}

void ExpectInvalid(const absl::StatusOr<std::vector<uint8_t>>& result,
                   const std::string& part) {
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr(part));
}

TEST(LzfDecompressTest, LiteralRunsAreCopied) {
  // Control 2: three literal bytes; control 0: one.
  const absl::StatusOr<std::vector<uint8_t>> out =
      LzfDecompress(Bytes({2, 'a', 'b', 'c', 0, 'd'}), 4);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_THAT(*out, ElementsAreArray(Expand("abcd")));
}

TEST(LzfDecompressTest, OverlappingBackReferenceRepeatsBytes) {
  // "ab", then length field 3 (5 bytes) from 2 back: "ababa"; then length
  // field 7 plus 1 (10 bytes) from 1 back: ten 'a'.
  const absl::StatusOr<std::vector<uint8_t>> out =
      LzfDecompress(Bytes({1, 'a', 'b', 3 << 5, 1, 7 << 5, 1, 0}), 17);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_THAT(*out, ElementsAreArray(Expand("abababaaaaaaaaaaa")));
}

TEST(LzfDecompressTest, LongDistanceUsesTheControlBitsAndTheNextByte) {
  // 300 literal bytes, then 4 bytes from 300 back: distance - 1 = 299 =
  // 1 << 8 | 43.
  std::string stream;
  std::string expected;
  for (int run = 0; run < 10; ++run) {
    stream.push_back(29);  // 30 literal bytes
    for (int i = 0; i < 30; ++i) {
      const char c = static_cast<char>('A' + (run * 30 + i) % 26);
      stream.push_back(c);
      expected.push_back(c);
    }
  }
  stream += Bytes({2 << 5 | 1, 43});
  expected += expected.substr(0, 4);
  const absl::StatusOr<std::vector<uint8_t>> out =
      LzfDecompress(stream, expected.size());
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_THAT(*out, ElementsAreArray(Expand(expected)));
}

TEST(LzfDecompressTest, EmptyStreamIsZeroBytes) {
  const absl::StatusOr<std::vector<uint8_t>> out = LzfDecompress("", 0);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_TRUE(out->empty());
  ExpectInvalid(LzfDecompress("", 1), "expands to 0 bytes, 1 expected");
}

TEST(LzfDecompressTest, BackReferenceBeforeTheStartIsRefused) {
  // One byte written, then a reference 2 bytes back.
  ExpectInvalid(LzfDecompress(Bytes({0, 'a', 1 << 5, 1}), 4),
                "LZF run at compressed byte 2: back-reference 2 bytes back "
                "from output byte 1, before the start");
  // A reference first of all.
  ExpectInvalid(LzfDecompress(Bytes({1 << 5, 0}), 3), "before the start");
}

TEST(LzfDecompressTest, OutputOverrunIsRefused) {
  ExpectInvalid(LzfDecompress(Bytes({2, 'a', 'b', 'c'}), 2),
                "literal of 3 bytes at output byte 0 overruns the 2 expected");
  ExpectInvalid(LzfDecompress(Bytes({0, 'a', 7 << 5, 200, 0}), 100),
                "back-reference of 209 bytes at output byte 1 overruns");
}

TEST(LzfDecompressTest, TruncatedInputIsRefused) {
  ExpectInvalid(LzfDecompress(Bytes({5, 'a', 'b'}), 6),
                "compressed byte 0: literal of 6 bytes but 2 left");
  // Reference without its distance byte, long reference without its
  // length byte or distance byte.
  ExpectInvalid(LzfDecompress(Bytes({0, 'a', 1 << 5}), 4),
                "compressed byte 2: input ends in a back-reference");
  ExpectInvalid(LzfDecompress(Bytes({0, 'a', 7 << 5}), 20),
                "input ends in a back-reference");
  ExpectInvalid(LzfDecompress(Bytes({0, 'a', 7 << 5, 3}), 20),
                "input ends in a back-reference");
  // A stream that stops short of the expected size.
  ExpectInvalid(LzfDecompress(Bytes({1, 'a', 'b'}), 3),
                "expands to 2 bytes, 3 expected");
}

TEST(LzfDecompressTest, MaxExpansionBoundsEveryStream) {
  // The densest stream: one literal, then long references of 264 bytes.
  std::string stream = Bytes({0, 'z'});
  for (int i = 0; i < 100; ++i) stream += Bytes({7 << 5, 255, 0});
  const size_t size = 1 + 100 * 264;
  ASSERT_TRUE(LzfDecompress(stream, size).ok());
  EXPECT_GE(LzfMaxExpansion(stream.size()), size);
}

// PCL's own compressor (what writes binary_compressed PCDs) round-trips.
TEST(LzfDecompressTest, ReadsWhatPclCompresses) {
  std::mt19937 random(7);
  std::vector<std::vector<uint8_t>> inputs;
  std::vector<uint8_t> runs;  // repetitive: many back-references
  for (int i = 0; i < 70000; ++i) runs.push_back((i / 50) % 7);
  inputs.push_back(runs);
  std::vector<uint8_t> noise;  // incompressible: literals
  for (int i = 0; i < 5000; ++i) noise.push_back(random() & 0xff);
  inputs.push_back(noise);
  std::vector<uint8_t> floats;  // like a cloud: smooth floats and NaN
  for (int i = 0; i < 20000; ++i) {
    const float value = i % 17 == 0 ? std::numeric_limits<float>::quiet_NaN()
                                    : 1.0f + 0.001f * (i / 4);
    const auto* bytes = reinterpret_cast<const uint8_t*>(&value);
    floats.insert(floats.end(), bytes, bytes + 4);
  }
  inputs.push_back(floats);
  for (const std::vector<uint8_t>& input : inputs) {
    std::vector<char> compressed(input.size() * 2 + 64);
    const unsigned size = pcl::lzfCompress(
        input.data(), static_cast<unsigned>(input.size()), compressed.data(),
        static_cast<unsigned>(compressed.size()));
    ASSERT_GT(size, 0u);
    const absl::StatusOr<std::vector<uint8_t>> out =
        LzfDecompress(absl::string_view(compressed.data(), size), input.size());
    ASSERT_TRUE(out.ok()) << out.status();
    EXPECT_EQ(*out, input);
    EXPECT_GE(LzfMaxExpansion(size), input.size());
  }
}

}  // namespace
}  // namespace fovea
