// Unit tests of the sphere-slab volume (physics/sphere_slab.h) and of the per-zone overlap of a
// sphere (physics/zone_overlap.h), against textbook cap formulas and numerical integration.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "sphere_slab.h"
#include "zone_overlap.h"

namespace {

using tsg::geometry::sphere_slab_fraction;
using tsg::geometry::sphere_slab_volume;
using tsg::geometry::sphere_volume;

constexpr double kPi = 3.14159265358979323846;

// Textbook spherical cap of height h: π h² (3R - h) / 3 (independent of the header's form).
double cap(double radius, double h) { return kPi * h * h * (3 * radius - h) / 3; }

// Composite Simpson rule of the cross-section area π (R² - s²) between a and b.
double simpson(double radius, double a, double b, int n = 2000)
{
  const double h = (b - a) / n;
  double sum = 0;
  for (int k = 0; k <= n; ++k) {
    const double s = a + k * h;
    const double weight = (k == 0 || k == n) ? 1 : (k % 2 ? 4 : 2);
    sum += weight * kPi * (radius * radius - s * s);
  }
  return sum * h / 3;
}

TEST(SphereSlab, WholeSphereHalfAndNothing)
{
  const double r = 2e-4;
  EXPECT_DOUBLE_EQ(sphere_slab_volume(0.01, r, 0.0, 1.0), sphere_volume(r));
  EXPECT_DOUBLE_EQ(sphere_slab_volume(0.01, r, 0.01, 1.0), 0.5 * sphere_volume(r));
  EXPECT_DOUBLE_EQ(sphere_slab_volume(0.01, r, -1.0, 0.01), 0.5 * sphere_volume(r));
  EXPECT_EQ(sphere_slab_volume(0.01, r, 0.0102, 1.0), 0.0);  // touches the slab only
  EXPECT_EQ(sphere_slab_volume(0.01, r, 0.02, 0.03), 0.0);
  EXPECT_EQ(sphere_slab_volume(0.01, r, 0.005, 0.005), 0.0);  // empty slab
  EXPECT_NEAR(sphere_volume(1.0), 4.18879020478639, 1e-13);
}

TEST(SphereSlab, CapsMatchTheTextbookFormula)
{
  const double r = 1e-3;
  for (double c : {0.0, 0.05, -0.2})
    for (double h : {1e-9, 1e-6, 1e-4, 3e-4, 1e-3, 1.5e-3, 1.999e-3}) {
      // the plane positions are rounded to doubles: the cap height the sphere really has is the
      // distance from the plane to the pole, (c + r) - x0, as computed relative to the centre
      const double x_top = c + r - h, x_bottom = c - r + h;
      const double h_top = r - (x_top - c), h_bottom = r + (x_bottom - c);
      EXPECT_NEAR(sphere_slab_volume(c, r, x_top, 1.0) / cap(r, h_top), 1.0, 1e-12) << "c = " << c << ", h = " << h;
      EXPECT_NEAR(sphere_slab_volume(c, r, -1.0, x_bottom) / cap(r, h_bottom), 1.0, 1e-12)
          << "c = " << c << ", h = " << h;
    }
}

TEST(SphereSlab, RandomSlabsMatchNumericalIntegration)
{
  std::mt19937_64 rng(20240601);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const double r = 1.0;
  for (int k = 0; k < 200; ++k) {
    double a = u(rng), b = u(rng);
    if (a > b) std::swap(a, b);
    const double lo = std::max(a, -r), hi = std::min(b, r);
    const double expected = hi > lo ? simpson(r, lo, hi) : 0.0;  // Simpson is exact for a quadratic
    EXPECT_NEAR(sphere_slab_volume(0.0, r, a, b), expected, 1e-12 * sphere_volume(r)) << a << " " << b;
  }
}

TEST(SphereSlab, AdjacentSlabsAddUpToTheSphere)
{
  const double r = 3e-4, c = 0.0123;
  std::vector<double> cuts = {c - r - 1e-5, c - 2.7e-4, c - 1e-4, c, c + 1.3e-7, c + 2.9e-4, c + r + 1e-3};
  double sum = 0, fractions = 0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    sum += sphere_slab_volume(c, r, cuts[k], cuts[k + 1]);
    fractions += sphere_slab_fraction(c, r, cuts[k], cuts[k + 1]);
  }
  EXPECT_NEAR(sum / sphere_volume(r), 1.0, 1e-14);
  EXPECT_NEAR(fractions, 1.0, 1e-14);
}

TEST(SphereSlab, ThinSlabKeepsFullRelativePrecision)
{
  // a slab 1e-9 R thick through the centre holds π R² w (1 - O(w²))
  const double r = 2e-4, w = 2e-13;
  EXPECT_NEAR(sphere_slab_volume(0.0, r, -w / 2, w / 2) / (kPi * r * r * w), 1.0, 1e-12);
  // and near the pole, a thin shell [R - 2w, R - w] holds cap(2w) - cap(w), i.e. π w² (3R - 3w)
  // up to the rounding of the plane positions (2e-20 m near R, relative 1e-7 of w)
  const double lo = r - 2 * w, hi = r - w;
  EXPECT_NEAR(sphere_slab_volume(0.0, r, lo, hi) / (cap(r, r - lo) - cap(r, r - hi)), 1.0, 1e-9);
}

TEST(SphereSlab, FractionIsVolumeOverSphere)
{
  const double r = 7e-4, c = 0.3;
  for (double x0 : {0.2995, 0.2999, 0.3, 0.3004})
    EXPECT_NEAR(sphere_slab_fraction(c, r, x0, x0 + 5e-4), sphere_slab_volume(c, r, x0, x0 + 5e-4) / sphere_volume(r),
                1e-15);
}

std::vector<tsg::zones::Zone> three_zones()
{
  // [0, 0.01) conveying, [0.01, 0.015) kneading, gap, [0.02, 0.03) chopping
  return tsg::zones::parse_zones_text(
      "1 conveying 0 0.01 1e-6\n2 kneading 0.01 0.015 1e-6\n3 chopping 0.02 0.03 1e-6\n", "z");
}

TEST(ZoneOverlap, SphereCutByAZoneBoundaryCountsInBothZones)
{
  const auto zones = three_zones();
  std::vector<double> f(3, 0.0);
  tsg::zones::for_each_overlap(zones, 0.0098, 5e-4, 0.0, 0.0, [&](int z, double fraction) { f[z] += fraction; });
  const double r = 5e-4;
  EXPECT_NEAR(f[0], 1 - cap(r, 3e-4) / sphere_volume(r), 1e-14);
  EXPECT_NEAR(f[1], cap(r, 3e-4) / sphere_volume(r), 1e-14);
  EXPECT_EQ(f[2], 0.0);
}

TEST(ZoneOverlap, SphereInAGapCountsNowhere)
{
  const auto zones = three_zones();
  int calls = 0;
  tsg::zones::for_each_overlap(zones, 0.0175, 1e-3, 0.0, 0.0, [&](int, double) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ZoneOverlap, PeriodicImageAcrossTheBoxBoundary)
{
  // box [0, 0.03): a sphere at x = 0.0297 with R = 5e-4 sticks out by 2e-4 through x = 0.03,
  // which is x = 0 again: that cap belongs to zone 1
  const auto zones = three_zones();
  const double r = 5e-4;
  std::vector<double> f(3, 0.0);
  tsg::zones::for_each_overlap(zones, 0.0297, r, 0.03, 0.0, [&](int z, double fraction) { f[z] += fraction; });
  EXPECT_NEAR(f[0], cap(r, 2e-4) / sphere_volume(r), 1e-14);
  EXPECT_NEAR(f[2], 1 - cap(r, 2e-4) / sphere_volume(r), 1e-14);
  EXPECT_NEAR(f[0] + f[1] + f[2], 1.0, 1e-14);
  // without periodicity the cap is outside every zone
  std::vector<double> g(3, 0.0);
  tsg::zones::for_each_overlap(zones, 0.0297, r, 0.0, 0.0, [&](int z, double fraction) { g[z] += fraction; });
  EXPECT_EQ(g[0], 0.0);
  // and the other end: a sphere at x = 0.0002 sticks out through x = 0 into zone 3 (x < 0.03)
  std::vector<double> h(3, 0.0);
  tsg::zones::for_each_overlap(zones, 0.0002, r, 0.03, 0.0, [&](int z, double fraction) { h[z] += fraction; });
  EXPECT_NEAR(h[2], cap(r, 3e-4) / sphere_volume(r), 1e-14);
  EXPECT_NEAR(h[0], 1 - cap(r, 3e-4) / sphere_volume(r), 1e-14);
}

}  // namespace
