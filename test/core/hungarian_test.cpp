#include "ret3d/core/hungarian.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <set>

namespace ret3d {
namespace {

// Minimum total cost over all assignments of min(rows, cols) pairs, by enumerating column permutations.
double bruteForce(const Eigen::MatrixXd& c) {
  const bool transpose = c.rows() > c.cols();
  const Eigen::MatrixXd a = transpose ? Eigen::MatrixXd(c.transpose()) : c;
  std::vector<int> cols(a.cols());
  std::iota(cols.begin(), cols.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  do {  // the first a.rows() entries of each permutation give an assignment (repeats are harmless)
    double s = 0;
    for (int r = 0; r < a.rows(); ++r) s += a(r, cols[r]);
    best = std::min(best, s);
  } while (std::next_permutation(cols.begin(), cols.end()));
  return best;
}

TEST(Hungarian, OptimalOnRandomMatricesVersusBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::uniform_int_distribution<int> size(1, 6);
  std::uniform_int_distribution<int> small(0, 3);
  for (int trial = 0; trial < 400; ++trial) {
    const int rows = size(rng), cols = size(rng);
    Eigen::MatrixXd c(rows, cols);
    for (int r = 0; r < rows; ++r)
      for (int k = 0; k < cols; ++k) c(r, k) = trial % 2 ? u(rng) : small(rng);  // odd: ties galore
    const std::vector<int> a = solveAssignment(c);
    ASSERT_EQ(static_cast<int>(a.size()), rows);
    std::set<int> used;
    double total = 0;
    int assigned = 0;
    for (int r = 0; r < rows; ++r) {
      if (a[r] < 0) continue;
      ASSERT_LT(a[r], cols);
      EXPECT_TRUE(used.insert(a[r]).second) << "column used twice";
      total += c(r, a[r]);
      ++assigned;
    }
    EXPECT_EQ(assigned, std::min(rows, cols));
    EXPECT_NEAR(total, bruteForce(c), 1e-9) << "trial " << trial << "\n" << c;
  }
}

TEST(Hungarian, GreedyWouldBeWorse) {
  // Greedy by rows takes (0,0)=1 and is then forced into (1,1)=10: total 11; the optimum is 2 + 2 = 4.
  Eigen::MatrixXd c(2, 2);
  c << 1, 2, 2, 10;
  const std::vector<int> a = solveAssignment(c);
  EXPECT_EQ(a[0], 1);
  EXPECT_EQ(a[1], 0);
}

TEST(Hungarian, EmptyAndNonFinite) {
  EXPECT_TRUE(solveAssignment(Eigen::MatrixXd(0, 3)).empty());
  EXPECT_EQ(solveAssignment(Eigen::MatrixXd(2, 0)), std::vector<int>({-1, -1}));
  Eigen::MatrixXd c(1, 1);
  c << std::numeric_limits<double>::infinity();
  EXPECT_THROW(solveAssignment(c), std::invalid_argument);
}

}  // namespace
}  // namespace ret3d
