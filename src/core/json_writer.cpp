#include "ret3d/core/json_writer.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <stdexcept>

namespace ret3d {

namespace {

std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      q += '\\';
      q += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
      q += buf;
    } else {
      q += c;
    }
  }
  return q + "\"";
}

}  // namespace

JsonWriter::JsonWriter(Format format) : format_(format) {
  if (format_.decimals >= 0) out_ << std::fixed << std::setprecision(format_.decimals);
  out_ << "{";
  levels_.push_back({});
}

void JsonWriter::element() {
  if (levels_.empty()) throw std::logic_error("JsonWriter: element after the document was closed");
  Level& l = levels_.back();
  const bool own_line = format_.top_level_lines && levels_.size() == 1;
  if (!l.empty) out_ << ",";
  if (own_line) {
    out_ << "\n  ";
  } else if (!l.empty) {
    out_ << " ";
  }
  l.empty = false;
}

void JsonWriter::member(const std::string& key) {
  if (levels_.empty() || levels_.back().array)
    throw std::logic_error("JsonWriter: member \"" + key + "\" outside an object");
  element();
  out_ << quoted(key) << ": ";
}

JsonWriter& JsonWriter::beginObject(const std::string& key) {
  member(key);
  out_ << "{";
  levels_.push_back({});
  return *this;
}

JsonWriter& JsonWriter::beginObject() {
  if (levels_.empty() || !levels_.back().array)
    throw std::logic_error("JsonWriter: object without a key outside an array");
  element();
  out_ << "{";
  levels_.push_back({});
  return *this;
}

JsonWriter& JsonWriter::beginArray(const std::string& key) {
  member(key);
  out_ << "[";
  levels_.push_back({true, true});
  return *this;
}

void JsonWriter::close(bool array) {
  if (levels_.size() < 2 || levels_.back().array != array)
    throw std::logic_error(array ? "JsonWriter: endArray without an open array"
                                 : "JsonWriter: endObject without an open object");
  levels_.pop_back();
  out_ << (array ? "]" : "}");
}

JsonWriter& JsonWriter::endObject() {
  close(false);
  return *this;
}

JsonWriter& JsonWriter::endArray() {
  close(true);
  return *this;
}

JsonWriter& JsonWriter::field(const std::string& key, double value) {
  member(key);
  if (!std::isfinite(value)) {
    out_ << "null";
  } else if (format_.whole_as_integer && value == std::floor(value) && std::abs(value) < 1e15) {
    out_ << static_cast<long long>(value);
  } else {
    out_ << value;
  }
  return *this;
}

JsonWriter& JsonWriter::field(const std::string& key, bool value) {
  member(key);
  out_ << (value ? "true" : "false");
  return *this;
}

JsonWriter& JsonWriter::field(const std::string& key, const std::string& value) {
  member(key);
  out_ << quoted(value);
  return *this;
}

std::string JsonWriter::str() const {
  if (levels_.size() != 1) throw std::logic_error("JsonWriter: an object or array is still open");
  return out_.str() + (format_.top_level_lines ? "\n}\n" : "}\n");
}

void JsonWriter::save(const std::string& path) const {
  const std::string text = str();
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream f(path);
  if (!f || !(f << text)) throw std::runtime_error("cannot write " + path);
}

}  // namespace ret3d
