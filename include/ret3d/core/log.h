// The package's one logger for code outside src/ros: levelled messages to stderr, with an optional sink so the ROS
// layer can route them to rosconsole.
#pragma once

#include <functional>
#include <sstream>
#include <string>

namespace ret3d {

enum class LogLevel { Debug = 0, Info = 1, Warn = 2, Error = 3 };

using LogSink = std::function<void(LogLevel, const std::string&)>;

// Replaces the sink (default: "[ret3d] LEVEL: message" on stderr). Pass nullptr to restore the default.
void setLogSink(LogSink sink);
// Messages below this level are dropped (default Info).
void setLogLevel(LogLevel level);
void log(LogLevel level, const std::string& message);

// Stream-style helpers: RET3D_WARN("skipped " << n << " points");
#define RET3D_LOG_STREAM(level, expr)    \
  do {                                   \
    std::ostringstream ret3d_log_oss_;   \
    ret3d_log_oss_ << expr;              \
    ::ret3d::log(level, ret3d_log_oss_.str()); \
  } while (0)
#define RET3D_DEBUG(expr) RET3D_LOG_STREAM(::ret3d::LogLevel::Debug, expr)
#define RET3D_INFO(expr) RET3D_LOG_STREAM(::ret3d::LogLevel::Info, expr)
#define RET3D_WARN(expr) RET3D_LOG_STREAM(::ret3d::LogLevel::Warn, expr)
#define RET3D_ERROR(expr) RET3D_LOG_STREAM(::ret3d::LogLevel::Error, expr)

}  // namespace ret3d
