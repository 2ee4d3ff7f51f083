// libFuzzer entry point; compiled once per target with SVRC_FUZZ_TARGET set to
// a svrc::fuzz::Target enumerator (tests/fuzz/CMakeLists.txt). A broken
// contract aborts, so libFuzzer saves the input like any crash.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tests/fuzz/fuzz_bodies.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr svrc::fuzz::Target kTarget = svrc::fuzz::Target::SVRC_FUZZ_TARGET;
  const std::string err =
      svrc::fuzz::RunOne(kTarget, std::string_view(reinterpret_cast<const char*>(data), size));
  if (!err.empty()) {
    std::fprintf(stderr, "svrc fuzz %s: contract broken: %s\n",
                 std::string(svrc::fuzz::TargetName(kTarget)).c_str(), err.c_str());
    std::abort();
  }
  return 0;
}
