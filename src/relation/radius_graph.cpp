#include "ret3d/relation/radius_graph.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace ret3d {
namespace relation {

namespace {

// Cells of side `radius`: every neighbour of a point lies in its own cell or one of the 8 around it.
struct CellKey {
  std::int64_t ix, iy;
  bool operator<(const CellKey& o) const { return ix != o.ix ? ix < o.ix : iy < o.iy; }
  bool operator==(const CellKey& o) const { return ix == o.ix && iy == o.iy; }
};

}  // namespace

RadiusGraph buildRadiusGraph(const std::vector<Eigen::Vector2d>& centres, double radius, bool with_edges) {
  const std::size_t n = centres.size();
  RadiusGraph g;
  g.offset.assign(n + 1, 0);
  std::vector<std::vector<std::int64_t>> nbrs(n);
  const bool edges = with_edges && radius > 0 && std::isfinite(radius);

  if (edges) {
    // Sort object indices by cell (O(n log n)); a cell's members are then one contiguous run, found by binary search.
    const double r2 = radius * radius;
    std::vector<CellKey> key(n);
    std::vector<std::size_t> order;
    order.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (!centres[i].allFinite()) continue;
      key[i] = {static_cast<std::int64_t>(std::floor(centres[i].x() / radius)),
                static_cast<std::int64_t>(std::floor(centres[i].y() / radius))};
      order.push_back(i);
    }
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return key[a] < key[b] || (key[a] == key[b] && a < b);
    });
    std::vector<CellKey> sorted_keys(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) sorted_keys[k] = key[order[k]];
    for (std::size_t i = 0; i < n; ++i) {
      if (!centres[i].allFinite()) continue;
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        for (std::int64_t dy = -1; dy <= 1; ++dy) {
          const CellKey c{key[i].ix + dx, key[i].iy + dy};
          auto range = std::equal_range(sorted_keys.begin(), sorted_keys.end(), c);
          for (auto it = range.first; it != range.second; ++it) {
            const std::size_t j = order[static_cast<std::size_t>(it - sorted_keys.begin())];
            if ((centres[j] - centres[i]).squaredNorm() <= r2) nbrs[i].push_back(static_cast<std::int64_t>(j));
          }
        }
      }
      std::sort(nbrs[i].begin(), nbrs[i].end());
    }
  }

  for (std::size_t i = 0; i < n; ++i) {
    if (nbrs[i].empty()) nbrs[i].push_back(static_cast<std::int64_t>(i));  // self-loop (always within r of itself)
    g.offset[i + 1] = g.offset[i] + static_cast<std::int64_t>(nbrs[i].size());
  }
  g.source.reserve(static_cast<std::size_t>(g.offset[n]));
  g.target.reserve(static_cast<std::size_t>(g.offset[n]));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::int64_t j : nbrs[i]) {
      g.source.push_back(j);
      g.target.push_back(static_cast<std::int64_t>(i));
    }
  }
  return g;
}

}  // namespace relation
}  // namespace ret3d
