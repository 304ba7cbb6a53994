#include "core_log_route.h"

#include <ros/console.h>

#include <map>
#include <mutex>

namespace alvio_ros {

namespace {

// Lock order: `install` is never taken by the sink, so installing (install, then the core's
// sink mutex) cannot deadlock with logging (the core's sink mutex, then `mutex`).
struct Routes {
  std::mutex install;
  std::mutex mutex;
  int next_id = 0;
  std::map<int, alvio::LogSink> routes;  // id -> listener (may be empty)
};

Routes& routes() {
  static Routes r;
  return r;
}

void toRosconsole(alvio::LogLevel level, const std::string& message) {
  switch (level) {
    case alvio::LogLevel::kDebug:
      ROS_DEBUG_NAMED("core", "%s", message.c_str());
      break;
    case alvio::LogLevel::kInfo:
      ROS_INFO_NAMED("core", "%s", message.c_str());
      break;
    case alvio::LogLevel::kWarn:
      ROS_WARN_NAMED("core", "%s", message.c_str());
      break;
    case alvio::LogLevel::kError:
      ROS_ERROR_NAMED("core", "%s", message.c_str());
      break;
  }
}

void sink(alvio::LogLevel level, const std::string& message) {
  toRosconsole(level, message);
  Routes& r = routes();
  std::lock_guard<std::mutex> lock(r.mutex);
  for (auto& [id, listener] : r.routes)
    if (listener) listener(level, message);
}

}  // namespace

CoreLogRoute::CoreLogRoute() {
  Routes& r = routes();
  std::lock_guard<std::mutex> install(r.install);
  bool first = false;
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    id_ = r.next_id++;
    first = r.routes.empty();
    r.routes[id_] = nullptr;
  }
  if (first) alvio::setLogSink(sink);
}

CoreLogRoute::~CoreLogRoute() {
  Routes& r = routes();
  std::lock_guard<std::mutex> install(r.install);
  bool last = false;
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    r.routes.erase(id_);
    last = r.routes.empty();
  }
  if (last) alvio::setLogSink(nullptr);
}

void CoreLogRoute::setListener(alvio::LogSink listener) {
  Routes& r = routes();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.routes[id_] = std::move(listener);
}

void CoreLogRoute::clearListener() {
  setListener(nullptr);
}

}  // namespace alvio_ros
