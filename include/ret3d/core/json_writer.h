// The package's one JSON writer for what its commands report (metrics.json, bench and soak results, velocity errors):
// nested objects and arrays of numbers, strings and booleans, members in the order written.
#pragma once

#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

namespace ret3d {

class JsonWriter {
 public:
  struct Format {
    // Doubles with this many decimals (fixed); -1: up to 6 significant digits (the iostream default).
    int decimals = -1;
    // A double without fraction is written as an integer ("3" rather than "3.0000").
    bool whole_as_integer = false;
    // The top-level members one per line, indented by two spaces; otherwise the whole document on one line.
    bool top_level_lines = false;
  };

  // Starts the document's top-level object.
  explicit JsonWriter(Format format);
  JsonWriter() : JsonWriter(Format{}) {}

  JsonWriter& beginObject(const std::string& key);
  JsonWriter& beginObject();  // an object as the next element of an array
  JsonWriter& endObject();
  JsonWriter& beginArray(const std::string& key);
  JsonWriter& endArray();

  // A non-finite double is written as null (JSON has no NaN or infinity).
  JsonWriter& field(const std::string& key, double value);
  JsonWriter& field(const std::string& key, bool value);
  JsonWriter& field(const std::string& key, const std::string& value);
  JsonWriter& field(const std::string& key, const char* value) { return field(key, std::string(value)); }
  template <typename T, typename = std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>>>
  JsonWriter& field(const std::string& key, T value) {
    member(key);
    out_ << value;
    return *this;
  }

  // The finished document (every object and array closed), newline-terminated.
  std::string str() const;
  // Writes str() to the file, creating its folder; throws std::runtime_error naming the file when it cannot.
  void save(const std::string& path) const;

 private:
  struct Level {
    bool array = false;
    bool empty = true;
  };
  void element();  // the separator before the next element of the innermost object or array
  void member(const std::string& key);
  void close(bool array);

  Format format_;
  std::ostringstream out_;
  std::vector<Level> levels_;
};

}  // namespace ret3d
