// Little-endian byte writer and a bounds-checked reader for the result
// container (docs/container.md). The reader never reads past its end: every
// Read* returns false instead, so the decoder can turn it into INVALID_ARGUMENT.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace svrc::codec {

class ByteWriter {
 public:
  void U8(uint8_t v) { out_.push_back(static_cast<char>(v)); }
  void U16(uint16_t v) { Le(v, 2); }
  void U32(uint32_t v) { Le(v, 4); }
  void U64(uint64_t v) { Le(v, 8); }
  void I64(int64_t v) { Le(static_cast<uint64_t>(v), 8); }
  void F64(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, 8);
    Le(bits, 8);
  }
  void Bytes(std::string_view b) { out_.append(b); }
  // u32 length, then the bytes.
  void String(std::string_view s) {
    U32(static_cast<uint32_t>(s.size()));
    Bytes(s);
  }
  size_t size() const { return out_.size(); }
  std::string& str() { return out_; }

 private:
  void Le(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  std::string out_;
};

class ByteReader {
 public:
  explicit ByteReader(std::string_view in) : in_(in) {}

  size_t remaining() const { return in_.size() - pos_; }
  size_t position() const { return pos_; }
  bool AtEnd() const { return pos_ == in_.size(); }

  bool U8(uint8_t* v) {
    uint64_t x;
    if (!Le(&x, 1)) return false;
    *v = static_cast<uint8_t>(x);
    return true;
  }
  bool U16(uint16_t* v) {
    uint64_t x;
    if (!Le(&x, 2)) return false;
    *v = static_cast<uint16_t>(x);
    return true;
  }
  bool U32(uint32_t* v) {
    uint64_t x;
    if (!Le(&x, 4)) return false;
    *v = static_cast<uint32_t>(x);
    return true;
  }
  bool U64(uint64_t* v) { return Le(v, 8); }
  bool I64(int64_t* v) {
    uint64_t x;
    if (!Le(&x, 8)) return false;
    *v = static_cast<int64_t>(x);
    return true;
  }
  bool F64(double* v) {
    uint64_t x;
    if (!Le(&x, 8)) return false;
    std::memcpy(v, &x, 8);
    return true;
  }
  // A view of the next `n` bytes (checked against what is left first).
  bool Bytes(uint64_t n, std::string_view* v) {
    if (n > remaining()) return false;
    *v = in_.substr(pos_, static_cast<size_t>(n));
    pos_ += static_cast<size_t>(n);
    return true;
  }
  bool String(std::string* s) {
    uint32_t n;
    std::string_view v;
    if (!U32(&n) || !Bytes(n, &v)) return false;
    s->assign(v);
    return true;
  }

 private:
  bool Le(uint64_t* v, int n) {
    if (remaining() < static_cast<size_t>(n)) return false;
    uint64_t x = 0;
    for (int i = 0; i < n; ++i) {
      x |= static_cast<uint64_t>(static_cast<uint8_t>(in_[pos_ + i])) << (8 * i);
    }
    pos_ += n;
    *v = x;
    return true;
  }
  std::string_view in_;
  size_t pos_ = 0;
};

// One section of the container: 4-byte tag, u64 length, payload.
struct Section {
  std::string_view tag;
  std::string_view payload;
};

// Splits `in` (a run of sections) into its sections, checking every length
// against the bytes left. Returns false on a truncated or overlong section.
inline bool SplitSections(std::string_view in, std::vector<Section>* out) {
  ByteReader r(in);
  while (!r.AtEnd()) {
    Section s;
    uint64_t length = 0;
    if (!r.Bytes(4, &s.tag) || !r.U64(&length) || !r.Bytes(length, &s.payload)) return false;
    out->push_back(s);
  }
  return true;
}

}  // namespace svrc::codec
