#pragma once
// A tiny levelled logger for the ROS-free core. The default sink writes to
// stderr; nodelets redirect it to rosconsole and the MRPT logger to its file,
// so the core never needs to know who is listening.

#include <functional>
#include <iomanip>
#include <sstream>
#include <string>

namespace alvio {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3 };

using LogSink = std::function<void(LogLevel, const std::string&)>;

/// Replace the sink (thread-safe). Pass nullptr to restore the stderr sink.
void setLogSink(LogSink sink);
/// The current sink (empty when it is the stderr sink), so a tee can chain to it.
LogSink logSink();
/// What the default sink does: "[alvio <level>] message" on stderr.
void logToStderr(LogLevel level, const std::string& message);
/// Messages below this level are dropped before formatting reaches the sink.
void setLogLevel(LogLevel level);
LogLevel logLevel();
void logMessage(LogLevel level, const std::string& message);
const char* logLevelName(LogLevel level);

/// A timestamp in seconds as log text, to the millisecond. A stream's default of six
/// significant digits prints every time since 2001 as 1.6e+09 or so.
inline std::string stampText(double t_s) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(3) << t_s;
  return os.str();
}

namespace detail {
template <typename... Args>
std::string concat(const Args&... args) {
  std::ostringstream os;
  (os << ... << args);
  return os.str();
}
}  // namespace detail

template <typename... Args>
void logDebug(const Args&... args) {
  if (logLevel() <= LogLevel::kDebug) logMessage(LogLevel::kDebug, detail::concat(args...));
}
template <typename... Args>
void logInfo(const Args&... args) {
  if (logLevel() <= LogLevel::kInfo) logMessage(LogLevel::kInfo, detail::concat(args...));
}
template <typename... Args>
void logWarn(const Args&... args) {
  if (logLevel() <= LogLevel::kWarn) logMessage(LogLevel::kWarn, detail::concat(args...));
}
template <typename... Args>
void logError(const Args&... args) {
  logMessage(LogLevel::kError, detail::concat(args...));
}

}  // namespace alvio
