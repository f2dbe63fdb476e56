// Internal to src/eval: the optimal one-to-one assignment that TrackEval's CLEAR and HOTA take from
// scipy.optimize.linear_sum_assignment, as a maximisation over the core solver (ret3d/core/hungarian.h).
#pragma once

#include <vector>

namespace ret3d {
namespace eval {
namespace detail {

// Rows x cols scores (row-major). Returns, per row, the column assigned (-1 when rows > cols leaves it out) so that
// the total score of the min(rows, cols) pairs is maximal.
std::vector<int> maximiseAssignment(const std::vector<double>& score, int rows, int cols);

}  // namespace detail
}  // namespace eval
}  // namespace ret3d
