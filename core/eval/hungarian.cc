#include "core/eval/hungarian.h"

#include <algorithm>
#include <limits>

namespace fovea {

std::vector<int> MaxWeightAssignment(
    const std::vector<std::vector<double>>& score) {
  const int rows = static_cast<int>(score.size());
  const int cols = rows > 0 ? static_cast<int>(score[0].size()) : 0;
  std::vector<int> assignment(rows, -1);
  if (rows == 0 || cols == 0) return assignment;
  // Square cost matrix (minimisation): cost = max - score, padding 0 cost
  // beyond the real entries (an unassigned row or column scores nothing).
  const int n = std::max(rows, cols);
  double max_score = 0.0;
  for (const std::vector<double>& row : score) {
    for (const double s : row) max_score = std::max(max_score, s);
  }
  auto cost = [&](int r, int c) {
    return r < rows && c < cols ? max_score - score[r][c] : max_score;
  };
  // The classic potentials formulation (1-based, column 0 a sentinel).
  const double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(n + 1, 0.0);
  std::vector<int> p(n + 1, 0), way(n + 1, 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(n + 1, kInf);
    std::vector<bool> used(n + 1, false);
    do {
      used[j0] = true;
      const int i0 = p[j0];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= n; ++j) {
        if (used[j]) continue;
        const double cur = cost(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= n; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  for (int j = 1; j <= n; ++j) {
    const int r = p[j] - 1, c = j - 1;
    if (r >= 0 && r < rows && c < cols) assignment[r] = c;
  }
  return assignment;
}

}  // namespace fovea
