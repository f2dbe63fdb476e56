// Shared by the KITTI readers and writers (internal to src/io): whitespace-separated text lines, numbers parsed
// strictly and locale-independently, and errors that name the file, the line and the field.
#pragma once

#include <fstream>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace ret3d {
namespace kitti {
namespace detail {

// The place a value came from, for error messages: "FILE:LINE: field 'NAME': problem".
struct Where {
  const std::string& path;
  int line;  // 1-based; 0 when the problem concerns the whole file
};

// Throws kitti::ParseError "FILE:LINE: field 'FIELD': PROBLEM" (or "FILE: ..." when line is 0, or without the field
// part when field is empty).
[[noreturn]] void fail(const Where& where, std::string_view field, const std::string& problem);

// Splits on spaces, tabs and carriage returns; empty when the line is blank.
std::vector<std::string_view> splitFields(std::string_view line);

// A finite number; ParseError naming the field otherwise.
double parseDouble(std::string_view token, const Where& where, std::string_view field);
// An integer (written either as "3" or as an integral float such as "3.00"); ParseError otherwise.
int parseInt(std::string_view token, const Where& where, std::string_view field);

// Calls fn(fields, where) for every non-blank line of a text file.
void forEachLine(const std::string& path,
                 const std::function<void(const std::vector<std::string_view>&, const Where&)>& fn);
// A line of exactly `count` numbers named names[0..count-1] (a pose row, an OXTS record); `what` names the record in
// the field-count message, e.g. "a 3x4 pose".
std::vector<double> parseNumberRow(const std::vector<std::string_view>& fields, const Where& where,
                                   const char* const* names, int count, const std::string& what);
// Replaces the file's content with `text`.
void writeText(const std::string& path, const std::string& text);

// Opens a file for reading / writing; std::runtime_error naming the file when that fails.
std::ifstream openForRead(const std::string& path);
std::ofstream openForWrite(const std::string& path);
// Flushes and closes; std::runtime_error naming the file when a write failed (e.g. disk full).
void closeWritten(std::ofstream& out, const std::string& path);

// Locale-independent number formatting: fixed with `digits` decimals, scientific with `digits` mantissa decimals.
void appendFixed(std::string& out, double v, int digits);
void appendScientific(std::string& out, double v, int digits);

}  // namespace detail
}  // namespace kitti
}  // namespace ret3d
