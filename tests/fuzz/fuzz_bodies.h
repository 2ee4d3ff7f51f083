// The bodies of the libFuzzer targets (tests/fuzz/fuzz_main.cc) as plain
// functions, so that the GoogleTest replay (fuzz_replay_test.cc) runs every
// committed crasher and every corpus file through exactly the same code.
// How to build and run the targets: docs/fuzzing.md.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace svrc::fuzz {

// One target per PLC reader format, one for validation + feature complex, two
// for the container decoder (raw bytes; and with the trailing HASH section
// recomputed, so mutations get past the integrity check into the parser).
enum class Target {
  kPoly, kSmesh, kNode, kOff, kStl, kObj, kMedit,
  kValidate,
  kDecode, kDecodeRehash,
};
inline constexpr Target kAllTargets[] = {
    Target::kPoly, Target::kSmesh, Target::kNode, Target::kOff, Target::kStl,
    Target::kObj,  Target::kMedit, Target::kValidate, Target::kDecode, Target::kDecodeRehash};

// "plc_poly", ..., "plc_validate", "codec_decode", "codec_decode_rehash": the
// libFuzzer binary is fuzz_<name>, its crashers go to regressions/<name>/.
std::string_view TargetName(Target target);

// Validate target: parses bytes[1:] in the format picked by bytes[0] % 7 (the
// InputFormat order) and validates/prepares PLCs up to these sizes, so that
// one input stays in the millisecond range.
inline constexpr size_t kMaxValidateVertices = 4096;
inline constexpr size_t kMaxValidateFacets = 4096;
inline constexpr size_t kMaxValidatePolygonVertices = 16384;

// Runs one input. Returns "" when every contract held, else what broke (a
// status code a function must never return, an inconsistent result, a
// decoded mesh that does not survive re-encoding). Crashes and sanitizer
// reports are, of course, not returned: they end the process.
std::string RunOne(Target target, std::string_view bytes);

// The seed files of `target` under `corpus_dir`, recursively, sorted: for a
// reader the files with its extension, for validate every reader file, for
// the decoders none (their seed is tests/codec/data/reference_v1.svrc).
std::vector<std::string> SeedFiles(Target target, const std::string& corpus_dir);
// The input libFuzzer sees for the seed file `path` of `target`: the file
// itself, or for validate the file prefixed with its format byte
// (tests/fuzz/run_fuzz.sh builds the same seeds).
std::string SeedBytes(Target target, const std::string& path, const std::string& file_bytes);

}  // namespace svrc::fuzz
