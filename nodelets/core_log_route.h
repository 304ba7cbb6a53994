#pragma once
// Routes the core's log messages (alvio::logInfo ...) to rosconsole, under the
// logger "ros.alvio.core", while at least one alvio nodelet holds a route, and
// copies them to extra listeners (the logger nodelet's text log). The core's sink
// is process-wide, so the nodelets of one manager share it: the first route
// installs it and the last one restores the core's default.

#include <functional>
#include <string>

#include "alvio/common/logging.h"

namespace alvio_ros {

class CoreLogRoute {
 public:
  CoreLogRoute();
  ~CoreLogRoute();
  CoreLogRoute(const CoreLogRoute&) = delete;
  CoreLogRoute& operator=(const CoreLogRoute&) = delete;

  /// Also send every core message to `listener` until this route is destroyed or
  /// clearListener() is called. One listener per route.
  void setListener(alvio::LogSink listener);
  void clearListener();

 private:
  int id_;
};

}  // namespace alvio_ros
