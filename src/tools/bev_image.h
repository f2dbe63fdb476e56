// A bird's-eye-view picture of a scan with boxes drawn over it, written as PNG by zlib (no external tool): what
// `ret3d draw` makes (docs/real_*.png). The image shows the sensor frame from above with x (forward) pointing up
// the image and y (left) to the left, so it reads like a map with the vehicle driving upwards.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ret3d/core/types.h"

namespace ret3d {
namespace tools {

using Rgb = std::array<std::uint8_t, 3>;

// An RGB colour with channels in [0, 1] (e.g. classColour of src/ros/markers.h) as 8-bit channels.
Rgb toRgb(const std::array<float, 3>& unit);

// The ground rectangle an image shows, metres in the sensor frame, and its scale.
struct BevView {
  double x_min = -48.0, x_max = 48.0;
  double y_min = -48.0, y_max = 48.0;
  double pixels_per_metre = 10.0;
};

// How a point's grey level is chosen: its intensity (reflectance) or its height.
enum class PointShade { Intensity, Height };

class BevImage {
 public:
  // A black image of the view. Throws std::invalid_argument for an empty extent, a non-positive scale or a side
  // of more than 10000 pixels.
  explicit BevImage(const BevView& view);
  // A black canvas of width x height pixels for text and composition (its view: 1 pixel per metre from the origin).
  BevImage(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  const BevView& view() const { return view_; }

  // Continuous pixel coordinates (column, row) of the ground point (x, y); pixel (c, r) covers [c, c+1) x [r, r+1).
  Eigen::Vector2d toPixel(double x, double y) const;
  // Throws std::out_of_range outside the image.
  Rgb pixel(int col, int row) const;
  // Ignored outside the image.
  void setPixel(int col, int row, const Rgb& c);
  void fillRect(int col, int row, int w, int h, const Rgb& c);
  // Copies `src` with its top-left corner at (col, row); what falls outside is cut off.
  void paste(const BevImage& src, int col, int row);

  // One pixel per point, grey from dark to white by intensity, or by height between z_min and z_max; where several
  // points fall on one pixel the brightest wins. Points outside the view are skipped.
  void drawPoints(const PointCloud& cloud, PointShade shade, double z_min = -2.5, double z_max = 1.0);
  // A straight line between pixel positions, `thickness` pixels wide; clipped to the image.
  void drawLine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Rgb& c, int thickness = 1);
  // The same between ground points (x, y).
  void drawGroundLine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Rgb& c, int thickness = 1);
  // The box's BEV outline (core bevCorners) and, with `heading`, a line from its centre to the middle of its front
  // edge, so the direction it faces shows.
  void drawBox(const Box& box, const Rgb& c, int thickness = 1, bool heading = true);
  // A circle of `radius` metres around the ground point (x, y), e.g. range rings.
  void drawGroundCircle(double x, double y, double radius, const Rgb& c);

  // Text in a 5 x 7 pixel font (upper case, digits, common punctuation; lower case is drawn as upper case, other
  // characters as '?'), each font pixel `scale` x `scale` image pixels, top-left corner at (col, row).
  // Returns the width drawn, in pixels.
  int drawText(int col, int row, const std::string& text, const Rgb& c, int scale = 1);
  // Width and height of drawText's output for `text`, without drawing.
  static int textWidth(const std::string& text, int scale = 1);
  static int textHeight(int scale = 1) { return 7 * scale; }

  // The image as a PNG file (8-bit RGB, zlib level 9, one filter per row chosen by the usual minimum-sum heuristic).
  std::vector<std::uint8_t> encodePng() const;
  // Throws std::runtime_error naming the file when it cannot be written.
  void writePng(const std::string& path) const;

 private:
  void stamp(int col, int row, const Rgb& c, int thickness);

  BevView view_;
  int width_ = 0, height_ = 0;
  std::vector<std::uint8_t> rgb_;  // row-major, 3 bytes per pixel
};

}  // namespace tools
}  // namespace ret3d
