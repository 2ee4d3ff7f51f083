// Exact arithmetic on floating-point expansions (Shewchuk 1997, "Adaptive
// Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates",
// §2). Used by the exact fallbacks of core/geometry/predicates.h and
// available for any other polynomial predicate: write the polynomial once as a
// template over the number type and instantiate it with Expansion.
//
// An expansion is a sum of doubles, stored nonoverlapping and in increasing
// order of magnitude with zeros eliminated, so the sign of the value is the
// sign of the last component. Exact barring overflow and underflow; requires
// IEEE double arithmetic with round-to-nearest-even and no contraction into
// FMA (the build uses -ffp-contract=off).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>

namespace svrc::geom {

// ---- error-free transformations (Shewchuk §2.4–2.5) -------------------------

// x + y == a + b exactly, x = fl(a + b). Requires |a| >= |b| (or a == 0).
inline void FastTwoSum(double a, double b, double& x, double& y) {
  x = a + b;
  const double b_virtual = x - a;
  y = b - b_virtual;
}

// x + y == a + b exactly, x = fl(a + b). No precondition (Knuth's algorithm).
inline void TwoSum(double a, double b, double& x, double& y) {
  x = a + b;
  const double b_virtual = x - a;
  const double a_virtual = x - b_virtual;
  const double b_round = b - b_virtual;
  const double a_round = a - a_virtual;
  y = a_round + b_round;
}

// x + y == a − b exactly, x = fl(a − b).
inline void TwoDiff(double a, double b, double& x, double& y) {
  x = a - b;
  const double b_virtual = a - x;
  const double a_virtual = x + b_virtual;
  const double b_round = b_virtual - b;
  const double a_round = a - a_virtual;
  y = a_round + b_round;
}

// Dekker's split: a == hi + lo, each with at most 26 significant bits.
inline void Split(double a, double& hi, double& lo) {
  constexpr double kSplitter = 134217729.0;  // 2^27 + 1
  const double c = kSplitter * a;
  const double a_big = c - a;
  hi = c - a_big;
  lo = a - hi;
}

// x + y == a·b exactly, x = fl(a·b) (Dekker/Veltkamp; no FMA on purpose).
inline void TwoProduct(double a, double b, double& x, double& y) {
  x = a * b;
  double a_hi, a_lo, b_hi, b_lo;
  Split(a, a_hi, a_lo);
  Split(b, b_hi, b_lo);
  const double err1 = x - a_hi * b_hi;
  const double err2 = err1 - a_lo * b_hi;
  const double err3 = err2 - a_hi * b_lo;
  y = a_lo * b_lo - err3;
}

// ---- expansions ------------------------------------------------------------

class Expansion {
 public:
  Expansion() = default;  // zero
  explicit Expansion(double x) {
    if (x != 0) c_.push_back(x);
  }
  // Exact a − b, a + b, a·b.
  static Expansion Diff(double a, double b);
  static Expansion Sum(double a, double b);
  static Expansion Product(double a, double b);

  int Sign() const { return c_.empty() ? 0 : (c_.back() > 0 ? 1 : -1); }
  bool IsZero() const { return c_.empty(); }
  // Approximate value (sum of the components, largest last).
  double Estimate() const;
  size_t size() const { return c_.size(); }
  const double* data() const { return c_.data(); }
  double operator[](size_t i) const { return c_[i]; }

  Expansion operator-() const;
  // Exact product with one double (Shewchuk's Scale-Expansion, zero-eliminating).
  Expansion Scale(double b) const;

  friend Expansion operator+(const Expansion& e, const Expansion& f);
  friend Expansion operator-(const Expansion& e, const Expansion& f);
  friend Expansion operator*(const Expansion& e, const Expansion& f);
  Expansion& operator+=(const Expansion& f) { return *this = *this + f; }
  Expansion& operator-=(const Expansion& f) { return *this = *this - f; }
  Expansion& operator*=(const Expansion& f) { return *this = *this * f; }

 private:
  // Components in a small buffer (no allocation up to kInline words: enough
  // for in-sphere on inputs whose coordinate differences are exact), on the
  // heap beyond. (Own type: absl::InlinedVector trips GCC 12's
  // -Wmaybe-uninitialized under -O3 -Werror.)
  class Words {
   public:
    static constexpr uint32_t kInline = 40;
    Words() = default;
    Words(const Words& o) { CopyFrom(o); }
    Words& operator=(const Words& o) {
      if (this != &o) {
        size_ = 0;
        CopyFrom(o);
      }
      return *this;
    }
    Words(Words&& o) noexcept { MoveFrom(o); }
    Words& operator=(Words&& o) noexcept {
      if (this != &o) {
        heap_.reset();
        cap_ = kInline;
        size_ = 0;
        MoveFrom(o);
      }
      return *this;
    }
    bool empty() const { return size_ == 0; }
    size_t size() const { return size_; }
    double* data() { return heap_ ? heap_.get() : inline_; }
    const double* data() const { return heap_ ? heap_.get() : inline_; }
    double operator[](size_t i) const { return data()[i]; }
    double back() const { return data()[size_ - 1]; }
    double* begin() { return data(); }
    double* end() { return data() + size_; }
    const double* begin() const { return data(); }
    const double* end() const { return data() + size_; }
    void reserve(size_t n) {
      if (n <= cap_) return;
      std::unique_ptr<double[]> h(new double[n]);
      if (size_ > 0) std::memcpy(h.get(), data(), size_ * sizeof(double));
      heap_ = std::move(h);
      cap_ = static_cast<uint32_t>(n);
    }
    void push_back(double x) {
      if (size_ == cap_) reserve(2 * size_t{cap_});
      data()[size_++] = x;
    }

   private:
    void CopyFrom(const Words& o) {
      reserve(o.size_);
      if (o.size_ > 0) std::memcpy(data(), o.data(), o.size_ * sizeof(double));
      size_ = o.size_;
    }
    void MoveFrom(Words& o) {
      if (o.heap_) {
        heap_ = std::move(o.heap_);
        cap_ = o.cap_;
        size_ = o.size_;
        o.cap_ = kInline;
        o.size_ = 0;
      } else {
        CopyFrom(o);
      }
    }
    double inline_[kInline];
    std::unique_ptr<double[]> heap_;
    uint32_t size_ = 0;
    uint32_t cap_ = kInline;
  };
  // Nonoverlapping, increasing magnitude, no zero components.
  Words c_;
};

}  // namespace svrc::geom
