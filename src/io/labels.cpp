// KITTI label files: object layout (label_2, 15 fields + optional score) and tracking layout (label_02, frame and
// track id first, truncation an integer, 17 fields + optional score).
#include <cmath>
#include <stdexcept>

#include "ret3d/io/kitti.h"
#include "text_fields.h"

namespace ret3d {
namespace kitti {
namespace {

// Field names as the KITTI devkit readme calls them; used in error messages.
constexpr const char* kObjectFields[] = {"type",       "truncated",    "occluded", "alpha",  "bbox_left",
                                         "bbox_top",   "bbox_right",   "bbox_bottom", "height", "width",
                                         "length",     "x",            "y",        "z",      "rotation_y",
                                         "score"};
constexpr int kObjectFieldCount = 15;  // without score

Label parseLine(const std::vector<std::string_view>& f, const detail::Where& where, bool tracking) {
  const int offset = tracking ? 2 : 0;
  const int base = kObjectFieldCount + offset;
  const int n = static_cast<int>(f.size());
  const auto fieldName = [&](int i) -> std::string {
    if (i < offset) return i == 0 ? "frame" : "track_id";
    return kObjectFields[i - offset];
  };
  const std::string layout = tracking ? "tracking layout: 17, or 18 with score" : "object layout: 15, or 16 with score";
  if (n < base) {
    detail::fail(where, fieldName(n),
                 "missing; the line has " + std::to_string(n) + " fields (" + layout + ")");
  }
  if (n > base + 1) {
    detail::fail(where, fieldName(base),
                 "followed by " + std::to_string(n - base - 1) + " extra field(s); the line has " + std::to_string(n) +
                     " fields (" + layout + ")");
  }

  Label l;
  const auto num = [&](int i) { return detail::parseDouble(f[i], where, fieldName(i)); };
  const auto integer = [&](int i) { return detail::parseInt(f[i], where, fieldName(i)); };
  if (tracking) {
    l.frame = integer(0);
    l.track_id = integer(1);
    if (l.frame < 0) detail::fail(where, "frame", "negative frame index " + std::string(f[0]));
  }
  l.type = std::string(f[offset]);
  // Tracking truncation is an integer level (0, 1, 2; -1 for DontCare); the object layout's is a fraction.
  l.truncated = tracking ? integer(offset + 1) : num(offset + 1);
  l.occluded = integer(offset + 2);
  l.alpha = num(offset + 3);
  for (int k = 0; k < 4; ++k) l.bbox[k] = num(offset + 4 + k);
  l.h = num(offset + 8);
  l.w = num(offset + 9);
  l.l = num(offset + 10);
  l.x = num(offset + 11);
  l.y = num(offset + 12);
  l.z = num(offset + 13);
  l.rotation_y = num(offset + 14);
  if (n == base + 1) l.score = num(base);
  return l;
}

std::vector<Label> readLabels(const std::string& path, bool tracking) {
  std::vector<Label> labels;
  detail::forEachLine(path, [&](const auto& fields, const detail::Where& where) {
    labels.push_back(parseLine(fields, where, tracking));
  });
  return labels;
}

// Fixed notation with 6 decimals: what the KITTI tracking labels use, and enough for a 1e-4 round trip.
constexpr int kDigits = 6;

void appendCommon(std::string& s, const Label& l, bool tracking) {
  // The type is one whitespace-free token, or the line would not read back.
  std::string type = l.type.empty() ? std::string("DontCare") : l.type;
  for (char& c : type) {
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') c = '_';
  }
  s += type;
  s += ' ';
  if (tracking) {
    s += std::to_string(static_cast<int>(std::lround(l.truncated)));
  } else {
    detail::appendFixed(s, l.truncated, kDigits);
  }
  s += ' ';
  s += std::to_string(l.occluded);
  const double values[] = {l.alpha, l.bbox[0], l.bbox[1], l.bbox[2], l.bbox[3], l.h, l.w,
                           l.l,     l.x,       l.y,       l.z,       l.rotation_y};
  for (double v : values) {
    s += ' ';
    detail::appendFixed(s, v, kDigits);
  }
  if (l.score) {
    s += ' ';
    detail::appendFixed(s, *l.score, kDigits);
  }
}

void writeLines(const std::string& path, const std::vector<Label>& labels, bool tracking) {
  std::string s;
  for (const Label& l : labels) {
    s += tracking ? formatTrackingLabel(l) : formatObjectLabel(l);
    s += '\n';
  }
  detail::writeText(path, s);
}

}  // namespace

std::vector<Label> readObjectLabels(const std::string& path) { return readLabels(path, false); }
std::vector<Label> readTrackingLabels(const std::string& path) { return readLabels(path, true); }

std::string formatObjectLabel(const Label& l) {
  std::string s;
  appendCommon(s, l, false);
  return s;
}

std::string formatTrackingLabel(const Label& l) {
  // boxToLabel leaves frame at -1: writing that would give a file no reader (ours included) accepts.
  if (l.frame < 0) throw std::invalid_argument("tracking label without a frame index (frame = -1): set Label::frame");
  std::string s = std::to_string(l.frame) + ' ' + std::to_string(l.track_id) + ' ';
  appendCommon(s, l, true);
  return s;
}

void writeObjectLabels(const std::string& path, const std::vector<Label>& labels) { writeLines(path, labels, false); }
void writeTrackingLabels(const std::string& path, const std::vector<Label>& labels) { writeLines(path, labels, true); }

}  // namespace kitti
}  // namespace ret3d
