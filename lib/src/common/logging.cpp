#include "alvio/common/logging.h"

#include <atomic>
#include <iostream>
#include <mutex>

namespace alvio {
namespace {
std::mutex g_sink_mutex;
LogSink g_sink;
std::atomic<int> g_level{static_cast<int>(LogLevel::kInfo)};
}  // namespace

const char* logLevelName(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "debug";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kWarn:
      return "warn";
    case LogLevel::kError:
      return "error";
  }
  return "?";
}

void setLogSink(LogSink sink) {
  std::lock_guard<std::mutex> lock(g_sink_mutex);
  g_sink = std::move(sink);
}

LogSink logSink() {
  std::lock_guard<std::mutex> lock(g_sink_mutex);
  return g_sink;
}

void logToStderr(LogLevel level, const std::string& message) {
  std::cerr << "[alvio " << logLevelName(level) << "] " << message << std::endl;
}

void setLogLevel(LogLevel level) {
  g_level = static_cast<int>(level);
}
LogLevel logLevel() {
  return static_cast<LogLevel>(g_level.load());
}

void logMessage(LogLevel level, const std::string& message) {
  if (static_cast<int>(level) < g_level.load()) return;
  std::lock_guard<std::mutex> lock(g_sink_mutex);
  if (g_sink) {
    g_sink(level, message);
    return;
  }
  logToStderr(level, message);
}

}  // namespace alvio
