#include "assignment.h"

#include <Eigen/Core>

#include "ret3d/core/hungarian.h"

namespace ret3d {
namespace eval {
namespace detail {

std::vector<int> maximiseAssignment(const std::vector<double>& score, int rows, int cols) {
  // Maximising the score is minimising its negation; the core solver handles any shape.
  Eigen::MatrixXd cost(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) cost(r, c) = -score[static_cast<std::size_t>(r) * cols + c];
  return solveAssignment(cost);
}

}  // namespace detail
}  // namespace eval
}  // namespace ret3d
