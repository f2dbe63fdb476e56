// The sparse object graph of IntraRM (Ret3D §3.2): an edge between two objects whose BEV centres are at most r metres
// apart, and every object linked to itself. Built by grid hashing in O(n log n + edges).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace ret3d {
namespace relation {

// Directed edges grouped by target: for node i, its neighbours (itself included) are
// source[offset[i]] .. source[offset[i + 1] - 1], ascending. target[k] is the node edge k points to (so messages
// flow source -> target). An undirected pair {i, j} appears as i -> j and j -> i.
struct RadiusGraph {
  std::vector<std::int64_t> source;
  std::vector<std::int64_t> target;
  std::vector<std::int64_t> offset;  // size n + 1

  std::size_t numNodes() const { return offset.empty() ? 0 : offset.size() - 1; }
  std::size_t numEdges() const { return source.size(); }
};

// Neighbours within `radius` metres in the x-y plane (inclusive), plus self-loops. radius <= 0 (or with_edges false)
// gives self-loops only: each object refined alone (the "no-edge" ablation). Non-finite centres get a self-loop only.
RadiusGraph buildRadiusGraph(const std::vector<Eigen::Vector2d>& centres, double radius, bool with_edges = true);

}  // namespace relation
}  // namespace ret3d
