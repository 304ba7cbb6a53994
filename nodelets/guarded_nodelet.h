#pragma once
// A nodelet whose initialisation errors unload it cleanly: init() throws, the error is logged
// as "<name> not loaded: <reason>", and the exception reaches the manager, which unloads this
// nodelet and keeps running the others. Loading one also makes SIGTERM shut the manager
// down in order (see sigterm_shutdown.h), so that every nodelet saves its files.

#include <nodelet/nodelet.h>

#include <exception>

#include "sigterm_shutdown.h"

namespace alvio_ros {

class GuardedNodelet : public nodelet::Nodelet {
 protected:
  /// Subscriptions, publishers, parameters; throw on anything invalid.
  virtual void init() = 0;

 private:
  void onInit() final {
    shutdownOnSigterm();
    try {
      init();
    } catch (const std::exception& e) {
      NODELET_FATAL("%s not loaded: %s", getName().c_str(), e.what());
      throw;
    }
  }
};

}  // namespace alvio_ros
