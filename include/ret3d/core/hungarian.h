// Optimal assignment (Hungarian / Kuhn-Munkres with potentials, O(n^2 m)): the tracker's optional matcher and the
// one-to-one matching of the tracking metrics (CLEAR MOT, HOTA).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace ret3d {

// Minimum-cost assignment of the rows of `cost` (rows x cols, any shape) to distinct columns: min(rows, cols) pairs
// are assigned. Returns, per row, its column or -1 when unassigned (only when rows > cols). Costs must be finite;
// callers express "forbidden" with a large finite cost and drop such pairs afterwards.
std::vector<int> solveAssignment(const Eigen::MatrixXd& cost);

}  // namespace ret3d
