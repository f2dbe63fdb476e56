#include "text_fields.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "ret3d/io/kitti.h"

namespace ret3d {
namespace kitti {
namespace detail {

void fail(const Where& where, std::string_view field, const std::string& problem) {
  std::string msg = where.path;
  if (where.line > 0) msg += ":" + std::to_string(where.line);
  msg += ": ";
  if (!field.empty()) {
    msg += "field '";
    msg += field;
    msg += "': ";
  }
  msg += problem;
  throw ParseError(msg);
}

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; };
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

double parseDouble(std::string_view token, const Where& where, std::string_view field) {
  std::string_view t = token;
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);  // from_chars does not accept a leading '+'
  double v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec == std::errc::invalid_argument || ptr != t.data() + t.size()) {
    fail(where, field, "'" + std::string(token) + "' is not a number");
  }
  if (ec == std::errc::result_out_of_range) fail(where, field, "'" + std::string(token) + "' is out of range");
  if (!std::isfinite(v)) fail(where, field, "'" + std::string(token) + "' is not a finite number");
  return v;
}

int parseInt(std::string_view token, const Where& where, std::string_view field) {
  const double v = parseDouble(token, where, field);
  if (v != std::round(v) || std::fabs(v) > 2e9) {
    fail(where, field, "'" + std::string(token) + "' is not an integer");
  }
  return static_cast<int>(std::lround(v));
}

void forEachLine(const std::string& path,
                 const std::function<void(const std::vector<std::string_view>&, const Where&)>& fn) {
  std::ifstream in = openForRead(path);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto fields = splitFields(line);
    if (!fields.empty()) fn(fields, Where{path, line_no});
  }
}

std::vector<double> parseNumberRow(const std::vector<std::string_view>& fields, const Where& where,
                                   const char* const* names, int count, const std::string& what) {
  const int n = static_cast<int>(fields.size());
  if (n < count) {
    fail(where, names[n], "missing; the line has " + std::to_string(n) + " values (" + what + " has " +
                              std::to_string(count) + ")");
  }
  if (n > count) {
    fail(where, names[count - 1], "followed by " + std::to_string(n - count) + " extra value(s) (" + what + " has " +
                                      std::to_string(count) + ")");
  }
  std::vector<double> v(count);
  for (int i = 0; i < count; ++i) v[i] = parseDouble(fields[i], where, names[i]);
  return v;
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out = openForWrite(path);
  out << text;
  closeWritten(out, path);
}

std::ifstream openForRead(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open '" + path + "' for reading: " + std::strerror(errno));
  return in;
}

std::ofstream openForWrite(const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot open '" + path + "' for writing: " + std::strerror(errno));
  return out;
}

void closeWritten(std::ofstream& out, const std::string& path) {
  out.flush();
  const bool ok = static_cast<bool>(out);
  out.close();
  if (!ok || out.fail()) throw std::runtime_error("error while writing '" + path + "'");
}

namespace {
void appendFormatted(std::string& out, double v, std::chars_format fmt, int digits) {
  char buf[512];  // fixed notation of a double needs at most ~330 characters
  if (v == 0.0) v = 0.0;  // no "-0.000000"
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), v, fmt, digits);
  if (ec != std::errc()) throw std::runtime_error("cannot format number");
  out.append(buf, ptr);
}
}  // namespace

void appendFixed(std::string& out, double v, int digits) { appendFormatted(out, v, std::chars_format::fixed, digits); }

void appendScientific(std::string& out, double v, int digits) {
  appendFormatted(out, v, std::chars_format::scientific, digits);
}

}  // namespace detail
}  // namespace kitti
}  // namespace ret3d
