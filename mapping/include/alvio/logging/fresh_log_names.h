#pragma once
// Names for a new set of MRPT logs that leave earlier ones alone. A robot's earlier run, the
// logger nodelet before a reload, or the run before a clock jump may have logged into the same
// folder: the new files are numbered instead (alvio_1.rawlog, alvio_1.log, then _2 ...).

#include <string>

#include "alvio/config/logger_options.h"

namespace alvio {

/// `options` with name and text_file numbered so that none of <name>.rawlog (or .rawlog.part),
/// <name>.3Dscene and text_file exists yet in `dir` (options.out_dir when set); unchanged when
/// none does.
LoggerOptions freshLogNames(LoggerOptions options, const std::string& dir);

}  // namespace alvio
