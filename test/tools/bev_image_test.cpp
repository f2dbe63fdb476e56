// The bird's-eye-view raster of `ret3d draw`: where things land in the image, and a PNG any decoder reads back.
#include "tools/bev_image.h"

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

namespace ret3d {
namespace tools {
namespace {

const Rgb kBlack{0, 0, 0};
const Rgb kGreen{0, 255, 0};

// 20 m x 20 m around the sensor at 10 px/m: 200 x 200 pixels; ground (x, y) is at column (10 - y) * 10,
// row (10 - x) * 10.
BevView smallView() {
  BevView v;
  v.x_min = v.y_min = -10.0;
  v.x_max = v.y_max = 10.0;
  v.pixels_per_metre = 10.0;
  return v;
}

TEST(BevImage, ForwardIsUpAndLeftIsLeft) {
  BevImage img(smallView());
  EXPECT_EQ(img.width(), 200);
  EXPECT_EQ(img.height(), 200);
  const Eigen::Vector2d ahead = img.toPixel(5.0, 0.0), left = img.toPixel(0.0, 5.0);
  EXPECT_DOUBLE_EQ(ahead.x(), 100.0);
  EXPECT_DOUBLE_EQ(ahead.y(), 50.0);  // 5 m ahead: upper half
  EXPECT_DOUBLE_EQ(left.x(), 50.0);   // 5 m to the left: left half
  EXPECT_DOUBLE_EQ(left.y(), 100.0);
}

TEST(BevImage, BoxOutlineAndHeadingLandOnTheExpectedPixels) {
  BevImage img(smallView());
  Box b;  // x 3..7, y -4..-2, facing +x: columns 120..140, rows 30..70, front edge at row 30
  b.x = 5.0;
  b.y = -3.0;
  b.length = 4.0;
  b.width = 2.0;
  b.yaw = 0.0;
  img.drawBox(b, kGreen, 1, true);
  EXPECT_EQ(img.pixel(126, 30), kGreen);  // front edge
  EXPECT_EQ(img.pixel(126, 70), kGreen);  // rear edge
  EXPECT_EQ(img.pixel(120, 60), kGreen);  // left side (y = -2)
  EXPECT_EQ(img.pixel(140, 60), kGreen);  // right side (y = -4)
  EXPECT_EQ(img.pixel(130, 40), kGreen);  // heading: centre (130, 50) to the front edge's middle (130, 30)
  EXPECT_EQ(img.pixel(130, 60), kBlack);  // behind the centre: no heading line
  EXPECT_EQ(img.pixel(125, 45), kBlack);  // inside, off the heading line
  EXPECT_EQ(img.pixel(100, 100), kBlack);  // the sensor
  EXPECT_EQ(img.pixel(145, 50), kBlack);  // outside
}

TEST(BevImage, HeadingFollowsYaw) {
  BevImage img(smallView());
  Box b;  // just ahead of the sensor, facing left (+y): the heading runs along row 99 from column 100 to column 80
  b.x = 0.05;
  b.length = 4.0;
  b.width = 2.0;
  b.yaw = M_PI / 2;
  img.drawBox(b, kGreen, 1, true);
  EXPECT_EQ(img.pixel(90, 99), kGreen);
  EXPECT_EQ(img.pixel(110, 99), kBlack);
}

TEST(BevImage, BrightestPointWinsAndOutsidePointsAreSkipped) {
  BevImage img(smallView());
  PointCloud cloud;
  cloud.points.push_back({0.05f, 0.05f, 0.0f, 0.0f});   // pixel (99, 99), dark
  cloud.points.push_back({0.05f, 0.05f, 0.0f, 1.0f});   // same pixel, full intensity
  cloud.points.push_back({0.05f, -5.05f, 0.0f, 0.0f});  // pixel (150, 99), intensity 0
  cloud.points.push_back({50.0f, 0.0f, 0.0f, 1.0f});    // outside
  img.drawPoints(cloud, PointShade::Intensity);
  EXPECT_EQ(img.pixel(99, 99), (Rgb{255, 255, 255}));
  EXPECT_EQ(img.pixel(150, 99), (Rgb{60, 60, 60}));  // dark returns stay visible
  int lit = 0;
  for (int r = 0; r < img.height(); ++r)
    for (int c = 0; c < img.width(); ++c) lit += img.pixel(c, r) != kBlack;
  EXPECT_EQ(lit, 2);

  BevImage by_height(smallView());
  PointCloud high;
  high.points.push_back({0.05f, 0.05f, 1.0f, 0.0f});  // at z_max: white whatever the intensity
  by_height.drawPoints(high, PointShade::Height, -2.5, 1.0);
  EXPECT_EQ(by_height.pixel(99, 99), (Rgb{255, 255, 255}));
}

TEST(BevImage, LinesFarOutsideAreClippedNotDrawn) {
  BevImage img(smallView());
  img.drawLine({-1e7, -5.0}, {1e7, -5.0}, kGreen, 3);  // above the image
  for (int c = 0; c < img.width(); c += 7) EXPECT_EQ(img.pixel(c, 0), kBlack);
  img.drawLine({-1e7, 10.5}, {1e7, 10.5}, kGreen, 1);  // through row 10, across the whole width
  EXPECT_EQ(img.pixel(0, 10), kGreen);
  EXPECT_EQ(img.pixel(199, 10), kGreen);
}

TEST(BevImage, TextIsDrawnInTheFont) {
  BevImage img(smallView());
  EXPECT_EQ(BevImage::textWidth("Car", 2), 34);  // 3 glyphs of 5 columns + 2 gaps, doubled
  EXPECT_EQ(img.drawText(10, 10, "I", kGreen, 1), 5);
  // 'I': a bar across the top (columns 1-3), a stem in the middle column.
  EXPECT_EQ(img.pixel(11, 10), kGreen);
  EXPECT_EQ(img.pixel(10, 10), kBlack);
  EXPECT_EQ(img.pixel(12, 13), kGreen);
  EXPECT_EQ(img.pixel(11, 13), kBlack);
}

TEST(BevImage, RefusesAnEmptyOrHugeView) {
  BevView v = smallView();
  v.x_max = v.x_min;
  EXPECT_THROW(BevImage{v}, std::invalid_argument);
  v = smallView();
  v.pixels_per_metre = 1000.0;
  EXPECT_THROW(BevImage{v}, std::invalid_argument);
  EXPECT_THROW(BevImage(smallView()).pixel(200, 0), std::out_of_range);
}

std::uint32_t be32(const std::vector<std::uint8_t>& d, std::size_t at) {
  return (std::uint32_t(d[at]) << 24) | (std::uint32_t(d[at + 1]) << 16) | (std::uint32_t(d[at + 2]) << 8) | d[at + 3];
}

// A minimal PNG reader (RGB 8-bit, one IDAT chunk or several): checks every CRC, inflates, undoes the filters.
std::vector<std::uint8_t> decodePng(const std::vector<std::uint8_t>& png, int* w, int* h) {
  const std::uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  EXPECT_TRUE(std::equal(sig, sig + 8, png.begin()));
  std::vector<std::uint8_t> idat;
  std::size_t at = 8;
  bool end = false;
  while (at + 12 <= png.size() && !end) {
    const std::uint32_t len = be32(png, at);
    const std::string type(png.begin() + at + 4, png.begin() + at + 8);
    const uLong crc = crc32(crc32(0L, Z_NULL, 0), png.data() + at + 4, len + 4);
    EXPECT_EQ(crc, be32(png, at + 8 + len)) << type;
    if (type == "IHDR") {
      *w = static_cast<int>(be32(png, at + 8));
      *h = static_cast<int>(be32(png, at + 12));
      EXPECT_EQ(png[at + 16], 8);  // bit depth
      EXPECT_EQ(png[at + 17], 2);  // RGB
    } else if (type == "IDAT") {
      idat.insert(idat.end(), png.begin() + at + 8, png.begin() + at + 8 + len);
    } else if (type == "IEND") {
      end = true;
    }
    at += 12 + len;
  }
  EXPECT_TRUE(end);
  const std::size_t stride = static_cast<std::size_t>(*w) * 3;
  std::vector<std::uint8_t> raw((stride + 1) * *h);
  uLongf raw_size = raw.size();
  EXPECT_EQ(uncompress(raw.data(), &raw_size, idat.data(), idat.size()), Z_OK);
  EXPECT_EQ(raw_size, raw.size());
  std::vector<std::uint8_t> out(stride * *h);
  for (int r = 0; r < *h; ++r) {
    const std::uint8_t type = raw[r * (stride + 1)];
    const std::uint8_t* in = raw.data() + r * (stride + 1) + 1;
    std::uint8_t* cur = out.data() + r * stride;
    const std::uint8_t* up = r > 0 ? cur - stride : nullptr;
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= 3 ? cur[i - 3] : 0, b = up ? up[i] : 0, c = (i >= 3 && up) ? up[i - 3] : 0;
      int pred = 0;
      if (type == 1) pred = a;
      if (type == 2) pred = b;
      if (type == 3) pred = (a + b) / 2;
      if (type == 4) {
        const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        pred = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
      }
      EXPECT_LE(type, 4);
      cur[i] = static_cast<std::uint8_t>(in[i] + pred);
    }
  }
  return out;
}

TEST(BevImage, PngDecodesToTheSamePixels) {
  BevImage img(smallView());
  PointCloud cloud;
  for (int i = 0; i < 2000; ++i)  // a spiral of points with varied intensity: every filter gets used
    cloud.points.push_back({static_cast<float>(0.004 * i * std::cos(0.05 * i)),
                            static_cast<float>(0.004 * i * std::sin(0.05 * i)), 0.0f, static_cast<float>(i % 97) / 96});
  img.drawPoints(cloud, PointShade::Intensity);
  Box b;
  b.x = 2.0;
  b.length = 4.0;
  b.width = 1.8;
  b.yaw = 0.4;
  img.drawBox(b, {255, 160, 0}, 2, true);
  img.drawText(2, 2, "Cyclist 0.87", {255, 0, 255}, 2);
  int w = 0, h = 0;
  const std::vector<std::uint8_t> pixels = decodePng(img.encodePng(), &w, &h);
  ASSERT_EQ(w, img.width());
  ASSERT_EQ(h, img.height());
  int mismatches = 0;
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const std::uint8_t* p = pixels.data() + (static_cast<std::size_t>(r) * w + c) * 3;
      mismatches += Rgb{p[0], p[1], p[2]} != img.pixel(c, r);
    }
  EXPECT_EQ(mismatches, 0);
}

}  // namespace
}  // namespace tools
}  // namespace ret3d
