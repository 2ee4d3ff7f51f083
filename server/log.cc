#include "server/log.h"

#include <memory>

#include "spdlog/sinks/stdout_color_sinks.h"

namespace svrc::server {

spdlog::logger& ServerLog() {
  static const std::shared_ptr<spdlog::logger> logger = [] {
    std::shared_ptr<spdlog::logger> existing = spdlog::get("server");
    return existing ? existing : spdlog::stderr_color_mt("server");
  }();
  return *logger;
}

}  // namespace svrc::server
