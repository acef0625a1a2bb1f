// physics/yield_law.h: Hertz with a limiting contact pressure, against its closed forms and against
// an independent integration of a head-on impact.
#include <gtest/gtest.h>

#include <cmath>

#include "yield_law.h"

namespace y = tsg::yield;

namespace {
// the 400 µm particle against the screws: E* of the particle–geometry pair, p_y 1 MPa
const y::Parameters kParams{3.87e7, 2.0e-4, 1.0e6};
constexpr double kMass = 4.23e-8;  // kg

// Velocity Verlet of a sphere hitting a rigid wall head-on at `speed`: the rebound speed.
double integrated_rebound(const y::Parameters &p, double speed, double dt)
{
  double overlap = 0, v = speed;  // v > 0: moving into the wall
  y::History history;
  double force = 0;
  while (true) {
    v -= 0.5 * dt * force / kMass;
    overlap += dt * v;
    if (overlap <= 0) return -v;
    const y::State s = y::evaluate(p, history, overlap);
    history = s.history;
    force = s.force;
    v -= 0.5 * dt * force / kMass;
  }
}
}  // namespace

TEST(YieldLaw, BelowTheYieldOverlapItIsHertz)
{
  const double dy = y::yield_overlap(kParams);
  const double overlap = 0.5 * dy;
  const y::State s = y::evaluate(kParams, y::History{}, overlap);
  EXPECT_DOUBLE_EQ(s.force, 4.0 / 3.0 * kParams.modulus * std::sqrt(kParams.radius * overlap) * overlap);
  EXPECT_FALSE(s.yielding);
  // the largest Hertz pressure 2 E* a / (π R) reaches p_y exactly at δ_y
  const double a = std::sqrt(kParams.radius * dy);
  EXPECT_NEAR(2 * kParams.modulus * a / (y::kPi * kParams.radius), kParams.yield_pressure,
              1e-9 * kParams.yield_pressure);
}

TEST(YieldLaw, BeyondYieldTheForceGrowsAtPiPyR)
{
  const double dy = y::yield_overlap(kParams);
  const double d1 = 3 * dy, d2 = 5 * dy;
  const double slope = (y::loading_force(kParams, d2) - y::loading_force(kParams, d1)) / (d2 - d1);
  EXPECT_NEAR(slope, y::kPi * kParams.yield_pressure * kParams.radius, 1e-9 * slope);
}

TEST(YieldLaw, UnloadingStartsAtTheLargestForceAndEndsAtThePlasticOverlap)
{
  const double dmax = 0.3 * kParams.radius;
  const y::History h = y::loaded_to(kParams, dmax);
  EXPECT_NEAR(y::evaluate(kParams, h, dmax * (1 - 1e-12)).force, h.max_force, 1e-6 * h.max_force);
  EXPECT_GT(h.plastic_overlap, 0);
  EXPECT_LT(h.plastic_overlap, dmax);
  EXPECT_DOUBLE_EQ(y::evaluate(kParams, h, h.plastic_overlap).force, 0);
}

TEST(YieldLaw, LoadingWorkIsTheIntegralOfTheLoadingForce)
{
  const double dmax = 0.2 * kParams.radius;
  const int n = 200000;
  double work = 0;
  for (int k = 0; k < n; ++k) {
    const double a = dmax * k / n, b = dmax * (k + 1) / n;
    work += 0.5 * (b - a) * (y::loading_force(kParams, a) + y::loading_force(kParams, b));
  }
  EXPECT_NEAR(y::loading_work(kParams, dmax), work, 1e-6 * work);
}

TEST(YieldLaw, AnIntegratedImpactReboundsAtTheClosedFormSpeed)
{
  for (double speed : {0.01, 1.0, 10.0, 37.0}) {
    const double expected = y::rebound_speed(kParams, kMass, speed);
    EXPECT_NEAR(integrated_rebound(kParams, speed, 1e-9), expected, 5e-3 * expected) << "impact at " << speed << " m/s";
  }
  // far beyond yield almost all the work is dissipated: 37 m/s (the Hertz release of an overlap of
  // R/2 against the screws) comes back at a few m/s
  EXPECT_LT(y::rebound_speed(kParams, kMass, 37.0), 0.2 * 37.0);
}

TEST(YieldLaw, AnElasticImpactGivesAllItsEnergyBack)
{
  const double elastic = 0.5 * std::sqrt(2 * 0.4 * y::yield_force(kParams) * y::yield_overlap(kParams) / kMass);
  EXPECT_NEAR(y::rebound_speed(kParams, kMass, elastic), elastic, 1e-12 * elastic);
}

TEST(YieldLaw, ParametersAreValidated)
{
  EXPECT_THROW(y::validate({0, 1e-4, 1e6}), std::invalid_argument);
  EXPECT_THROW(y::validate({1e7, -1e-4, 1e6}), std::invalid_argument);
  EXPECT_THROW(y::validate({1e7, 1e-4, 0}), std::invalid_argument);
  EXPECT_NO_THROW(y::validate(kParams));
}
