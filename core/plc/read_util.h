// Tokenizing helpers shared by the PLC readers: line-oriented tokens with
// comments, locale-independent number parsing, "file:line: reason" errors.
// Nothing here allocates in proportion to a count read from the input.
#pragma once

#include <cstdint>
#include <cstdio>
#include <type_traits>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"

namespace svrc::plc::internal {

// String concatenation that takes std::string_view (Debian's Abseil has its
// own absl::string_view, so absl::StrCat rejects std::string_view).
inline void CatAppend(std::string& s, std::string_view v) { s.append(v.data(), v.size()); }
inline void CatAppend(std::string& s, const char* v) { s.append(v); }
inline void CatAppend(std::string& s, const std::string& v) { s.append(v); }
inline void CatAppend(std::string& s, char v) { s.push_back(v); }
template <typename T>
  requires std::is_arithmetic_v<T>
inline void CatAppend(std::string& s, T v) {
  if constexpr (std::is_floating_point_v<T>) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", static_cast<double>(v));
    s.append(buf);
  } else {
    s.append(std::to_string(v));
  }
}
template <typename... Args>
std::string Cat(const Args&... args) {
  std::string s;
  (CatAppend(s, args), ...);
  return s;
}

inline std::string Lower(std::string_view v) {
  std::string s(v);
  for (char& c : s) c = (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
  return s;
}
inline bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }
inline std::string_view Strip(std::string_view v) {
  while (!v.empty() && IsSpace(v.front())) v.remove_prefix(1);
  while (!v.empty() && IsSpace(v.back())) v.remove_suffix(1);
  return v;
}

// Parses a decimal integer (optional sign). False on junk or overflow.
bool ParseInt(std::string_view s, int64_t* out);
// Parses a floating-point number, locale-independent: decimal or exponent
// forms, optional leading '+', and "nan"/"inf"/"infinity" (any case) so that
// validation can report them. False on junk.
bool ParseDouble(std::string_view s, double* out);

// Reads whitespace-separated tokens line by line. Text after `comment` on a
// line is ignored; blank lines are skipped.
class LineReader {
 public:
  LineReader(std::string_view bytes, std::string_view name, char comment = '#');

  // Advances to the next line with at least one token; false at end of input.
  bool NextLine();
  // Tokens of the current line not consumed yet.
  size_t Remaining() const { return tokens_.size() - pos_; }
  std::string_view Peek() const { return tokens_[pos_]; }
  std::string_view Take() { return tokens_[pos_++]; }
  const std::vector<std::string_view>& tokens() const { return tokens_; }
  void SkipRestOfLine() { pos_ = tokens_.size(); }
  // The whole current line (raw, without the end of line).
  std::string_view raw_line() const { return raw_; }
  size_t line() const { return line_; }
  bool at_end() const { return next_ >= bytes_.size(); }
  // After a last line without a line ending next_ is size + 1: clamp, or the
  // count caps (CappedReserve) wrap to SIZE_MAX (fuzz: plc_poly regression).
  size_t bytes_left() const { return next_ < bytes_.size() ? bytes_.size() - next_ : 0; }

  // Next token, continuing on the following lines if this one is used up.
  // Returns an error naming `what` at end of input.
  absl::Status NextToken(std::string_view what, std::string_view* tok);
  absl::Status NextInt(std::string_view what, int64_t* v);
  absl::Status NextDouble(std::string_view what, double* v);
  // Like NextInt/NextDouble but only from the current line; false if none left.
  bool LineInt(int64_t* v, absl::Status* error);
  bool LineDouble(double* v, absl::Status* error);

  absl::Status Error(std::string_view reason) const;
  absl::Status ErrorAt(size_t line, std::string_view reason) const;
  const std::string& name() const { return name_; }

 private:
  std::string_view bytes_;
  std::string name_;
  char comment_;
  size_t next_ = 0;   // offset of the next unread line
  size_t line_ = 0;   // 1-based number of the current line
  std::string_view raw_;
  std::vector<std::string_view> tokens_;
  size_t pos_ = 0;
};

// At most this many elements are reserved up front from a count in a file.
inline size_t CappedReserve(int64_t count, size_t bytes_left, size_t min_bytes_per_item) {
  if (count <= 0) return 0;
  const size_t cap = bytes_left / (min_bytes_per_item ? min_bytes_per_item : 1) + 1;
  return static_cast<size_t>(count) < cap ? static_cast<size_t>(count) : cap;
}

}  // namespace svrc::plc::internal
