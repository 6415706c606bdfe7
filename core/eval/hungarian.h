#ifndef FOVEA_CORE_EVAL_HUNGARIAN_H_
#define FOVEA_CORE_EVAL_HUNGARIAN_H_

#include <vector>

namespace fovea {

// The one-to-one assignment of rows to columns that maximises the sum of
// `score[row][col]` (Kuhn-Munkres, O(n^3) in max(rows, cols)); the matrix
// may be rectangular, so some rows or columns stay unassigned. Returns, per
// row, its column or -1. Scores must be finite; an empty matrix (or rows
// of no columns) assigns nothing.
std::vector<int> MaxWeightAssignment(
    const std::vector<std::vector<double>>& score);

}  // namespace fovea

#endif  // FOVEA_CORE_EVAL_HUNGARIAN_H_
