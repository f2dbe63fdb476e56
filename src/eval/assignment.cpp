#include "assignment.h"

#include <algorithm>
#include <limits>

namespace ret3d {
namespace eval {
namespace detail {

namespace {

// Minimum-cost assignment for n <= m (rows <= cols) by successive shortest augmenting paths with potentials
// (Kuhn-Munkres in its O(n^2 m) form). cost(i, j) = at(i, j).
template <typename At>
std::vector<int> minCostRows(int n, int m, At at) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> row_pot(n + 1, 0.0), col_pot(m + 1, 0.0), slack(m + 1);
  std::vector<int> col_row(m + 1, 0), prev_col(m + 1, 0);
  std::vector<char> visited(m + 1);
  for (int r = 1; r <= n; ++r) {
    col_row[0] = r;
    int col = 0;
    std::fill(slack.begin(), slack.end(), inf);
    std::fill(visited.begin(), visited.end(), 0);
    while (col_row[col] != 0) {
      visited[col] = 1;
      const int row = col_row[col];
      double step = inf;
      int next = 0;
      for (int j = 1; j <= m; ++j) {
        if (visited[j]) continue;
        const double reduced = at(row - 1, j - 1) - row_pot[row] - col_pot[j];
        if (reduced < slack[j]) {
          slack[j] = reduced;
          prev_col[j] = col;
        }
        if (slack[j] < step) {
          step = slack[j];
          next = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (visited[j]) {
          row_pot[col_row[j]] += step;
          col_pot[j] -= step;
        } else {
          slack[j] -= step;
        }
      }
      col = next;
    }
    while (col != 0) {
      const int back = prev_col[col];
      col_row[col] = col_row[back];
      col = back;
    }
  }
  std::vector<int> out(n, -1);
  for (int j = 1; j <= m; ++j) {
    if (col_row[j] != 0) out[col_row[j] - 1] = j - 1;
  }
  return out;
}

}  // namespace

std::vector<int> maximiseAssignment(const std::vector<double>& score, int rows, int cols) {
  if (rows == 0) return {};
  if (cols == 0) return std::vector<int>(rows, -1);
  if (rows <= cols) {
    return minCostRows(rows, cols, [&](int i, int j) { return -score[static_cast<std::size_t>(i) * cols + j]; });
  }
  const std::vector<int> col_to_row =
      minCostRows(cols, rows, [&](int i, int j) { return -score[static_cast<std::size_t>(j) * cols + i]; });
  std::vector<int> out(rows, -1);
  for (int c = 0; c < cols; ++c) {
    if (col_to_row[c] >= 0) out[col_to_row[c]] = c;
  }
  return out;
}

}  // namespace detail
}  // namespace eval
}  // namespace ret3d
