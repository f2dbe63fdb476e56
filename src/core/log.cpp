#include "ret3d/core/log.h"

#include <iostream>
#include <mutex>

namespace ret3d {
namespace {
std::mutex g_mutex;
LogSink g_sink;
LogLevel g_level = LogLevel::Info;

const char* levelName(LogLevel l) {
  switch (l) {
    case LogLevel::Debug: return "DEBUG";
    case LogLevel::Info: return "INFO";
    case LogLevel::Warn: return "WARN";
    case LogLevel::Error: return "ERROR";
  }
  return "?";
}
}  // namespace

void setLogSink(LogSink sink) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_sink = std::move(sink);
}

void setLogLevel(LogLevel level) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_level = level;
}

void log(LogLevel level, const std::string& message) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (level < g_level) return;
  if (g_sink) {
    g_sink(level, message);
  } else {
    std::cerr << "[ret3d] " << levelName(level) << ": " << message << std::endl;
  }
}

}  // namespace ret3d
