// SHA-256 (FIPS 180-4, section 6.2), used for input fingerprints in result
// provenance and for content-addressed result storage. Pure C++, no OpenSSL.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace svrc::util {

// Incremental hasher:
//   Sha256 h; h.Update(a); h.Update(b); std::string hex = h.FinalHex();
// After Final*/FinalHex the object is reset and can hash a new message.
class Sha256 {
 public:
  using Digest = std::array<uint8_t, 32>;

  Sha256() { Reset(); }

  void Reset();
  void Update(const void* data, size_t size);
  void Update(std::string_view bytes) { Update(bytes.data(), bytes.size()); }

  // Pads, returns the 32-byte digest and resets.
  Digest Final();
  // Same as Final(), as 64 lowercase hex characters.
  std::string FinalHex();

 private:
  void Compress(const uint8_t* block);

  uint32_t h_[8];
  uint8_t buffer_[64];
  size_t buffered_ = 0;   // bytes in buffer_
  uint64_t total_ = 0;    // message length in bytes
};

// One-shot helpers.
Sha256::Digest Sha256Digest(std::string_view bytes);
std::string Sha256Hex(std::string_view bytes);

// Lowercase hex of arbitrary bytes.
std::string ToHex(const uint8_t* data, size_t size);

}  // namespace svrc::util
