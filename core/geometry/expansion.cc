// Expansion arithmetic after Shewchuk 1997, §2.6–2.8 (Grow-, Scale- and
// Fast-Expansion-Sum with zero elimination). Written from the paper.
#include "core/geometry/expansion.h"

#include <algorithm>
#include <cmath>

namespace svrc::geom {

Expansion Expansion::Diff(double a, double b) {
  double x, y;
  TwoDiff(a, b, x, y);
  Expansion e;
  if (y != 0) e.c_.push_back(y);
  if (x != 0) e.c_.push_back(x);
  return e;
}

Expansion Expansion::Sum(double a, double b) {
  double x, y;
  TwoSum(a, b, x, y);
  Expansion e;
  if (y != 0) e.c_.push_back(y);
  if (x != 0) e.c_.push_back(x);
  return e;
}

Expansion Expansion::Product(double a, double b) {
  double x, y;
  TwoProduct(a, b, x, y);
  Expansion e;
  if (y != 0) e.c_.push_back(y);
  if (x != 0) e.c_.push_back(x);
  return e;
}

double Expansion::Estimate() const {
  double s = 0;
  for (double c : c_) s += c;
  return s;
}

Expansion Expansion::operator-() const {
  Expansion e = *this;
  for (double& c : e.c_) c = -c;
  return e;
}

// Scale-Expansion (Shewchuk Theorem 19): h = e·b. Each component product
// e_i·b = T + t is exact; t is folded into the running sum Q with TwoSum and
// T with FastTwoSum (|T| ≥ |Q| there), emitting the low-order words.
Expansion Expansion::Scale(double b) const {
  Expansion h;
  if (c_.empty() || b == 0) return h;
  h.c_.reserve(2 * c_.size());
  double b_hi, b_lo;
  Split(b, b_hi, b_lo);
  auto product = [&](double a, double& x, double& y) {
    x = a * b;
    double a_hi, a_lo;
    Split(a, a_hi, a_lo);
    const double err1 = x - a_hi * b_hi;
    const double err2 = err1 - a_lo * b_hi;
    const double err3 = err2 - a_hi * b_lo;
    y = a_lo * b_lo - err3;
  };
  double q, t;
  product(c_[0], q, t);
  if (t != 0) h.c_.push_back(t);
  for (size_t i = 1; i < c_.size(); ++i) {
    double big, small, s, w;
    product(c_[i], big, small);
    TwoSum(q, small, s, w);
    if (w != 0) h.c_.push_back(w);
    FastTwoSum(big, s, q, w);
    if (w != 0) h.c_.push_back(w);
  }
  if (q != 0) h.c_.push_back(q);
  return h;
}

// Fast-Expansion-Sum (Shewchuk Theorem 13): merge both component lists by
// magnitude, then run one TwoSum chain from the smallest word up. (The first
// step may be a FastTwoSum since |g1| ≤ |g2|; TwoSum computes the same pair.)
Expansion operator+(const Expansion& e, const Expansion& f) {
  if (e.c_.empty()) return f;
  if (f.c_.empty()) return e;
  const size_t m = e.c_.size() + f.c_.size();
  double g_small[32];
  std::unique_ptr<double[]> g_heap;
  double* g = g_small;
  if (m > 32) {
    g_heap.reset(new double[m]);
    g = g_heap.get();
  }
  std::merge(e.c_.begin(), e.c_.end(), f.c_.begin(), f.c_.end(), g,
             [](double x, double y) { return std::fabs(x) < std::fabs(y); });
  Expansion h;
  h.c_.reserve(m);
  double q = g[0];
  for (size_t i = 1; i < m; ++i) {
    double s, w;
    TwoSum(q, g[i], s, w);
    if (w != 0) h.c_.push_back(w);
    q = s;
  }
  if (q != 0) h.c_.push_back(q);
  return h;
}

Expansion operator-(const Expansion& e, const Expansion& f) { return e + (-f); }

Expansion operator*(const Expansion& e, const Expansion& f) {
  const Expansion& longer = e.size() >= f.size() ? e : f;
  const Expansion& shorter = e.size() >= f.size() ? f : e;
  Expansion h;
  for (double c : shorter.c_) h = h + longer.Scale(c);
  return h;
}

}  // namespace svrc::geom
