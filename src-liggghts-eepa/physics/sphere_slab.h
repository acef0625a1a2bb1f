// Exact volume of a sphere inside a slab x0 <= x <= x1, dependency-free. SI units.
//
// A sphere of radius R centred at c has cross-section area π (R² - s²) at s = x - c, so the part
// between s = a and s = b (-R <= a <= b <= R) is
//   V(a, b) = ∫_a^b π (R² - s²) ds = π (b - a) (R² - (a² + a b + b²) / 3).
// a = -R, b = R gives 4/3 π R³; a = R - h, b = R gives the spherical cap π h² (3R - h) / 3.
// The bracket is evaluated as a sum of non-negative products of the distances to the poles,
//   R² - (a² + ab + b²)/3 = [ (R-a)(R+a) + (R-b)(R+b) + ((R-a)(R+b) + (R-b)(R+a))/2 ] / 3,
// so nothing cancels: thin slabs and small caps keep full relative precision, and the pieces of a
// sphere cut by adjacent slabs add up to the whole sphere.
#ifndef TSG_SPHERE_SLAB_H
#define TSG_SPHERE_SLAB_H

#include <algorithm>

namespace tsg::geometry {

constexpr double kPi = 3.14159265358979323846;

namespace detail {
// R² - (a² + ab + b²)/3 for -R <= a <= b <= R, without cancellation (see the top of the file)
inline double bracket(double radius, double a, double b)
{
  const double below_a = radius + a, above_a = radius - a;
  const double below_b = radius + b, above_b = radius - b;
  return (above_a * below_a + above_b * below_b + 0.5 * (above_a * below_b + above_b * below_a)) / 3.0;
}
}  // namespace detail

inline double sphere_volume(double radius) { return 4.0 / 3.0 * kPi * radius * radius * radius; }

// Volume of the sphere (centre, radius) between the planes x = x0 and x = x1 (x0 <= x1).
inline double sphere_slab_volume(double centre, double radius, double x0, double x1)
{
  const double a = std::max(x0 - centre, -radius);
  const double b = std::min(x1 - centre, radius);
  if (!(b > a)) return 0.0;
  return kPi * (b - a) * detail::bracket(radius, a, b);
}

// Fraction (0..1) of the sphere's volume between x0 and x1.
inline double sphere_slab_fraction(double centre, double radius, double x0, double x1)
{
  const double a = std::max(x0 - centre, -radius) / radius;
  const double b = std::min(x1 - centre, radius) / radius;
  if (!(b > a)) return 0.0;
  return 0.75 * (b - a) * detail::bracket(1.0, a, b);
}

}  // namespace tsg::geometry

#endif
