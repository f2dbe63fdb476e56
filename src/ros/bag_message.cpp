#include "ret3d/ros/bag_message.h"

#include <cstring>
#include <map>
#include <sstream>

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

}  // namespace

std::string serializedMessageProblem(const std::string& datatype, const std::string& definition,
                                     const std::uint8_t* bytes, std::size_t size) {
  const Definitions defs = parseDefinitions(datatype, definition);
  Walker walker(defs, bytes, size);
  return walker.value(datatype) ? std::string() : walker.problem();
}

}  // namespace ret3d
