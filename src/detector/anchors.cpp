#include "ret3d/detector/anchors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "ret3d/core/log.h"

namespace ret3d {

double anchorShapeIoU(const Anchor& a, double length, double width, double height, double z) {
  const double bev = std::min(a.length, length) * std::min(a.width, width);
  const double zo = std::max(0.0, std::min(a.z + 0.5 * a.height, z + 0.5 * height) -
                                      std::max(a.z - 0.5 * a.height, z - 0.5 * height));
  const double inter = bev * zo;
  const double uni = a.length * a.width * a.height + length * width * height - inter;
  return uni > 0 ? inter / uni : 0.0;
}

namespace {

Anchor typicalAnchor(ObjectClass c) {
  switch (c) {
    case ObjectClass::Car: return {c, 3.9, 1.6, 1.56, -0.95, 0};
    case ObjectClass::Pedestrian: return {c, 0.8, 0.6, 1.73, -0.85, 0};
    case ObjectClass::Cyclist: return {c, 1.76, 0.6, 1.73, -0.85, 0};
    default: return {c, 1.0, 1.0, 1.0, -1.0, 0};
  }
}

void sortByArea(std::vector<Anchor>* a) {
  std::stable_sort(a->begin(), a->end(),
                   [](const Anchor& x, const Anchor& y) { return x.length * x.width < y.length * y.width; });
}

}  // namespace

std::vector<Anchor> defaultAnchors(const std::vector<ObjectClass>& classes, int k) {
  std::vector<Anchor> out;
  for (ObjectClass c : classes) {
    std::vector<Anchor> per;
    const Anchor t = typicalAnchor(c);
    for (int i = 0; i < k; ++i) {
      const double f = k == 1 ? 1.0 : 0.85 + 0.3 * i / (k - 1);
      per.push_back({c, t.length * f, t.width * f, t.height, t.z, 0});
    }
    sortByArea(&per);
    out.insert(out.end(), per.begin(), per.end());
  }
  return out;
}

std::vector<Anchor> kmeansAnchors(const std::vector<Box>& boxes, const std::vector<ObjectClass>& classes, int k,
                                  unsigned seed) {
  std::vector<Anchor> out;
  std::mt19937 rng(seed);
  for (ObjectClass c : classes) {
    std::vector<Anchor> pts;  // the boxes as anchors (size + z)
    for (const Box& b : boxes)
      if (b.label == c && b.length > 0 && b.width > 0 && b.height > 0) pts.push_back({c, b.length, b.width, b.height, b.z, 0});
    if (pts.empty()) {
      RET3D_WARN("k-means anchors: no " << className(c) << " boxes; using the typical KITTI size");
      auto d = defaultAnchors({c}, 1);
      out.insert(out.end(), d.begin(), d.end());
      continue;
    }
    auto dist = [](const Anchor& centre, const Anchor& p) {
      return 1.0 - anchorShapeIoU(centre, p.length, p.width, p.height, p.z);
    };
    // Distinct boxes bound the number of clusters.
    std::vector<Anchor> distinct;
    for (const auto& p : pts) {
      bool seen = false;
      for (const auto& d : distinct) seen |= dist(d, p) < 1e-12;
      if (!seen) distinct.push_back(p);
      if (static_cast<int>(distinct.size()) >= k) break;
    }
    const int kk = std::min<int>(k, static_cast<int>(distinct.size()));
    // k-means++ seeding.
    std::vector<Anchor> centres;
    centres.push_back(pts[std::uniform_int_distribution<std::size_t>(0, pts.size() - 1)(rng)]);
    while (static_cast<int>(centres.size()) < kk) {
      std::vector<double> d2(pts.size());
      double total = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        double best = std::numeric_limits<double>::max();
        for (const auto& ce : centres) best = std::min(best, dist(ce, pts[i]));
        d2[i] = best * best;
        total += d2[i];
      }
      if (total <= 0) break;
      double r = std::uniform_real_distribution<double>(0, total)(rng);
      std::size_t pick = 0;
      for (; pick + 1 < pts.size() && r > d2[pick]; ++pick) r -= d2[pick];
      centres.push_back(pts[pick]);
    }
    std::vector<int> assign(pts.size(), -1);
    for (int iter = 0; iter < 100; ++iter) {
      bool changed = false;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        int best = 0;
        double bd = std::numeric_limits<double>::max();
        for (std::size_t j = 0; j < centres.size(); ++j) {
          const double d = dist(centres[j], pts[i]);
          if (d < bd) bd = d, best = static_cast<int>(j);
        }
        changed |= assign[i] != best;
        assign[i] = best;
      }
      if (!changed && iter > 0) break;
      for (std::size_t j = 0; j < centres.size(); ++j) {
        Anchor sum{c, 0, 0, 0, 0, 0};
        int n = 0;
        for (std::size_t i = 0; i < pts.size(); ++i)
          if (assign[i] == static_cast<int>(j)) {
            sum.length += pts[i].length, sum.width += pts[i].width, sum.height += pts[i].height, sum.z += pts[i].z;
            ++n;
          }
        if (n > 0) centres[j] = {c, sum.length / n, sum.width / n, sum.height / n, sum.z / n, 0};
      }
    }
    sortByArea(&centres);
    out.insert(out.end(), centres.begin(), centres.end());
  }
  return out;
}

void assignAnchorStrides(std::vector<Anchor>* anchors, std::vector<int> strides, double resolution, double fraction) {
  std::sort(strides.begin(), strides.end());
  for (auto& a : *anchors) {
    a.stride = strides.front();
    for (int s : strides)
      if (s * resolution <= fraction * std::max(a.length, a.width)) a.stride = s;
  }
}

}  // namespace ret3d
