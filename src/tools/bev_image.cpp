// Bird's-eye-view raster and PNG writer (src/tools/bev_image.h).
#include "tools/bev_image.h"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace tools {
namespace {

// The 5 x 7 font: 7 rows of 5 columns each, '#' set.
struct Glyph {
  char ch;
  const char* rows;  // 35 characters
};

// clang-format off
constexpr Glyph kFont[] = {
  {' ', "..................................."},
  {'0', ".###.#...##..###.#.###..##...#.###."},
  {'1', "..#...##....#....#....#....#...###."},
  {'2', ".###.#...#....#...#...#...#...#####"},
  {'3', "#####...#...#.....#.....##...#.###."},
  {'4', "...#...##..#.#.#..#.#####...#....#."},
  {'5', "######....####.....#....##...#.###."},
  {'6', "..##..#...#....####.#...##...#.###."},
  {'7', "#####....#...#...#...#....#....#..."},
  {'8', ".###.#...##...#.###.#...##...#.###."},
  {'9', ".###.#...##...#.####....#...#..##.."},
  {'A', ".###.#...##...#######...##...##...#"},
  {'B', "####.#...##...#####.#...##...#####."},
  {'C', ".###.#...##....#....#....#...#.###."},
  {'D', "###..#..#.#...##...##...##..#.###.."},
  {'E', "######....#....####.#....#....#####"},
  {'F', "######....#....####.#....#....#...."},
  {'G', ".###.#...##....#.####...##...#.####"},
  {'H', "#...##...##...#######...##...##...#"},
  {'I', ".###...#....#....#....#....#...###."},
  {'J', "..###...#....#....#....#.#..#..##.."},
  {'K', "#...##..#.#.#..##...#.#..#..#.#...#"},
  {'L', "#....#....#....#....#....#....#####"},
  {'M', "#...###.###.#.##.#.##...##...##...#"},
  {'N', "#...##...###..##.#.##..###...##...#"},
  {'O', ".###.#...##...##...##...##...#.###."},
  {'P', "####.#...##...#####.#....#....#...."},
  {'Q', ".###.#...##...##...##.#.##..#..##.#"},
  {'R', "####.#...##...#####.#.#..#..#.#...#"},
  {'S', ".#####....#.....###.....#....#####."},
  {'T', "#####..#....#....#....#....#....#.."},
  {'U', "#...##...##...##...##...##...#.###."},
  {'V', "#...##...##...##...##...#.#.#...#.."},
  {'W', "#...##...##...##.#.##.#.##.#.#.#.#."},
  {'X', "#...##...#.#.#...#...#.#.#...##...#"},
  {'Y', "#...##...#.#.#...#....#....#....#.."},
  {'Z', "#####....#...#...#...#...#....#####"},
  {'.', "..........................##...##.."},
  {',', ".....................##....#...#..."},
  {':', "......##...##........##...##......."},
  {';', "......##...##........##....#...#..."},
  {'-', "...............#####..............."},
  {'_', "..............................#####"},
  {'/', ".........#...#...#...#...#........."},
  {'(', "...#...#...#....#....#.....#.....#."},
  {')', ".#.....#.....#....#....#...#...#..."},
  {'[', ".###..#....#....#....#....#....###."},
  {']', ".###....#....#....#....#....#..###."},
  {'%', "##...##..#...#...#...#...#..##...##"},
  {'=', "..........#####.....#####.........."},
  {'+', ".......#....#..#####..#....#......."},
  {'<', "...#...#...#...#.....#.....#.....#."},
  {'>', ".#.....#.....#.....#...#...#...#..."},
  {'#', ".#.#..#.#.#####.#.#.#####.#.#..#.#."},
  {'\'', "..#....#...#......................."},
  {'*', ".......#..#.#.#.###.#.#.#..#......."},
  {'!', "..#....#....#....#....#.........#.."},
  {'?', ".###.#...#....#...#...#.........#.."},
  {'|', "..#....#....#....#....#....#....#.."},
};
// clang-format on

const char* glyphRows(char ch) {
  const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  for (const Glyph& g : kFont)
    if (g.ch == up) return g.rows;
  for (const Glyph& g : kFont)
    if (g.ch == '?') return g.rows;
  return nullptr;
}

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

void putChunk(std::vector<std::uint8_t>& out, const char type[5], const std::vector<std::uint8_t>& data) {
  putU32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  // The CRC covers the chunk type and data (PNG spec §5.3).
  const uLong crc = crc32(crc32(0L, Z_NULL, 0), out.data() + start, static_cast<uInt>(out.size() - start));
  putU32(out, static_cast<std::uint32_t>(crc));
}

// PNG's Paeth predictor (PNG spec §9.4).
std::uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<std::uint8_t>(a);
  return static_cast<std::uint8_t>(pb <= pc ? b : c);
}

}  // namespace

Rgb toRgb(const std::array<float, 3>& unit) {
  Rgb out;
  for (int i = 0; i < 3; ++i)
    out[i] = static_cast<std::uint8_t>(std::lround(255.0f * std::clamp(unit[i], 0.0f, 1.0f)));
  return out;
}

BevImage::BevImage(const BevView& view) : view_(view) {
  if (!(view.x_max > view.x_min) || !(view.y_max > view.y_min))
    throw std::invalid_argument("BEV image: empty extent x [" + std::to_string(view.x_min) + ", " +
                                std::to_string(view.x_max) + "] y [" + std::to_string(view.y_min) + ", " +
                                std::to_string(view.y_max) + "]");
  if (!(view.pixels_per_metre > 0)) throw std::invalid_argument("BEV image: pixels per metre must be positive");
  const double w = std::ceil((view.y_max - view.y_min) * view.pixels_per_metre - 1e-9);
  const double h = std::ceil((view.x_max - view.x_min) * view.pixels_per_metre - 1e-9);
  if (w > 10000 || h > 10000)
    throw std::invalid_argument("BEV image: " + std::to_string(static_cast<long>(w)) + " x " +
                                std::to_string(static_cast<long>(h)) + " pixels is more than 10000 a side");
  width_ = std::max(1, static_cast<int>(w));
  height_ = std::max(1, static_cast<int>(h));
  rgb_.assign(static_cast<std::size_t>(width_) * height_ * 3, 0);
}

BevImage::BevImage(int width, int height)
    : BevImage(BevView{0.0, static_cast<double>(std::max(1, height)), 0.0, static_cast<double>(std::max(1, width)),
                       1.0}) {}

Eigen::Vector2d BevImage::toPixel(double x, double y) const {
  return {(view_.y_max - y) * view_.pixels_per_metre, (view_.x_max - x) * view_.pixels_per_metre};
}

Rgb BevImage::pixel(int col, int row) const {
  if (col < 0 || row < 0 || col >= width_ || row >= height_)
    throw std::out_of_range("BEV image: pixel (" + std::to_string(col) + ", " + std::to_string(row) + ") outside " +
                            std::to_string(width_) + " x " + std::to_string(height_));
  const std::size_t i = (static_cast<std::size_t>(row) * width_ + col) * 3;
  return {rgb_[i], rgb_[i + 1], rgb_[i + 2]};
}

void BevImage::setPixel(int col, int row, const Rgb& c) {
  if (col < 0 || row < 0 || col >= width_ || row >= height_) return;
  const std::size_t i = (static_cast<std::size_t>(row) * width_ + col) * 3;
  rgb_[i] = c[0];
  rgb_[i + 1] = c[1];
  rgb_[i + 2] = c[2];
}

void BevImage::fillRect(int col, int row, int w, int h, const Rgb& c) {
  for (int r = std::max(0, row); r < std::min(height_, row + h); ++r)
    for (int k = std::max(0, col); k < std::min(width_, col + w); ++k) setPixel(k, r, c);
}

void BevImage::paste(const BevImage& src, int col, int row) {
  for (int r = 0; r < src.height_; ++r)
    for (int k = 0; k < src.width_; ++k) setPixel(col + k, row + r, src.pixel(k, r));
}

void BevImage::drawPoints(const PointCloud& cloud, PointShade shade, double z_min, double z_max) {
  const double z_span = std::max(1e-6, z_max - z_min);
  for (const Point& p : cloud.points) {
    const Eigen::Vector2d px = toPixel(p.x, p.y);
    const int col = static_cast<int>(std::floor(px.x())), row = static_cast<int>(std::floor(px.y()));
    if (col < 0 || row < 0 || col >= width_ || row >= height_) continue;
    // A floor of 60 keeps dark returns visible against the black background; sqrt spreads KITTI's mostly low
    // reflectances over the grey range.
    const double t = shade == PointShade::Intensity ? std::sqrt(std::clamp<double>(p.intensity, 0.0, 1.0))
                                                    : std::clamp((p.z - z_min) / z_span, 0.0, 1.0);
    const auto v = static_cast<std::uint8_t>(std::lround(60.0 + 195.0 * t));
    const std::size_t i = (static_cast<std::size_t>(row) * width_ + col) * 3;
    if (rgb_[i] < v) rgb_[i] = rgb_[i + 1] = rgb_[i + 2] = v;
  }
}

void BevImage::stamp(int col, int row, const Rgb& c, int thickness) {
  const int lo = -(thickness - 1) / 2;
  for (int dr = lo; dr < lo + thickness; ++dr)
    for (int dc = lo; dc < lo + thickness; ++dc) setPixel(col + dc, row + dr, c);
}

void BevImage::drawLine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Rgb& c, int thickness) {
  thickness = std::max(1, thickness);
  // Liang-Barsky clipping to the image (plus the line's width), so a box far outside costs nothing.
  const double margin = thickness + 1.0;
  double t0 = 0, t1 = 1;
  const Eigen::Vector2d d = b - a;
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {a.x() + margin, width_ + margin - a.x(), a.y() + margin, height_ + margin - a.y()};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
    if (t0 > t1) return;
  }
  const Eigen::Vector2d s = a + t0 * d, e = a + t1 * d;
  // Two samples per pixel of length: every pixel the line crosses is hit.
  const int n = std::max(1, static_cast<int>(std::ceil(2.0 * (e - s).cwiseAbs().maxCoeff())));
  for (int i = 0; i <= n; ++i) {
    const Eigen::Vector2d q2 = s + (e - s) * (static_cast<double>(i) / n);
    stamp(static_cast<int>(std::floor(q2.x())), static_cast<int>(std::floor(q2.y())), c, thickness);
  }
}

void BevImage::drawGroundLine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Rgb& c, int thickness) {
  drawLine(toPixel(a.x(), a.y()), toPixel(b.x(), b.y()), c, thickness);
}

void BevImage::drawBox(const Box& box, const Rgb& c, int thickness, bool heading) {
  const auto corners = bevCorners(box);  // counter-clockwise from front-left
  for (int i = 0; i < 4; ++i) drawGroundLine(corners[i], corners[(i + 1) % 4], c, thickness);
  if (heading) {
    // Front-left and the corner before it (front-right, the last one counter-clockwise) bound the front edge.
    const Eigen::Vector2d front = 0.5 * (corners[0] + corners[3]);
    drawGroundLine(Eigen::Vector2d(box.x, box.y), front, c, thickness);
  }
}

void BevImage::drawGroundCircle(double x, double y, double radius, const Rgb& c) {
  const double r_px = radius * view_.pixels_per_metre;
  const int n = std::max(16, static_cast<int>(std::ceil(2.0 * M_PI * r_px)));
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    const Eigen::Vector2d p = toPixel(x + radius * std::cos(a), y + radius * std::sin(a));
    setPixel(static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())), c);
  }
}

int BevImage::textWidth(const std::string& text, int scale) {
  return text.empty() ? 0 : static_cast<int>(text.size()) * 6 * scale - scale;
}

int BevImage::drawText(int col, int row, const std::string& text, const Rgb& c, int scale) {
  scale = std::max(1, scale);
  int x = col;
  for (const char ch : text) {
    const char* rows = glyphRows(ch);
    for (int r = 0; r < 7; ++r)
      for (int k = 0; k < 5; ++k)
        if (rows[r * 5 + k] == '#') fillRect(x + k * scale, row + r * scale, scale, scale, c);
    x += 6 * scale;  // one blank column between characters
  }
  return textWidth(text, scale);
}

std::vector<std::uint8_t> BevImage::encodePng() const {
  // Filtered scanlines (PNG spec §9): per row the filter (None, Sub, Up, Average, Paeth) whose output has the
  // smallest sum of absolute signed bytes, the heuristic libpng uses.
  const std::size_t stride = static_cast<std::size_t>(width_) * 3;
  std::vector<std::uint8_t> raw;
  raw.reserve((stride + 1) * height_);
  std::vector<std::uint8_t> best(stride), trial(stride);
  for (int r = 0; r < height_; ++r) {
    const std::uint8_t* cur = rgb_.data() + r * stride;
    const std::uint8_t* up = r > 0 ? cur - stride : nullptr;
    long best_sum = -1;
    std::uint8_t best_type = 0;
    for (std::uint8_t type = 0; type < 5; ++type) {
      long sum = 0;
      for (std::size_t i = 0; i < stride; ++i) {
        const int a = i >= 3 ? cur[i - 3] : 0, b = up ? up[i] : 0, c = (i >= 3 && up) ? up[i - 3] : 0;
        int pred = 0;
        switch (type) {
          case 1: pred = a; break;
          case 2: pred = b; break;
          case 3: pred = (a + b) / 2; break;
          case 4: pred = paeth(a, b, c); break;
          default: break;
        }
        trial[i] = static_cast<std::uint8_t>(cur[i] - pred);
        sum += std::abs(static_cast<int>(static_cast<std::int8_t>(trial[i])));
      }
      if (best_sum < 0 || sum < best_sum) {
        best_sum = sum;
        best_type = type;
        best.swap(trial);
      }
    }
    raw.push_back(best_type);
    raw.insert(raw.end(), best.begin(), best.end());
  }
  uLongf packed_size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<std::uint8_t> packed(packed_size);
  if (compress2(packed.data(), &packed_size, raw.data(), static_cast<uLong>(raw.size()), 9) != Z_OK)
    throw std::runtime_error("BEV image: zlib compression failed");
  packed.resize(packed_size);

  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<std::uint8_t> ihdr;
  putU32(ihdr, static_cast<std::uint32_t>(width_));
  putU32(ihdr, static_cast<std::uint32_t>(height_));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, adaptive filtering, no interlace
  putChunk(png, "IHDR", ihdr);
  putChunk(png, "IDAT", packed);
  putChunk(png, "IEND", {});
  return png;
}

void BevImage::writePng(const std::string& path) const {
  const std::vector<std::uint8_t> png = encodePng();
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error(path + ": cannot open for writing");
  f.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  if (!f) throw std::runtime_error(path + ": write failed");
}

}  // namespace tools
}  // namespace ret3d
