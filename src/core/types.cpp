#include "ret3d/core/types.h"

namespace ret3d {

const char* className(ObjectClass c) {
  switch (c) {
    case ObjectClass::Car: return "Car";
    case ObjectClass::Pedestrian: return "Pedestrian";
    case ObjectClass::Cyclist: return "Cyclist";
    case ObjectClass::Unknown: break;
  }
  return "Unknown";
}

std::optional<ObjectClass> classFromName(std::string_view name) {
  for (ObjectClass c : kDetectedClasses) {
    if (name == className(c)) return c;
  }
  return std::nullopt;
}

void PointCloud::push_back(const Point& p, float t, std::uint16_t r, bool with_extras) {
  points.push_back(p);
  if (with_extras || !time.empty()) time.push_back(t);
  if (with_extras || !ring.empty()) ring.push_back(r);
}

}  // namespace ret3d
