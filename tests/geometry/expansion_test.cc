// Expansion arithmetic against GMP rationals (doubles convert exactly).
#include "core/geometry/expansion.h"

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <random>

#include <gtest/gtest.h>

namespace svrc::geom {
namespace {

mpq_class Exact(const Expansion& e) {
  mpq_class s = 0;
  for (size_t i = 0; i < e.size(); ++i) s += mpq_class(e[i]);
  return s;
}

// Nonoverlapping, increasing magnitude, no zeros.
void ExpectWellFormed(const Expansion& e) {
  for (size_t i = 0; i < e.size(); ++i) {
    ASSERT_NE(e[i], 0.0);
    if (i > 0) {
      ASSERT_LT(std::fabs(e[i - 1]), std::fabs(e[i]));
      // Nonoverlapping: |e[i-1]| < 2^(lowest set bit of e[i]).
      int ex;
      const double m = std::frexp(e[i], &ex);  // e[i] = m·2^ex, |m| in [0.5, 1)
      const int64_t mant = static_cast<int64_t>(std::ldexp(std::fabs(m), 53));
      const int low_bit = ex - 53 + __builtin_ctzll(static_cast<uint64_t>(mant));
      ASSERT_LT(std::fabs(e[i - 1]), std::ldexp(1.0, low_bit));
    }
  }
}

double RandomDouble(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> mant(-1, 1);
  std::uniform_int_distribution<int> ex(-60, 60);
  return std::ldexp(mant(rng), ex(rng));
}

TEST(ExpansionTest, ErrorFreeTransformations) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 5000; ++i) {
    const double a = RandomDouble(rng), b = RandomDouble(rng);
    double x, y;
    TwoSum(a, b, x, y);
    ASSERT_EQ(mpq_class(x) + mpq_class(y), mpq_class(a) + mpq_class(b));
    TwoDiff(a, b, x, y);
    ASSERT_EQ(mpq_class(x) + mpq_class(y), mpq_class(a) - mpq_class(b));
    TwoProduct(a, b, x, y);
    ASSERT_EQ(mpq_class(x) + mpq_class(y), mpq_class(a) * mpq_class(b));
    ASSERT_EQ(x, a * b);
  }
}

TEST(ExpansionTest, RandomPolynomialsMatchGmp) {
  std::mt19937_64 rng(2);
  for (int iter = 0; iter < 3000; ++iter) {
    Expansion e;
    mpq_class q = 0;
    const int terms = 1 + iter % 7;
    for (int t = 0; t < terms; ++t) {
      const double a = RandomDouble(rng), b = RandomDouble(rng), c = RandomDouble(rng);
      Expansion term = Expansion::Diff(a, b) * Expansion::Product(b, c);
      mpq_class qt = (mpq_class(a) - mpq_class(b)) * (mpq_class(b) * mpq_class(c));
      if (t % 2) {
        e -= term;
        q -= qt;
      } else {
        e += term;
        q += qt;
      }
      e = e.Scale(0.75);
      q *= mpq_class(0.75);
    }
    ExpectWellFormed(e);
    ASSERT_EQ(Exact(e), q);
    ASSERT_EQ(e.Sign(), sgn(q));
  }
}

// Long expansions (beyond the inline buffer) through copies and moves.
TEST(ExpansionTest, LongExpansionsCopyAndMove) {
  std::mt19937_64 rng(3);
  Expansion e;
  mpq_class q = 0;
  size_t longest = 0;
  // Words spread over 2^-900..2^900: sums stay exact, and long.
  for (int i = 0; i < 400; ++i) {
    const double a = RandomDouble(rng) * std::ldexp(1.0, 9 * (i % 200) - 900);
    e += Expansion(a);
    q += mpq_class(a);
    longest = std::max(longest, e.size());
  }
  ASSERT_GT(longest, 40u);  // exercised the heap storage
  Expansion copy = e;
  Expansion moved = std::move(copy);
  Expansion assigned;
  assigned = moved;
  assigned = assigned;  // self-assignment keeps the value
  ExpectWellFormed(assigned);
  EXPECT_EQ(Exact(assigned), q);
  EXPECT_EQ(Exact(moved), q);
  EXPECT_EQ((assigned - e).Sign(), 0);
  // Products on a moderate exponent range (no underflow).
  Expansion f;
  mpq_class r = 0;
  for (int i = 0; i < 60; ++i) {
    const double a = RandomDouble(rng) * std::ldexp(1.0, 8 * (i % 30) - 120), b = RandomDouble(rng);
    f += Expansion::Product(a, b);
    r += mpq_class(a) * mpq_class(b);
  }
  EXPECT_EQ(Exact(f * f), r * r);
  EXPECT_EQ(Exact(f * (-f)), -(r * r));
}

TEST(ExpansionTest, CancellationGivesExactZero) {
  const double a = 0.1, b = 1e-17, c = 3.0;
  Expansion x = Expansion::Sum(a, b) * Expansion(c);
  Expansion y = Expansion::Product(a, c) + Expansion::Product(b, c);
  Expansion d = x - y;
  EXPECT_TRUE(d.IsZero());
  EXPECT_EQ(d.Sign(), 0);
  EXPECT_EQ(Expansion().Sign(), 0);
  EXPECT_EQ(Expansion(-2.0).Sign(), -1);
}

}  // namespace
}  // namespace svrc::geom
