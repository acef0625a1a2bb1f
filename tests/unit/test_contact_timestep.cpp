// Unit tests of the critical time-step estimates (src-liggghts-eepa/physics/contact_timestep.h).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "contact_timestep.h"
#include "eepa_law.h"

namespace {

using tsg::timestep::eepa_step_factor;
using tsg::timestep::hertz_collision_time;
using tsg::timestep::rayleigh_time;
using tsg::timestep::verlet_stable_step;

constexpr double kPi = 3.14159265358979323846;

// Seed paper, Table 3: G = 1.7e7 Pa, nu = 0.25, density 1263 kg/m^3, mean radius 200 um.
constexpr double kShearModulus = 1.7e7;
constexpr double kPoisson = 0.25;
constexpr double kDensity = 1263;

TEST(RayleighTime, SeedPaperParticles)
{
  // by hand: pi * 2e-4 * sqrt(1263 / 1.7e7) / (0.1631 * 0.25 + 0.8766)
  //        = 6.2832e-4 * 8.6194e-3 / 0.917375 = 5.9035e-6 s
  const double t400 = rayleigh_time(2e-4, kDensity, kShearModulus, kPoisson);
  EXPECT_NEAR(t400, 5.9035e-6, 1e-10);
  const double t200 = rayleigh_time(1e-4, kDensity, kShearModulus, kPoisson);
  EXPECT_NEAR(t200, 0.5 * t400, 1e-20);
  // Seed, Section 2.2: "5e-7 s, which is 10% of the critical Rayleigh timestep for 400 um
  // particles or 20% for 200 um particles". With Table 3 it is 8.5 % and 16.9 %: the seed's
  // percentages are rounded up, consistent with diameters of 400 and 200 um.
  EXPECT_NEAR(5e-7 / t400, 0.0847, 5e-4);
  EXPECT_NEAR(5e-7 / t200, 0.1694, 5e-4);
  std::cout << "[ measured ] Rayleigh time, 400 um (R = 200 um): " << t400 << " s; 5e-7 s is " << 100 * 5e-7 / t400
            << " % of it; 200 um: " << t200 << " s, " << 100 * 5e-7 / t200 << " %\n";
}

TEST(HertzCollisionTime, LinearSpringIsHalfAPeriod)
{
  const double k = 250.0, m = 3e-6;
  for (double v : {0.01, 1.0, 10.0})
    EXPECT_NEAR(hertz_collision_time(k, 1.0, m, v), kPi * std::sqrt(m / k), 1e-12 * kPi * std::sqrt(m / k));
}

TEST(HertzCollisionTime, HertzMatchesJohnsonAndScalesWithSpeedToMinusOneFifth)
{
  const double k1 = 3.0e5, m = 2e-8;
  for (double v : {0.1, 1.0}) {
    const double max_overlap = std::pow(5 * m * v * v / (4 * k1), 0.4);  // (1/2) m v^2 = (2/5) k1 d^2.5
    EXPECT_NEAR(hertz_collision_time(k1, 1.5, m, v), 2.94328 * max_overlap / v, 1e-5 * 2.94328 * max_overlap / v);
  }
  EXPECT_NEAR(hertz_collision_time(k1, 1.5, m, 1.0) / hertz_collision_time(k1, 1.5, m, 0.1), std::pow(10.0, -0.2),
              1e-12);
}

TEST(HertzCollisionTime, AgreesWithIntegratedImpact)
{
  const double k1 = 3.0e5, m = 2e-8, v0 = 0.5;
  for (double n : {1.0, 1.5, 2.0}) {
    const double expected = hertz_collision_time(k1, n, m, v0);
    const double dt = expected / 200000;
    double overlap = 0, v = v0, a = 0, t = 0;
    for (int i = 0; i < 1000000 && overlap >= 0; ++i) {  // velocity Verlet on m d'' = -k1 d^n
      v += 0.5 * dt * a;
      overlap += dt * v;
      a = overlap > 0 ? -k1 * std::pow(overlap, n) / m : 0;
      v += 0.5 * dt * a;
      t += dt;
    }
    EXPECT_NEAR(t, expected, 2e-5 * expected) << "n = " << n;
  }
}

TEST(VerletStableStep, BoundsTheStepOfALinearOscillator)
{
  const double k = 400.0, m = 1e-6;
  const double limit = verlet_stable_step(k, m);
  EXPECT_NEAR(limit, 2 * std::sqrt(m / k), 1e-18);
  auto amplitude_after = [k, m](double dt) {
    double x = 1, v = 0, a = -k / m, largest = 0;
    for (int i = 0; i < 2000; ++i) {
      v += 0.5 * dt * a;
      x += dt * v;
      a = -k * x / m;
      v += 0.5 * dt * a;
      largest = std::max(largest, std::fabs(x));
    }
    return largest;
  };
  EXPECT_LT(amplitude_after(0.95 * limit),
            10.0);  // Verlet amplitude factor 1/sqrt(1 - (w dt/2)^2) = 3.2
  EXPECT_GT(amplitude_after(1.01 * limit), 1e3);
}

TEST(EepaStepFactor, SqrtOneMinusPlasticityRatio)
{
  EXPECT_EQ(eepa_step_factor(0.0), 1.0);
  EXPECT_NEAR(eepa_step_factor(0.8), 1 / std::sqrt(5.0), 1e-15);  // k2/k1 = 5: sqrt(5) shorter
  EXPECT_NEAR(eepa_step_factor(0.5), std::sqrt(0.5), 1e-15);
}

TEST(EepaStepFactor, EqualsStableStepRatioOfTheLawsBranchStiffnesses)
{
  for (double lambda : {0.0, 0.2, 0.8, 0.99}) {
    const tsg::eepa::Parameters p{3.0e5, lambda, 1.5, 20, -1e-3, 15, 1e-4};
    const double m = 2e-8, d = 2e-6;
    const tsg::eepa::State loading = tsg::eepa::evaluate(p, {}, d);
    const tsg::eepa::State unloading = tsg::eepa::evaluate(p, loading.history, 0.999999 * d);
    const double ratio = verlet_stable_step(unloading.stiffness, m) / verlet_stable_step(loading.stiffness, m);
    EXPECT_NEAR(ratio, eepa_step_factor(lambda) / std::sqrt(std::pow(0.999999, 0.5)), 1e-9) << lambda;
  }
}

}  // namespace
