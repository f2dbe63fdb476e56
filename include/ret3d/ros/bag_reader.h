// Reading a bag without trusting it. rosbag's reader believes every length, offset and position a bag states: a
// damaged bag of a few kilobytes makes it allocate gigabytes or read past its buffers (both found by fuzzing `ret3d
// convert --check`, test/fuzz/regressions/bag_check). Every bag ret3d reads goes through these:
//   - openCheckedBag: the file's layout is checked as rosbag will walk it (record lengths and header fields, the
//     connection headers, every chunk unpacked and its records, the index's positions and offsets) before rosbag
//     opens it;
//   - readBagMessage<M>: a message's bytes are walked along M's definition, every length checked against the bytes
//     that remain, before ROS's serializer (which resizes a vector to what the bytes claim) deserializes them.
#pragma once

#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/message_instance.h>

#include <boost/make_shared.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace ret3d {

// Largest record header and largest unpacked chunk a bag may state (a recorder's chunks are 768 KB by default).
inline constexpr std::uint64_t kMaxBagHeaderBytes = 16ull << 20;
inline constexpr std::uint64_t kMaxBagChunkBytes = 512ull << 20;

// Empty when the file at `path` is a rosbag 2.0 file that rosbag can read safely, else the first problem found, e.g.
// "record at byte 7183: connection header field past the header's end". Throws std::runtime_error when the file
// cannot be read.
std::string bagLayoutProblem(const std::string& path);

// Opens `bag` for reading once the layout is sound. Throws std::runtime_error "cannot open bag 'PATH': ..." naming
// the problem (not a bag, damaged, or rosbag's own refusal).
void openCheckedBag(rosbag::Bag& bag, const std::string& path);

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
