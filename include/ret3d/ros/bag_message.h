// Reading one message out of a bag without trusting its length fields.
//
// rosbag's instantiate<M>() deserializes with ROS's serializers, which resize a vector or string to the length the
// bytes claim before checking that the bytes hold that much: one damaged length field in a message of a few kilobytes
// asks for gigabytes (found by fuzzing `ret3d convert --check`). readBagMessage<M> first walks the serialized message
// along M's definition (ros::message_traits::Definition, nested types included) and checks every length against the
// bytes that remain, then deserializes.
#pragma once

#include <ros/serialization.h>
#include <rosbag/message_instance.h>

#include <boost/make_shared.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace ret3d {

// Empty when `bytes` hold a complete message of type `datatype` whose full definition (as gendeps writes it: the
// message, then "MSG: pkg/Type" sections for its nested types) is `definition`; otherwise what is wrong, e.g. "a
// string of 4026531840 bytes at byte 26 of 58". Bytes after a complete message are allowed, as ROS allows them.
std::string serializedMessageProblem(const std::string& datatype, const std::string& definition,
                                     const std::uint8_t* bytes, std::size_t size);

// The message, or null when `m` is of another type (as instantiate<M>()); throws std::runtime_error naming the topic
// and the problem when its bytes do not hold a well-formed M.
template <class M>
boost::shared_ptr<M> readBagMessage(const rosbag::MessageInstance& m) {
  if (!m.isType<M>()) return nullptr;
  std::vector<std::uint8_t> bytes(m.size());
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  m.write(out);
  const std::string problem = serializedMessageProblem(ros::message_traits::DataType<M>::value(),
                                                       ros::message_traits::Definition<M>::value(), bytes.data(),
                                                       bytes.size());
  if (!problem.empty()) {
    throw std::runtime_error(m.getTopic() + ": damaged " + m.getDataType() + " message: " + problem);
  }
  auto msg = boost::make_shared<M>();
  ros::serialization::IStream in(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::deserialize(in, *msg);
  return msg;
}

}  // namespace ret3d
