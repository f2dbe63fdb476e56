#include "ret3d/core/hungarian.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace ret3d {
namespace {

// Rows <= cols. The shortest augmenting path algorithm with row/column potentials (u, v): each row is added in
// turn and the tree of tight edges grown Dijkstra-like, so the whole solve is O(n^2 m).
std::vector<int> solveWide(const Eigen::MatrixXd& a) {
  const int n = static_cast<int>(a.rows());
  const int m = static_cast<int>(a.cols());
  const double inf = std::numeric_limits<double>::infinity();
  // 1-based arrays; column 0 is a virtual column holding the row being inserted.
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0), minv(m + 1);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  std::vector<char> used(m + 1);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::fill(minv.begin(), minv.end(), inf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = a(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    // Flip the augmenting path.
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(n, -1);
  for (int j = 1; j <= m; ++j)
    if (p[j] != 0) row_to_col[p[j] - 1] = j - 1;
  return row_to_col;
}

}  // namespace

std::vector<int> solveAssignment(const Eigen::MatrixXd& cost) {
  if (cost.rows() == 0) return {};
  if (cost.cols() == 0) return std::vector<int>(cost.rows(), -1);
  if (!cost.allFinite()) throw std::invalid_argument("solveAssignment: costs must be finite");
  if (cost.rows() <= cost.cols()) return solveWide(cost);
  // More rows than columns: solve the transpose, then invert the mapping.
  const std::vector<int> col_to_row = solveWide(cost.transpose());
  std::vector<int> row_to_col(cost.rows(), -1);
  for (int c = 0; c < static_cast<int>(col_to_row.size()); ++c) row_to_col[col_to_row[c]] = c;
  return row_to_col;
}

}  // namespace ret3d
