#pragma once
// roscpp turns SIGINT into an orderly shutdown but leaves SIGTERM (docker stop, systemd,
// roslaunch's escalation) at its default action, which kills the nodelet manager before
// any nodelet can save its trajectory or map. This makes SIGTERM do what SIGINT does.

namespace alvio_ros {

/// Once per process, and only when SIGTERM still has its default action (a host process
/// with a handler of its own keeps it).
void shutdownOnSigterm();

}  // namespace alvio_ros
