#include "core/eval/hungarian.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace fovea {
namespace {

double Total(const std::vector<std::vector<double>>& s,
             const std::vector<int>& a) {
  double total = 0.0;
  for (size_t r = 0; r < a.size(); ++r) {
    if (a[r] >= 0) total += s[r][a[r]];
  }
  return total;
}

TEST(MaxWeightAssignmentTest, PrefersTheBestTotalOverTheGreedyFirstPick) {
  // Greedy takes (0, 0) = 0.9 and leaves row 1 with 0.1: total 1.0. The
  // best is (0, 1) + (1, 0) = 0.8 + 0.85 = 1.65.
  const std::vector<std::vector<double>> s = {{0.9, 0.8}, {0.85, 0.1}};
  EXPECT_EQ(MaxWeightAssignment(s), (std::vector<int>{1, 0}));
}

TEST(MaxWeightAssignmentTest, MoreRowsThanColumnsLeavesTheWeakestRowOut) {
  const std::vector<std::vector<double>> s = {{0.2}, {0.7}, {0.5}};
  EXPECT_EQ(MaxWeightAssignment(s), (std::vector<int>{-1, 0, -1}));
}

TEST(MaxWeightAssignmentTest, MoreColumnsThanRowsUsesEachColumnOnce) {
  const std::vector<std::vector<double>> s = {{0.1, 0.9, 0.3}, {0.2, 0.8, 0.7}};
  EXPECT_EQ(MaxWeightAssignment(s), (std::vector<int>{1, 2}));
}

TEST(MaxWeightAssignmentTest, EmptyMatrixAssignsNothing) {
  EXPECT_TRUE(MaxWeightAssignment({}).empty());
  EXPECT_EQ(MaxWeightAssignment({{}, {}}), (std::vector<int>{-1, -1}));
}

TEST(MaxWeightAssignmentTest, MatchesBruteForceOnRandomMatrices) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 1 + trial % 6;
    std::vector<std::vector<double>> s(n, std::vector<double>(n));
    for (auto& row : s) {
      for (double& x : row) x = uniform(rng);
    }
    std::vector<int> perm(n);
    std::iota(perm.begin(), perm.end(), 0);
    double best = -1.0;
    do {
      best = std::max(best, Total(s, perm));
    } while (std::next_permutation(perm.begin(), perm.end()));
    const std::vector<int> a = MaxWeightAssignment(s);
    EXPECT_NEAR(Total(s, a), best, 1e-9) << "n = " << n;
    std::vector<int> sorted = a;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
  }
}

}  // namespace
}  // namespace fovea
