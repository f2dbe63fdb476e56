// rviz markers for objects (include/ret3d/ros/markers.h).
#include "ret3d/ros/markers.h"

#include <cmath>
#include <cstdio>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace {

geometry_msgs::Point point(const Eigen::Vector3d& v) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}

visualization_msgs::Marker base(const std_msgs::Header& header, const std::string& ns, int id, int type,
                                ObjectClass label) {
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  const auto c = classColour(label);
  m.color.r = c[0];
  m.color.g = c[1];
  m.color.b = c[2];
  m.color.a = 1.0f;
  return m;
}

}  // namespace

std::array<float, 3> classColour(ObjectClass c) {
  switch (c) {
    case ObjectClass::Car: return {0.0f, 1.0f, 0.0f};
    case ObjectClass::Pedestrian: return {1.0f, 0.0f, 1.0f};
    case ObjectClass::Cyclist: return {1.0f, 160.0f / 255.0f, 0.0f};
    default: return {0.6f, 0.6f, 0.6f};
  }
}

namespace {

// The box's 12 edges (boxCorners' order: bottom ring, top ring, verticals) and its front face's diagonal cross, which
// shows the heading.
visualization_msgs::Marker boxEdges(const std_msgs::Header& header, int id, const Box& b, double line_width) {
  static const int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                    {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  visualization_msgs::Marker edges = base(header, "boxes", id, visualization_msgs::Marker::LINE_LIST, b.label);
  edges.scale.x = line_width;
  const auto corners = boxCorners(b);
  for (const auto& e : kEdges) {
    edges.points.push_back(point(corners[e[0]]));
    edges.points.push_back(point(corners[e[1]]));
  }
  edges.points.push_back(point(corners[0]));
  edges.points.push_back(point(corners[7]));
  edges.points.push_back(point(corners[3]));
  edges.points.push_back(point(corners[4]));
  return edges;
}

// "Class #track score" (without a track: "Class score") above the box.
visualization_msgs::Marker boxLabel(const std_msgs::Header& header, int id, const Box& b, double text_size) {
  visualization_msgs::Marker text =
      base(header, "labels", id, visualization_msgs::Marker::TEXT_VIEW_FACING, b.label);
  text.pose.position = point(Eigen::Vector3d(b.x, b.y, b.top() + 0.6 * text_size));
  text.scale.z = text_size;
  char buf[64];
  if (b.track_id > 0) {
    std::snprintf(buf, sizeof(buf), "%s #%u %.2f", className(b.label), b.track_id, b.score);
  } else {
    std::snprintf(buf, sizeof(buf), "%s %.2f", className(b.label), b.score);
  }
  text.text = buf;
  return text;
}

// An arrow from the box's top centre to where its velocity takes it in arrow_seconds.
visualization_msgs::Marker velocityArrow(const std_msgs::Header& header, int id, const Box& b,
                                         const MarkerOptions& options) {
  visualization_msgs::Marker arrow = base(header, "velocity", id, visualization_msgs::Marker::ARROW, b.label);
  const Eigen::Vector3d from(b.x, b.y, b.top());
  arrow.points.push_back(point(from));
  arrow.points.push_back(point(from + options.arrow_seconds * Eigen::Vector3d(b.vx, b.vy, 0.0)));
  arrow.scale.x = options.line_width * 1.5;  // shaft diameter
  arrow.scale.y = options.line_width * 3.0;  // head diameter
  arrow.scale.z = 0.0;                       // default head length
  return arrow;
}

}  // namespace

visualization_msgs::MarkerArray MarkerBuilder::build(const std::vector<Box>& boxes, const std_msgs::Header& header,
                                                     const Eigen::Isometry3d& sensor_to_fixed) {
  const double stamp = header.stamp.toSec();
  if (stamp < last_stamp_) trails_.clear();  // a bag loop: the old trails belong to another time
  last_stamp_ = stamp;
  ++frame_;

  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker clear;
  clear.header = header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  out.markers.push_back(clear);

  const Eigen::Isometry3d fixed_to_sensor = sensor_to_fixed.inverse();
  int id = 0;
  for (const Box& b : boxes) {
    ++id;
    out.markers.push_back(boxEdges(header, id, b, options_.line_width));
    out.markers.push_back(boxLabel(header, id, b, options_.text_size));
    const double speed = std::hypot(b.vx, b.vy);
    if (speed >= options_.min_arrow_speed && options_.arrow_seconds > 0)
      out.markers.push_back(velocityArrow(header, id, b, options_));

    if (options_.trail_length > 0 && b.track_id > 0) {
      Trail& trail = trails_[b.track_id];
      trail.last_frame = frame_;
      trail.centres.push_back(sensor_to_fixed * Eigen::Vector3d(b.x, b.y, b.bottom()));
      while (trail.centres.size() > static_cast<std::size_t>(options_.trail_length)) trail.centres.pop_front();
      if (trail.centres.size() >= 2) {
        visualization_msgs::Marker strip =
            base(header, "trails", static_cast<int>(b.track_id), visualization_msgs::Marker::LINE_STRIP, b.label);
        strip.scale.x = options_.line_width;
        strip.color.a = 0.7f;
        for (const auto& c : trail.centres) strip.points.push_back(point(fixed_to_sensor * c));
        out.markers.push_back(strip);
      }
    }
  }
  // A track missing for as many frames as a trail is long is gone: forget its trail.
  for (auto it = trails_.begin(); it != trails_.end();) {
    if (frame_ - it->second.last_frame > static_cast<std::uint64_t>(options_.trail_length)) {
      it = trails_.erase(it);
    } else {
      ++it;
    }
  }
  return out;
}

}  // namespace ret3d
