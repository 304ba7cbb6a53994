#pragma once
// SIGINT/SIGTERM as a stop request: a long-running program polls the flag between
// units of work and then saves everything it has, instead of dying mid-run.

#include <atomic>

namespace alvio {

/// Install handlers for SIGINT and SIGTERM that set the returned flag. The handlers
/// reset themselves, so a second signal terminates the process as usual (an escape
/// when the save itself hangs).
const std::atomic<bool>& installStopSignalHandlers();

/// The signal that set the flag (0 when none).
int stopSignalNumber();

}  // namespace alvio
