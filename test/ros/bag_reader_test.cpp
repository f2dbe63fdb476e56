// Reading bags without trusting them (include/ret3d/ros/bag_reader.h): bags of every compression rosbag writes are
// checked and read whole; each kind of damage that made rosbag allocate gigabytes or read past its buffers is refused
// before rosbag opens the file, naming the file and the damage.
#include "ret3d/ros/bag_reader.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "ret3d/ros/conversions.h"
#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

sensor_msgs::PointCloud2 cloudMsg(int f) {
  PointCloud cloud;
  for (int k = 0; k < 50; ++k) cloud.points.push_back({1.0f + k, 0.1f * f, -1.0f, 0.5f});
  std_msgs::Header h;
  h.frame_id = "velodyne";
  h.stamp = ros::Time(1.0e9 + f / 10.0);
  return toPointCloud2(cloud, h);
}

// Three clouds on /points, in chunks of about one cloud.
void writeBag(const std::string& path, rosbag::compression::CompressionType compression) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(compression);
  bag.setChunkThreshold(1024);
  for (int f = 0; f < 3; ++f) bag.write("/points", cloudMsg(f).header.stamp, cloudMsg(f));
  bag.close();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void spit(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

std::uint32_t u32(const std::string& b, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

void putU32(std::string& b, std::size_t at, std::uint32_t v) { std::memcpy(b.data() + at, &v, 4); }

// The top-level records of an uncompressed bag, as the format defines them: position, op, and where each header
// field's value and the data start.
struct RawRecord {
  std::size_t pos = 0, data_at = 0;
  char op = 0;
  std::map<std::string, std::size_t> value_at;
};

std::vector<RawRecord> rawRecords(const std::string& b) {
  std::vector<RawRecord> out;
  for (std::size_t pos = 13; pos + 8 <= b.size();) {
    RawRecord r;
    r.pos = pos;
    const std::size_t header_len = u32(b, pos);
    for (std::size_t f = pos + 4; f < pos + 4 + header_len;) {
      const std::size_t len = u32(b, f);
      const std::string field = b.substr(f + 4, len);
      const std::size_t eq = field.find('=');
      r.value_at[field.substr(0, eq)] = f + 4 + eq + 1;
      if (field.substr(0, eq) == "op") r.op = field[eq + 1];
      f += 4 + len;
    }
    r.data_at = pos + 4 + header_len + 4;
    out.push_back(r);
    pos = r.data_at + u32(b, pos + 4 + header_len);
  }
  return out;
}

const RawRecord& firstOf(const std::vector<RawRecord>& records, char op) {
  for (const RawRecord& r : records) {
    if (r.op == op) return r;
  }
  throw std::runtime_error("no record of op " + std::to_string(int(op)));
}

TEST(BagReader, BagsOfEveryCompressionAreCheckedAndReadWhole) {
  test::TempDir dir;
  for (const auto& [name, compression] :
       {std::make_pair("none", rosbag::compression::Uncompressed), std::make_pair("bz2", rosbag::compression::BZ2),
        std::make_pair("lz4", rosbag::compression::LZ4)}) {
    const std::string path = dir / (std::string(name) + ".bag");
    writeBag(path, compression);
    EXPECT_EQ(bagLayoutProblem(path), "") << name;
    rosbag::Bag bag;
    openCheckedBag(bag, path);
    rosbag::View view(bag);
    int f = 0;
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = readBagMessage<sensor_msgs::PointCloud2>(m);
      ASSERT_TRUE(msg) << name;
      EXPECT_EQ(msg->data, cloudMsg(f).data) << name << " cloud " << f;
      ++f;
    }
    EXPECT_EQ(f, 3) << name;
  }
}

// Each damage, made in an uncompressed bag, must be refused by openCheckedBag with the file's name, "damaged" and
// `expected` in the message. Without the check rosbag reads past its buffers (connection header, index position,
// chunk position, index offset) or reads on into the next records (counts).
TEST(BagReader, DamageIsRefusedBeforeRosbagReadsIt) {
  test::TempDir dir;
  const std::string good = dir / "good.bag";
  writeBag(good, rosbag::compression::Uncompressed);
  const std::string bytes = slurp(good);
  const std::vector<RawRecord> records = rawRecords(bytes);
  const RawRecord &header = firstOf(records, 0x03), &connection = firstOf(records, 0x07),
                  &chunk_info = firstOf(records, 0x06), &index = firstOf(records, 0x04);

  const std::vector<std::tuple<std::string, std::function<void(std::string&)>, std::string>> damages = {
      {"connection header field",
       [&](std::string& b) { putU32(b, connection.data_at, 0x00FFFFFF); },  // the first field's length
       "connection header field past the header's end"},
      {"index position", [&](std::string& b) { putU32(b, header.value_at.at("index_pos"), connection.pos + 1); },
       "is no record's start"},
      {"chunk position", [&](std::string& b) { putU32(b, chunk_info.value_at.at("chunk_pos"), 13); },
       "is no chunk record's start"},
      {"index offset", [&](std::string& b) { putU32(b, index.data_at + 8, 3); }, "where no message is"},
      {"index count", [&](std::string& b) { putU32(b, index.value_at.at("count"), 1000000); }, "entries in"},
      {"connection count", [&](std::string& b) { putU32(b, header.value_at.at("conn_count"), 7); },
       "fewer records than the bag header counts"},
  };
  for (const auto& [what, damage, expected] : damages) {
    std::string b = bytes;
    damage(b);
    const std::string path = dir / "damaged.bag";
    spit(path, b);
    rosbag::Bag bag;
    const std::string msg = test::errorMessage([&] { openCheckedBag(bag, path); });
    EXPECT_NE(msg.find("cannot open bag '" + path + "': damaged"), std::string::npos) << what << ": " << msg;
    EXPECT_NE(msg.find(expected), std::string::npos) << what << ": " << msg;
  }
  rosbag::Bag bag;
  const std::string not_a_bag = dir / "not_a.bag";
  spit(not_a_bag, "#ROSBAG V1.2\nhello");
  EXPECT_EQ(test::errorMessage([&] { openCheckedBag(bag, not_a_bag); }),
            "cannot open bag '" + not_a_bag + "': not a rosbag 2.0 file");
}

TEST(BagReader, AMessageShorterThanItsLengthsSayIsNamed) {
  const sensor_msgs::PointCloud2 msg = cloudMsg(0);
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(msg));
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::serialize(out, msg);
  const std::string type = ros::message_traits::DataType<sensor_msgs::PointCloud2>::value();
  const std::string definition = ros::message_traits::Definition<sensor_msgs::PointCloud2>::value();
  EXPECT_EQ(serializedMessageProblem(type, definition, bytes.data(), bytes.size()), "");
  // Cut within the point data: the data's length says more than remains.
  const std::string cut = serializedMessageProblem(type, definition, bytes.data(), bytes.size() - 10);
  EXPECT_NE(cut.find("an array of " + std::to_string(msg.data.size()) + " uint8"), std::string::npos) << cut;
  EXPECT_NE(cut.find("runs past the message's end"), std::string::npos) << cut;
  // The frame id's length (after seq and stamp) damaged.
  std::vector<std::uint8_t> damaged = bytes;
  const std::uint32_t huge = 0xF0000000u;
  std::memcpy(damaged.data() + 12, &huge, 4);
  const std::string frame = serializedMessageProblem(type, definition, damaged.data(), damaged.size());
  EXPECT_NE(frame.find("a string of 4026531840 bytes at byte 16"), std::string::npos) << frame;
}

}  // namespace
}  // namespace ret3d
