#include "ret3d/ros/bag_reader.h"

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace ret3d {
namespace {

// One field of a message definition: its type without the array suffix, and how many elements it holds.
struct Field {
  std::string type;
  bool variable_array = false;  // T[]: a uint32 count precedes the elements
  std::uint32_t fixed_count = 1;  // T[N]: N elements, no count; a plain field: 1
};

using Definitions = std::map<std::string, std::vector<Field>>;  // "pkg/Type" -> its fields

std::string packageOf(const std::string& datatype) {
  const auto slash = datatype.find('/');
  return slash == std::string::npos ? std::string() : datatype.substr(0, slash);
}

std::size_t builtinSize(const std::string& type) {
  static const std::map<std::string, std::size_t> sizes = {
      {"bool", 1},    {"int8", 1},    {"uint8", 1},   {"byte", 1},    {"char", 1},     {"int16", 2},
      {"uint16", 2},  {"int32", 4},   {"uint32", 4},  {"float32", 4}, {"int64", 8},    {"uint64", 8},
      {"float64", 8}, {"time", 8},    {"duration", 8}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

// Parses gendeps' full text: the top message's fields, then sections "MSG: pkg/Type" after a line of '='.
Definitions parseDefinitions(const std::string& datatype, const std::string& text) {
  Definitions defs;
  std::string current = datatype;
  defs[current];
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    const auto hash = line.find('#');
    const std::string code = line.substr(0, hash);  // a string constant's '#' is cut too: constants are skipped
    std::istringstream tokens(code);
    std::string type, name;
    if (!(tokens >> type)) continue;
    if (type.find_first_not_of('=') == std::string::npos) continue;  // section separator
    if (type == "MSG:") {
      tokens >> current;
      defs[current];
      continue;
    }
    if (!(tokens >> name) || code.find('=') != std::string::npos) continue;  // a constant, not a field
    Field f;
    const auto bracket = type.find('[');
    if (bracket != std::string::npos) {
      const std::string count = type.substr(bracket + 1, type.size() - bracket - 2);
      f.variable_array = count.empty();
      if (!count.empty()) f.fixed_count = static_cast<std::uint32_t>(std::stoul(count));
      type = type.substr(0, bracket);
    }
    if (type == "Header") type = "std_msgs/Header";
    if (builtinSize(type) == 0 && type != "string" && type.find('/') == std::string::npos) {
      type = packageOf(current) + "/" + type;
    }
    f.type = type;
    defs[current].push_back(f);
  }
  return defs;
}

class Walker {
 public:
  Walker(const Definitions& defs, const std::uint8_t* bytes, std::size_t size)
      : defs_(defs), bytes_(bytes), size_(size) {}

  // Advances over one value of `type`; false with problem() set at the first length that does not fit.
  bool value(const std::string& type) {
    if (const std::size_t n = builtinSize(type)) return skip(n, type);
    if (type == "string") {
      std::uint32_t len;
      if (!count(len, "string length")) return false;
      return skip(len, "string of " + std::to_string(len) + " bytes");
    }
    const auto def = defs_.find(type);
    if (def == defs_.end()) return fail("no definition of " + type + " in the message's definition");
    for (const Field& f : def->second) {
      std::uint32_t n = f.fixed_count;
      if (f.variable_array && !count(n, f.type + "[] length")) return false;
      if (const std::size_t element = builtinSize(f.type)) {
        // Checked as one block: a count of billions must not be walked element by element.
        if (static_cast<std::uint64_t>(n) * element > size_ - pos_) {
          return overrun("an array of " + std::to_string(n) + " " + f.type + " at byte " + std::to_string(pos_) +
                         " of " + std::to_string(size_));
        }
        pos_ += static_cast<std::size_t>(n) * element;
        continue;
      }
      // Every element of a string or message array takes at least one byte: a count beyond the remaining bytes is
      // damage, and the walk below stays bounded by the message's size.
      if (f.variable_array && n > size_ - pos_) {
        return overrun("an array of " + std::to_string(n) + " " + f.type + " at byte " + std::to_string(pos_) +
                       " of " + std::to_string(size_));
      }
      for (std::uint32_t k = 0; k < n; ++k) {
        if (!value(f.type)) return false;
      }
    }
    return true;
  }

  const std::string& problem() const { return problem_; }

 private:
  bool count(std::uint32_t& n, const std::string& what) {
    if (!skip(4, what)) return false;
    std::memcpy(&n, bytes_ + pos_ - 4, 4);
    return true;
  }
  bool skip(std::size_t n, const std::string& what) {
    if (n > size_ - pos_) {
      return overrun("a " + what + " at byte " + std::to_string(pos_) + " of " + std::to_string(size_));
    }
    pos_ += n;
    return true;
  }
  bool fail(const std::string& what) {
    problem_ = what;
    return false;
  }
  bool overrun(const std::string& what) { return fail(what + " runs past the message's end"); }

  const Definitions& defs_;
  const std::uint8_t* bytes_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string problem_;
};


// ---- The bag's layout ----------------------------------------------------------------------------------------------
// Bag format 2.0: "#ROSBAG V2.0\n", then records: uint32 header length, header fields (uint32 length, name=value),
// uint32 data length, data. rosbag opens a bag by reading the bag header record (op 3), then at its index_pos
// conn_count connection records (op 7, whose data is itself a header of fields) and chunk_count chunk info records
// (op 6); for each chunk info it reads the chunk record (op 5) at chunk_pos and, right after it, one index record
// (op 4) per connection the chunk info lists. A message is read at its index entry's offset into the unpacked chunk:
// connection records there are skipped up to a message data record (op 2).

using Fields = std::map<std::string, std::string>;

struct Record {
  std::uint64_t pos = 0;  // of the header length
  char op = 0;
  Fields fields;
  std::uint64_t data_at = 0, data_len = 0;
};

// Bytes read on demand: the file itself, or a chunk unpacked in memory.
class Bytes {
 public:
  virtual ~Bytes() = default;
  virtual std::uint64_t size() const = 0;
  virtual std::string read(std::uint64_t at, std::uint64_t n) = 0;
  std::uint64_t u32(std::uint64_t at) {
    std::uint32_t v;
    std::memcpy(&v, read(at, 4).data(), 4);
    return v;
  }
};

class FileBytes : public Bytes {
 public:
  explicit FileBytes(const std::string& path) : in_(path, std::ios::binary) {
    if (!in_) throw std::runtime_error("cannot open bag '" + path + "'");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
  }
  std::uint64_t size() const override { return size_; }
  std::string read(std::uint64_t at, std::uint64_t n) override {
    std::string out(n, '\0');
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(out.data(), static_cast<std::streamsize>(n));
    if (!in_) throw std::runtime_error("read failed at byte " + std::to_string(at));
    return out;
  }

 private:
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

class MemoryBytes : public Bytes {
 public:
  explicit MemoryBytes(std::string data) : data_(std::move(data)) {}
  std::uint64_t size() const override { return data_.size(); }
  std::string read(std::uint64_t at, std::uint64_t n) override { return data_.substr(at, n); }

 private:
  std::string data_;
};

// The fields of a header (name=value, each after its uint32 length), or the problem.
std::string parseFields(const std::string& header, Fields& fields) {
  for (std::size_t f = 0; f < header.size();) {
    if (header.size() - f < 4) return "truncated header field";
    std::uint32_t field_len;
    std::memcpy(&field_len, header.data() + f, 4);
    if (field_len > header.size() - f - 4) return "header field past the header's end";
    const std::string field = header.substr(f + 4, field_len);
    const auto eq = field.find('=');
    if (eq == std::string::npos) return "header field without '='";
    fields[field.substr(0, eq)] = field.substr(eq + 1);
    f += 4 + field_len;
  }
  return "";
}

template <class T>
bool field(const Fields& fields, const std::string& name, T* value) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != sizeof(T)) return false;
  std::memcpy(value, it->second.data(), sizeof(T));
  return true;
}

std::string at(const Record& r) { return "record at byte " + std::to_string(r.pos) + ": "; }

// Every record in [begin, end) of `bytes`, each well-formed: its lengths inside the range, its header (and, for a
// connection record, its data) a list of fields, an op.
std::string readRecords(Bytes& bytes, std::uint64_t begin, std::uint64_t end, std::vector<Record>& out) {
  for (std::uint64_t pos = begin; pos < end;) {
    const std::string where = "record at byte " + std::to_string(pos) + ": ";
    if (end - pos < 4) return where + "truncated";
    const std::uint64_t header_len = bytes.u32(pos);
    if (header_len > end - pos - 4) return where + "header of " + std::to_string(header_len) + " bytes past the end";
    if (header_len > kMaxBagHeaderBytes) return where + "header of " + std::to_string(header_len) + " bytes";
    const std::uint64_t data_len_at = pos + 4 + header_len;
    if (end - data_len_at < 4) return where + "truncated";
    Record r;
    r.pos = pos;
    r.data_len = bytes.u32(data_len_at);
    r.data_at = data_len_at + 4;
    if (r.data_len > end - r.data_at) return where + "data of " + std::to_string(r.data_len) + " bytes past the end";
    const std::string problem = parseFields(bytes.read(pos + 4, header_len), r.fields);
    if (!problem.empty()) return where + problem;
    const auto op = r.fields.find("op");
    if (op == r.fields.end() || op->second.size() != 1) return where + "no op field";
    r.op = op->second[0];
    if (r.op == 0x07) {  // connection: its data is the connection header
      if (r.data_len > kMaxBagHeaderBytes) {
        return where + "connection header of " + std::to_string(r.data_len) + " bytes";
      }
      Fields connection;
      const std::string bad = parseFields(bytes.read(r.data_at, r.data_len), connection);
      if (!bad.empty()) return where + "connection " + bad;
    }
    out.push_back(std::move(r));
    pos = r.data_at + r.data_len;
  }
  return "";
}

// The chunk's records, unpacked as rosbag unpacks them (`size` bytes; none, bz2 or lz4), into `records`.
std::string readChunk(Bytes& file, const Record& chunk, std::vector<Record>& records) {
  const auto compression = chunk.fields.find("compression");
  std::uint32_t size = 0;
  if (compression == chunk.fields.end() || !field(chunk.fields, "size", &size)) {
    return at(chunk) + "chunk without compression or size";
  }
  if (size > kMaxBagChunkBytes) return at(chunk) + "chunk of " + std::to_string(size) + " bytes unpacked";
  std::string packed = file.read(chunk.data_at, chunk.data_len);
  std::string data;
  if (compression->second == "none") {
    if (size != chunk.data_len) return at(chunk) + "uncompressed chunk whose size differs from its data";
    data = std::move(packed);
  } else if (compression->second == "bz2" || compression->second == "lz4") {
    data.assign(size, '\0');
    unsigned int unpacked = size;
    const bool ok = compression->second == "bz2"
                        ? BZ2_bzBuffToBuffDecompress(data.data(), &unpacked, packed.data(),
                                                     static_cast<unsigned int>(packed.size()), 0, 0) == BZ_OK
                        : roslz4_buffToBuffDecompress(packed.data(), static_cast<unsigned int>(packed.size()),
                                                      data.data(), &unpacked) == 0;
    if (!ok) return at(chunk) + compression->second + " chunk that does not unpack";
    if (unpacked != size) {
      return at(chunk) + compression->second + " chunk of " + std::to_string(unpacked) + " bytes, not " +
             std::to_string(size);
    }
  } else {
    return at(chunk) + "chunk of unknown compression '" + compression->second + "'";
  }
  MemoryBytes inner(std::move(data));
  const std::string problem = readRecords(inner, 0, inner.size(), records);
  if (!problem.empty()) return "chunk at byte " + std::to_string(chunk.pos) + ": " + problem;
  for (const Record& r : records) {
    if (r.op != 0x02 && r.op != 0x07) {
      return "chunk at byte " + std::to_string(chunk.pos) + ": record of op " + std::to_string(int(r.op)) +
             " inside a chunk";
    }
  }
  return "";
}

std::string layoutProblem(Bytes& file) {
  const std::string magic = "#ROSBAG V2.0\n";
  if (file.size() < magic.size() || file.read(0, magic.size()) != magic) return "not a rosbag 2.0 file";
  std::vector<Record> records;
  std::string problem = readRecords(file, magic.size(), file.size(), records);
  if (!problem.empty()) return problem;
  if (records.empty() || records[0].op != 0x03) return "no bag header record after the version line";
  const Record& header = records[0];
  std::uint64_t index_pos = 0;
  std::uint32_t conn_count = 0, chunk_count = 0;
  if (!field(header.fields, "index_pos", &index_pos) || !field(header.fields, "conn_count", &conn_count) ||
      !field(header.fields, "chunk_count", &chunk_count)) {
    return at(header) + "bag header without index_pos, conn_count or chunk_count";
  }
  std::map<std::uint64_t, std::size_t> record_at;  // position -> index in records
  for (std::size_t i = 0; i < records.size(); ++i) record_at[records[i].pos] = i;
  if (index_pos == 0 && conn_count == 0 && chunk_count == 0) return "";  // an empty bag, or one never closed
  const auto index = record_at.find(index_pos);
  if (index == record_at.end()) return "index position " + std::to_string(index_pos) + " is no record's start";
  const std::size_t first = index->second;
  if (records.size() - first < static_cast<std::uint64_t>(conn_count) + chunk_count) {
    return "the index at byte " + std::to_string(index_pos) + " holds fewer records than the bag header counts";
  }
  for (std::size_t i = first; i < first + conn_count; ++i) {
    if (records[i].op != 0x07) return at(records[i]) + "not a connection record, where the index lists them";
  }
  for (std::size_t i = first + conn_count; i < first + conn_count + chunk_count; ++i) {
    const Record& info = records[i];
    std::uint64_t chunk_pos = 0;
    std::uint32_t count = 0;
    if (info.op != 0x06 || !field(info.fields, "chunk_pos", &chunk_pos) || !field(info.fields, "count", &count)) {
      return at(info) + "not a chunk info record, where the index lists them";
    }
    if (static_cast<std::uint64_t>(count) * 8 != info.data_len) {
      return at(info) + "chunk info of " + std::to_string(count) + " connections in " + std::to_string(info.data_len) +
             " bytes";
    }
    const auto chunk = record_at.find(chunk_pos);
    if (chunk == record_at.end() || records[chunk->second].op != 0x05) {
      return at(info) + "chunk position " + std::to_string(chunk_pos) + " is no chunk record's start";
    }
    std::vector<Record> inner;
    problem = readChunk(file, records[chunk->second], inner);
    if (!problem.empty()) return problem;
    // Where a message may be read: an inner record from which, past connection records, a message data record comes.
    std::set<std::uint64_t> readable;
    bool message_follows = false;
    for (auto r = inner.rbegin(); r != inner.rend(); ++r) {
      if (r->op == 0x02) message_follows = true;
      if (message_follows) readable.insert(r->pos);
    }
    const std::size_t c = chunk->second;
    if (records.size() - c - 1 < count) return at(info) + "fewer index records after its chunk than it counts";
    for (std::size_t k = c + 1; k <= c + count; ++k) {
      const Record& idx = records[k];
      std::uint32_t entries = 0;
      if (idx.op != 0x04 || !field(idx.fields, "count", &entries)) {
        return at(idx) + "not an index record, where chunk info at byte " + std::to_string(info.pos) + " puts one";
      }
      if (static_cast<std::uint64_t>(entries) * 12 != idx.data_len) {
        return at(idx) + "index of " + std::to_string(entries) + " entries in " + std::to_string(idx.data_len) +
               " bytes";
      }
      const std::string data = file.read(idx.data_at, idx.data_len);
      for (std::uint32_t e = 0; e < entries; ++e) {
        std::uint32_t offset;
        std::memcpy(&offset, data.data() + 12 * e + 8, 4);
        if (!readable.count(offset)) {
          return at(idx) + "index entry " + std::to_string(e) + " points to byte " + std::to_string(offset) +
                 " of its chunk, where no message is";
        }
      }
    }
  }
  return "";
}
}  // namespace

std::string serializedMessageProblem(const std::string& datatype, const std::string& definition,
                                     const std::uint8_t* bytes, std::size_t size) {
  const Definitions defs = parseDefinitions(datatype, definition);
  Walker walker(defs, bytes, size);
  return walker.value(datatype) ? std::string() : walker.problem();
}

std::string bagLayoutProblem(const std::string& path) {
  FileBytes file(path);
  return layoutProblem(file);
}

void openCheckedBag(rosbag::Bag& bag, const std::string& path) {
  const std::string problem = bagLayoutProblem(path);
  if (problem == "not a rosbag 2.0 file") throw std::runtime_error("cannot open bag '" + path + "': " + problem);
  if (!problem.empty()) throw std::runtime_error("cannot open bag '" + path + "': damaged: " + problem);
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error("cannot open bag '" + path + "': " + e.what());
  }
}

}  // namespace ret3d
