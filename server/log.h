// The "server" spdlog logger (stderr). Every line about a job starts with
// "job <id>:" so that one job's story can be grepped out of the log.
#pragma once

#include "spdlog/spdlog.h"

namespace svrc::server {

spdlog::logger& ServerLog();

}  // namespace svrc::server
