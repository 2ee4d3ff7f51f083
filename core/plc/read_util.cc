#include "core/plc/read_util.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"

namespace svrc::plc::internal {

bool ParseInt(std::string_view s, int64_t* out) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  int64_t v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size()) return false;
  *out = v;
  return true;
}

bool ParseDouble(std::string_view s, double* out) {
  bool neg = false;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
    neg = s[0] == '-';
    s.remove_prefix(1);
  }
  if (s.empty() || s[0] == '+' || s[0] == '-') return false;
  double v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
  if (p != s.data() + s.size()) {
    // Fortran-style exponents "1.5D+00" are not accepted (not TetGen either).
    return false;
  }
  if (ec == std::errc::result_out_of_range) {
    // Overflow/underflow: from_chars leaves v unchanged; decide by the exponent sign.
    const bool tiny = s.find_first_of("eE") != std::string_view::npos &&
                      s.find('-', s.find_first_of("eE")) != std::string_view::npos;
    v = tiny ? 0.0 : std::numeric_limits<double>::infinity();
  } else if (ec != std::errc()) {
    return false;
  }
  *out = neg ? -v : v;
  return true;
}

LineReader::LineReader(std::string_view bytes, std::string_view name, char comment)
    : bytes_(bytes), name_(name), comment_(comment) {}

bool LineReader::NextLine() {
  while (next_ < bytes_.size()) {
    size_t end = next_;
    while (end < bytes_.size() && bytes_[end] != '\n' && bytes_[end] != '\r') ++end;
    raw_ = bytes_.substr(next_, end - next_);
    // One line ending: \n, \r\n or \r.
    if (end < bytes_.size() && bytes_[end] == '\r' && end + 1 < bytes_.size() &&
        bytes_[end + 1] == '\n') {
      next_ = end + 2;
    } else {
      next_ = end < bytes_.size() ? end + 1 : end;  // never past the end
    }
    ++line_;
    tokens_.clear();
    pos_ = 0;
    size_t i = 0;
    while (i < raw_.size()) {
      const unsigned char c = static_cast<unsigned char>(raw_[i]);
      if (comment_ != 0 && raw_[i] == comment_) break;
      if (std::isspace(c) || c == 0) {
        ++i;
        continue;
      }
      size_t j = i;
      while (j < raw_.size() && !std::isspace(static_cast<unsigned char>(raw_[j])) &&
             raw_[j] != 0 && (comment_ == 0 || raw_[j] != comment_)) {
        ++j;
      }
      tokens_.push_back(raw_.substr(i, j - i));
      i = j;
    }
    if (!tokens_.empty()) return true;
  }
  tokens_.clear();
  pos_ = 0;
  return false;
}

absl::Status LineReader::NextToken(std::string_view what, std::string_view* tok) {
  while (Remaining() == 0) {
    if (!NextLine()) {
      return Error(Cat("unexpected end of file, expected ", what));
    }
  }
  *tok = Take();
  return absl::OkStatus();
}

absl::Status LineReader::NextInt(std::string_view what, int64_t* v) {
  std::string_view t;
  if (absl::Status s = NextToken(what, &t); !s.ok()) return s;
  if (!ParseInt(t, v)) return Error(Cat("expected ", what, " (an integer), got '", t.substr(0, 40), "'"));
  return absl::OkStatus();
}

absl::Status LineReader::NextDouble(std::string_view what, double* v) {
  std::string_view t;
  if (absl::Status s = NextToken(what, &t); !s.ok()) return s;
  if (!ParseDouble(t, v)) return Error(Cat("expected ", what, " (a number), got '", t.substr(0, 40), "'"));
  return absl::OkStatus();
}

bool LineReader::LineInt(int64_t* v, absl::Status* error) {
  if (Remaining() == 0) return false;
  const std::string_view t = Take();
  if (!ParseInt(t, v)) {
    *error = Error(Cat("expected an integer, got '", t.substr(0, 40), "'"));
    return false;
  }
  return true;
}

bool LineReader::LineDouble(double* v, absl::Status* error) {
  if (Remaining() == 0) return false;
  const std::string_view t = Take();
  if (!ParseDouble(t, v)) {
    *error = Error(Cat("expected a number, got '", t.substr(0, 40), "'"));
    return false;
  }
  return true;
}

absl::Status LineReader::Error(std::string_view reason) const { return ErrorAt(line_, reason); }

absl::Status LineReader::ErrorAt(size_t line, std::string_view reason) const {
  return absl::InvalidArgumentError(Cat(name_, ":", line, ": ", reason));
}

}  // namespace svrc::plc::internal
