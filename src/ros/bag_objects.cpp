#include "ret3d/ros/bag_objects.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <sstream>
#include <stdexcept>

#include "ret3d/Object3DArray.h"
#include "ret3d/ros/bag_reader.h"
#include "ret3d/ros/conversions.h"

namespace ret3d {

std::vector<StampedObjects> readBagObjects(const std::string& bag_path, const std::string& topic) {
  rosbag::Bag bag;
  openCheckedBag(bag, bag_path);
  const std::string wanted = ros::message_traits::DataType<ret3d::Object3DArray>::value();
  bool found = false;
  std::ostringstream topics;
  {
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      topics << "\n  " << c->topic << " (" << c->datatype << ")";
      if (c->topic == topic) {
        if (c->datatype != wanted) {
          throw std::runtime_error(bag_path + ": topic " + topic + " holds " + c->datatype + ", not " + wanted);
        }
        found = true;
      }
    }
  }
  if (!found) {
    throw std::runtime_error(bag_path + ": no topic " + topic + " in the bag; it has:" +
                             (topics.str().empty() ? std::string(" nothing") : topics.str()));
  }
  std::vector<StampedObjects> out;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    boost::shared_ptr<ret3d::Object3DArray> msg;
    try {
      msg = readBagMessage<ret3d::Object3DArray>(m);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(bag_path + ": " + e.what());
    }
    if (!msg) continue;
    StampedObjects s;
    s.stamp = msg->header.stamp.toSec();
    s.frame_id = msg->header.frame_id;
    s.boxes = fromMsg(*msg);
    out.push_back(std::move(s));
  }
  bag.close();
  return out;
}

}  // namespace ret3d
