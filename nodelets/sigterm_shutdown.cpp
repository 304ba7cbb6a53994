#include "sigterm_shutdown.h"

#include <ros/ros.h>

#include <csignal>
#include <mutex>

namespace alvio_ros {
namespace {

// ros::requestShutdown only sets a flag: it is what roscpp's own SIGINT handler calls.
void requestShutdown(int) {
  ros::requestShutdown();
}

}  // namespace

void shutdownOnSigterm() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction current {};
    if (sigaction(SIGTERM, nullptr, &current) != 0 || current.sa_handler != SIG_DFL) return;
    struct sigaction action {};
    action.sa_handler = requestShutdown;
    sigemptyset(&action.sa_mask);
    sigaction(SIGTERM, &action, nullptr);
  });
}

}  // namespace alvio_ros
