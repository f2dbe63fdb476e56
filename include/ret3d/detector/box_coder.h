// Box <-> regression targets of the two heads, on plain floats, shared by target assignment (training) and decoding
// (inference) so both read the same encoding.
#pragma once

#include <array>

#include "ret3d/bev/bev_encoder.h"
#include "ret3d/core/types.h"
#include "ret3d/detector/anchors.h"

namespace ret3d {

// Regression values after the head's activations, in the order the head maps hold them.
//   anchor head: dx, dy (box centre minus the cell corner, in cells; 2 sigmoid - 0.5 so in (-0.5, 1.5), which lets a
//                neighbouring cell predict the box, YOLOv5), dz = (z - z_a) / h_a, log(l / l_a), log(w / w_a),
//                log(h / h_a), sin(yaw), cos(yaw) (Complex-YOLO's Euler encoding), vx dt, vy dt (metres per sweep)
//   centre head: dx, dy (in [0, 1) within the centre cell), z, log l, log w, log h, sin, cos, vx dt, vy dt
constexpr int kBoxCodeSize = 10;
using BoxCode = std::array<float, kBoxCodeSize>;

// (u, v): the cell of a feature map of the given stride; dt: seconds between the sweeps.
BoxCode encodeAnchorBox(const Box& box, const Anchor& anchor, int u, int v, int stride, const BevGeometry& g,
                        double dt);
Box decodeAnchorBox(const BoxCode& code, const Anchor& anchor, int u, int v, int stride, const BevGeometry& g,
                    double dt);
BoxCode encodeCenterBox(const Box& box, int u, int v, int stride, const BevGeometry& g, double dt);
Box decodeCenterBox(const BoxCode& code, int u, int v, int stride, const BevGeometry& g, double dt);

}  // namespace ret3d
