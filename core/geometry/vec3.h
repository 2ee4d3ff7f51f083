// Plain 3D/2D vectors of doubles. Arithmetic here is for constructions only:
// every sign decision goes through core/geometry/predicates.h.
#pragma once

#include <array>
#include <cmath>

namespace svrc::geom {

struct Vec3 {
  double x = 0, y = 0, z = 0;

  constexpr Vec3() = default;
  constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}

  constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  const double* data() const { return &x; }

  friend constexpr Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend constexpr Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
  friend constexpr Vec3 operator*(Vec3 a, double s) { return {s * a.x, s * a.y, s * a.z}; }
  friend constexpr Vec3 operator/(Vec3 a, double s) { return {a.x / s, a.y / s, a.z / s}; }
  friend constexpr bool operator==(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
  Vec3& operator+=(Vec3 b) { x += b.x; y += b.y; z += b.z; return *this; }
  Vec3& operator-=(Vec3 b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
};

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");

constexpr double Dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 Cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr double Norm2(Vec3 a) { return Dot(a, a); }
inline double Norm(Vec3 a) { return std::sqrt(Norm2(a)); }
constexpr double Dist2(Vec3 a, Vec3 b) { return Norm2(a - b); }
inline double Dist(Vec3 a, Vec3 b) { return std::sqrt(Dist2(a, b)); }
inline bool IsFinite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

struct Vec2 {
  double x = 0, y = 0;
  constexpr Vec2() = default;
  constexpr Vec2(double x_, double y_) : x(x_), y(y_) {}
  const double* data() const { return &x; }
  friend constexpr Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
  friend constexpr Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
  friend constexpr Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
  friend constexpr bool operator==(Vec2 a, Vec2 b) { return a.x == b.x && a.y == b.y; }
};
static_assert(sizeof(Vec2) == 2 * sizeof(double), "Vec2 must be two packed doubles");

constexpr double Dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
constexpr double Norm2(Vec2 a) { return Dot(a, a); }

// Axis-aligned box.
struct Box3 {
  Vec3 lo{HUGE_VAL, HUGE_VAL, HUGE_VAL};
  Vec3 hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  void Add(Vec3 p) {
    lo = {std::fmin(lo.x, p.x), std::fmin(lo.y, p.y), std::fmin(lo.z, p.z)};
    hi = {std::fmax(hi.x, p.x), std::fmax(hi.y, p.y), std::fmax(hi.z, p.z)};
  }
  bool Empty() const { return lo.x > hi.x; }
  bool Contains(Vec3 p) const {  // closed box
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
  Vec3 Center() const { return 0.5 * (lo + hi); }
  double Diagonal() const { return Empty() ? 0.0 : Dist(lo, hi); }
};

}  // namespace svrc::geom
