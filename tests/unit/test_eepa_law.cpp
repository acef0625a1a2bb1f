// Unit tests of the EEPA normal contact law (src-liggghts-eepa/physics/eepa_law.h).
// Expected values are written from the equations of docs/model.md, never read back from the
// code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "eepa_law.h"

namespace {

using tsg::eepa::Branch;
using tsg::eepa::evaluate;
using tsg::eepa::History;
using tsg::eepa::Parameters;
using tsg::eepa::State;

constexpr double kPi = 3.14159265358979323846;

// Seed paper: particles of radius 200 um, G = 1.7e7 Pa, nu = 0.25, density 1263 kg/m^3 (Table 3);
// cohesive case lambda_p = 0.8, n = 1.5, X = 20, f0 = -1 mN, surface energy 15 J/m^2 (Table 4).
constexpr double kRadius = 2e-4;
constexpr double kShearModulus = 1.7e7;
constexpr double kPoisson = 0.25;
constexpr double kDensity = 1263;

double effective_modulus()
{  // 1/E* = 2 (1 - nu^2)/E, E = 2 G (1 + nu), two equal spheres
  const double young = 2 * kShearModulus * (1 + kPoisson);
  return young / (2 * (1 - kPoisson * kPoisson));
}
double effective_radius() { return kRadius / 2; }
double reduced_mass() { return 0.5 * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius * kDensity; }

Parameters seed()
{
  const double k1 = 4.0 / 3.0 * effective_modulus() * std::sqrt(effective_radius());
  return {k1, 0.8, 1.5, 20, -1e-3, 15, effective_radius()};
}
Parameters f0_only()
{
  Parameters p = seed();
  p.surface_energy = 0;
  return p;
}
Parameters no_adhesion(double plasticity_ratio, double slope_exponent)
{
  Parameters p = seed();
  p.plasticity_ratio = plasticity_ratio;
  p.slope_exponent = slope_exponent;
  p.pull_off_force = 0;
  p.surface_energy = 0;
  if (slope_exponent == 1) p.k1 = 450;  // linear spring, N/m; e depends on lambda_p and n only
  return p;
}

double k2_of(const Parameters &p) { return p.k1 / (1 - p.plasticity_ratio); }
double pw(double x, double e) { return std::pow(x, e); }

// One contact stepped through overlaps, keeping the history as LIGGGHTS would.
struct Contact {
  Parameters p;
  History history{};
  State step(double overlap)
  {
    const State s = evaluate(p, history, overlap);
    history = s.history;
    return s;
  }
};

// Hand-derived pull-off of a virgin unloading line from max_overlap (uncapped JKR branch).
struct HandPullOff {
  double plastic, f_min, delta_min, kadh;
};
HandPullOff hand_pull_off(const Parameters &p, double max_overlap)
{
  const double n = p.slope_exponent;
  HandPullOff h{};
  h.plastic = pw(p.plasticity_ratio, 1 / n) * max_overlap;
  h.f_min = 1.5 * kPi * p.surface_energy * std::sqrt(2 * effective_radius() * h.plastic);
  h.delta_min = pw(pw(h.plastic, n) - h.f_min / k2_of(p), 1 / n);
  h.kadh = h.f_min / pw(h.delta_min, p.tension_exponent);
  return h;
}

// --------------------------------------------------------------------------------------------
// Branch values over a load-unload-reload cycle
// --------------------------------------------------------------------------------------------

TEST(EepaBranches, ConstantPullOffCycleFollowsTheFormulas)
{
  const Parameters p = f0_only();
  const double n = p.slope_exponent, k1 = p.k1, k2 = k2_of(p), f0 = p.pull_off_force;
  const double lp_root = pw(p.plasticity_ratio, 1 / n);  // delta_p / delta_max on a virgin line
  const double d1 = 1e-6;
  Contact c{p};

  for (double d : {0.25 * d1, 0.5 * d1, d1}) {  // virgin loading: f0 + k1 d^n
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Loading);
    EXPECT_NEAR(s.force, f0 + k1 * pw(d, n), 1e-12 * k1 * pw(d1, n));
    EXPECT_DOUBLE_EQ(s.history.max_overlap, d);
    EXPECT_NEAR(s.history.plastic_overlap, lp_root * d, 1e-15 * d);
  }
  {  // unloading on the k2 line: f0 + k2 (d^n - lambda_p d1^n)
    const double d = 0.95 * d1;
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Unloading);
    EXPECT_NEAR(s.force, f0 + k2 * (pw(d, n) - p.plasticity_ratio * pw(d1, n)), 1e-12 * k1 * pw(d1, n));
  }
  for (double d : {0.5 * d1, 0.3 * d1}) {  // below delta_p = 0.862 d1: only f0 remains
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Adhesive);
    EXPECT_EQ(s.force, f0);
    EXPECT_NEAR(s.history.plastic_overlap, d, 1e-15 * d);  // new k2 line through (d, f0)
    EXPECT_DOUBLE_EQ(s.history.max_overlap, d1);
  }
  {  // reload on the new line from 0.3 d1; it meets k1 at 0.3 d1 / lambda_p^(1/n) = 0.348 d1
    const double d = 0.32 * d1;
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Unloading);
    EXPECT_NEAR(s.force, f0 + k2 * (pw(d, n) - pw(0.3 * d1, n)), 1e-12 * k1 * pw(d1, n));
  }
  {  // past the meeting point: k1 again, plastic overlap grows, max overlap kept
    const double d = 0.4 * d1;
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Loading);
    EXPECT_NEAR(s.force, f0 + k1 * pw(d, n), 1e-12 * k1 * pw(d1, n));
    EXPECT_NEAR(s.history.plastic_overlap, lp_root * d, 1e-15 * d);
    EXPECT_DOUBLE_EQ(s.history.max_overlap, d1);
  }
  {  // unloading from there follows the k2 line of 0.4 d1
    const double d = 0.38 * d1;
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Unloading);
    EXPECT_NEAR(s.force, f0 + k2 * (pw(d, n) - p.plasticity_ratio * pw(0.4 * d1, n)), 1e-12 * k1 * pw(d1, n));
  }
  {  // new maximum
    const double d = 1.5 * d1;
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Loading);
    EXPECT_NEAR(s.force, f0 + k1 * pw(d, n), 1e-12 * k1 * pw(d, n));
    EXPECT_DOUBLE_EQ(s.history.max_overlap, d);
  }
}

TEST(EepaBranches, SurfaceEnergyCycleFollowsTheFormulas)
{
  const Parameters p = seed();
  const double n = p.slope_exponent, X = p.tension_exponent, k1 = p.k1, k2 = k2_of(p);
  const double f0 = p.pull_off_force;
  const double d1 = 5e-6;  // large enough that 1.5 pi dgamma a < k2 delta_p^n / 2 (no cap)
  const HandPullOff h = hand_pull_off(p, d1);
  ASSERT_LT(h.f_min, 0.5 * k2 * pw(h.plastic, n));
  const double scale = k1 * pw(d1, n);

  Contact c{p};
  c.step(0.5 * d1);
  EXPECT_NEAR(c.step(d1).force, f0 + k1 * pw(d1, n), 1e-12 * scale);

  const tsg::eepa::PullOff pull = tsg::eepa::pull_off(p, d1);
  EXPECT_NEAR(pull.force, h.f_min, 1e-12 * h.f_min);
  EXPECT_NEAR(pull.overlap, h.delta_min, 1e-12 * h.delta_min);

  {  // k2 line above delta_min
    const double d = 1.05 * h.delta_min;
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Unloading);
    EXPECT_NEAR(s.force, f0 + k2 * (pw(d, n) - pw(h.plastic, n)), 1e-12 * scale);
  }
  // the adhesive branch f0 - kadh d^X, kadh = f_min / delta_min^X, evaluated un-normalised here
  double reload_from = 0;
  for (double d : {0.95 * h.delta_min, 0.9 * h.delta_min}) {
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Adhesive);
    EXPECT_NEAR(s.force, f0 - h.kadh * pw(d, X), 1e-12 * h.f_min);
    reload_from = d;
  }
  // reload: new k2 line with delta_p^n = d^n + (kadh/k2) d^X
  const double new_plastic_n = pw(reload_from, n) + h.kadh / k2 * pw(reload_from, X);
  EXPECT_NEAR(c.history.plastic_overlap, pw(new_plastic_n, 1 / n), 1e-12 * d1);
  {
    const double d = 0.92 * h.delta_min;
    const State s = c.step(d);
    EXPECT_EQ(s.branch, Branch::Unloading);
    EXPECT_NEAR(s.force, f0 + k2 * (pw(d, n) - new_plastic_n), 1e-12 * scale);
  }
  // the new line rejoins k1 where k2 (d^n - dp^n) = k1 d^n, i.e. d^n = dp^n / lambda_p
  const double join = pw(new_plastic_n / p.plasticity_ratio, 1 / n);
  ASSERT_LT(join, d1);
  const History at_reload = c.history;
  const State below = evaluate(p, at_reload, join * (1 - 1e-9));
  const State above = evaluate(p, at_reload, join * (1 + 1e-9));
  EXPECT_EQ(below.branch, Branch::Unloading);
  EXPECT_EQ(above.branch, Branch::Loading);
  EXPECT_NEAR(below.force, f0 + k1 * pw(join, n), 1e-7 * k1 * pw(join, n));
  EXPECT_NEAR(above.force, f0 + k1 * pw(join, n), 1e-7 * k1 * pw(join, n));
  EXPECT_DOUBLE_EQ(above.history.max_overlap, d1);  // the pull-off keeps its stress history
}

// --------------------------------------------------------------------------------------------
// Continuity and rejoining
// --------------------------------------------------------------------------------------------

TEST(EepaContinuity, ForceIsContinuousAlongLoadUnloadReloadPaths)
{
  const Parameters p = seed();
  const double n = p.slope_exponent, X = p.tension_exponent, k2 = k2_of(p);
  const double d1 = 5e-6;
  const double dmin = hand_pull_off(p, d1).delta_min;
  // every branch switch: loading, unloading, adhesive, reload, rejoin k1, new maximum, far out
  const std::vector<double> turns{0, d1, 0.2 * dmin, 0.8 * d1, 0.3 * dmin, 1.2 * d1, 1e-3 * dmin};
  const double h = d1 / 20000;
  const double largest = 1.2 * d1;

  Contact c{p};
  State last = c.step(h);
  std::vector<Branch> seen;
  for (std::size_t t = 1; t < turns.size(); ++t) {
    const double from = std::max(turns[t - 1], h), to = std::max(turns[t], h);
    const int steps = static_cast<int>(std::ceil(std::fabs(to - from) / h));
    for (int i = 1; i <= steps; ++i) {
      const double d = from + (to - from) * i / steps;
      const State s = c.step(d);
      // Lipschitz bound of the law over this path: k2 line slope at the largest overlap, and the
      // adhesive branch slope X f_min / delta_min at its steepest
      const HandPullOff pull = hand_pull_off(p, std::max(s.history.max_overlap, d1));
      const double lipschitz = std::max(n * k2 * pw(largest, n - 1), X * pull.f_min / pull.delta_min);
      const double step = std::fabs(to - from) / steps;
      ASSERT_LE(std::fabs(s.force - last.force), 1.01 * lipschitz * step)
          << "jump at d = " << d << " between branches " << static_cast<int>(last.branch) << " and "
          << static_cast<int>(s.branch);
      if (seen.empty() || seen.back() != s.branch) seen.push_back(s.branch);
      last = s;
    }
  }
  const std::vector<Branch> expected{Branch::Loading, Branch::Unloading, Branch::Adhesive, Branch::Unloading,
                                     Branch::Loading, Branch::Unloading, Branch::Adhesive, Branch::Unloading,
                                     Branch::Loading, Branch::Unloading, Branch::Adhesive};
  EXPECT_EQ(seen, expected);
}

TEST(EepaContinuity, OnlyTheConstantPullOffJumpsAtSeparation)
{
  const Parameters p = seed();
  Contact c{p};
  c.step(5e-6);
  const State touching = c.step(1e-15);
  EXPECT_NEAR(touching.force, p.pull_off_force, 1e-12 * std::fabs(p.pull_off_force));
  const State apart = c.step(0);
  EXPECT_EQ(apart.branch, Branch::Separated);
  EXPECT_EQ(apart.force, 0);
}

TEST(EepaRejoin, ReloadRejoinsK1ExactlyAtMaxOverlap)
{
  for (double lambda : {0.2, 0.5, 0.8, 0.99}) {
    Parameters p = f0_only();
    p.plasticity_ratio = lambda;
    const double n = p.slope_exponent, d1 = 2e-6;
    const double on_k1 = p.pull_off_force + p.k1 * pw(d1, n);
    Contact c{p};
    c.step(d1);
    // the k2 line through (d1, k1 d1^n) meets k1 at d1 itself
    EXPECT_NEAR(pw(pw(c.history.plastic_overlap, n) / lambda, 1 / n), d1, 1e-14 * d1);
    c.step(0.5 * (d1 + c.history.plastic_overlap));  // unload, stay above delta_p
    const State below = evaluate(p, c.history, d1 * (1 - 1e-12));
    const State at = evaluate(p, c.history, d1);
    const State above = evaluate(p, c.history, d1 * (1 + 1e-12));
    EXPECT_EQ(below.branch, Branch::Unloading) << lambda;
    EXPECT_EQ(above.branch, Branch::Loading) << lambda;
    const double line = p.pull_off_force + k2_of(p) * (pw(d1 * (1 - 1e-12), n) - lambda * pw(d1, n));
    EXPECT_NEAR(below.force, line, 1e-12 * k2_of(p) * pw(d1, n)) << lambda;
    EXPECT_NEAR(below.force, on_k1, 2 * n * k2_of(p) * pw(d1, n) * 1e-12) << lambda;  // slope x step
    EXPECT_NEAR(at.force, on_k1, 1e-12 * p.k1 * pw(d1, n)) << lambda;
    EXPECT_NEAR(above.force, on_k1, 1e-10 * p.k1 * pw(d1, n)) << lambda;
    EXPECT_DOUBLE_EQ(below.history.max_overlap, d1);
    EXPECT_DOUBLE_EQ(above.history.max_overlap, d1 * (1 + 1e-12));
  }
}

TEST(EepaRejoin, ReloadAfterAdhesiveExcursionRejoinsWhereItsLineMeetsK1)
{
  const Parameters p = seed();
  const double n = p.slope_exponent, X = p.tension_exponent, k2 = k2_of(p), d1 = 5e-6;
  const HandPullOff h = hand_pull_off(p, d1);
  Contact c{p};
  c.step(d1);
  double turn = d1;  // unload deep into the adhesive branch, to about delta_min / 2
  for (int i = 1; i <= 1000 && turn > 0.5 * h.delta_min; ++i) c.step(turn = d1 * (1 - i / 1000.0));
  ASSERT_EQ(evaluate(p, c.history, 0.99 * turn).branch, Branch::Adhesive);
  // the reload line passes through (turn, f0 - kadh turn^X) and meets k1 at dp^n / lambda_p
  const double plastic_n = pw(turn, n) + h.kadh / k2 * pw(turn, X);
  EXPECT_NEAR(c.history.plastic_overlap, pw(plastic_n, 1 / n), 1e-12 * d1);
  const double join = pw(plastic_n / p.plasticity_ratio, 1 / n);
  ASSERT_LT(join, d1);
  for (int i = 1; i < 1000; ++i) ASSERT_EQ(c.step(turn + (join - turn) * i / 1000.0).branch, Branch::Unloading) << i;
  EXPECT_NEAR(c.step(join).force, p.pull_off_force + p.k1 * pw(join, n), 1e-10 * p.k1 * pw(join, n));
  const State past = c.step(join * (1 + 1e-9));
  EXPECT_EQ(past.branch, Branch::Loading);
  EXPECT_DOUBLE_EQ(past.history.max_overlap, d1);
}

// --------------------------------------------------------------------------------------------
// Pull-off
// --------------------------------------------------------------------------------------------

TEST(EepaPullOff, ConstantPullOffOnlyBelowPlasticOverlap)
{
  const Parameters p = f0_only();
  const double d1 = 3e-6;
  const double plastic = pw(p.plasticity_ratio, 1 / p.slope_exponent) * d1;
  Contact c{p};
  c.step(d1);
  const History after_loading = c.history;
  for (int i = 999; i >= 1; --i) {  // every overlap below delta_p, sequentially and from the peak
    const double d = plastic * i / 1000.0;
    EXPECT_EQ(c.step(d).force, p.pull_off_force) << d;
    EXPECT_EQ(evaluate(p, after_loading, d).force, p.pull_off_force) << d;
  }
}

TEST(EepaPullOff, MostNegativeForceIsF0MinusFminAtDeltaMin)
{
  const Parameters p = seed();
  const double d1 = 5e-6;
  const HandPullOff h = hand_pull_off(p, d1);
  Contact c{p};
  c.step(d1);
  const History after_loading = c.history;
  double lowest = std::numeric_limits<double>::infinity();
  for (int i = 10000; i >= 1; --i) lowest = std::min(lowest, c.step(d1 * i / 10000.0).force);
  const double expected = p.pull_off_force - h.f_min;
  EXPECT_GE(lowest, expected - 1e-12 * h.f_min);
  EXPECT_LE(lowest, expected + 5e-3 * h.f_min);  // the grid passes within d1/2e4 of delta_min
  EXPECT_NEAR(evaluate(p, after_loading, h.delta_min).force, expected, 1e-12 * h.f_min);
}

TEST(EepaPullOff, CapWhenJkrPullOffExceedsHalfTheLineTension)
{
  Parameters p = seed();
  p.surface_energy = 1e6;
  const double n = p.slope_exponent, k2 = k2_of(p), d1 = 5e-6;
  const double plastic = pw(p.plasticity_ratio, 1 / n) * d1;
  const double f_min = 0.5 * k2 * pw(plastic, n);     // capped: k2 delta_p^n / 2
  const double delta_min = pw(0.5, 1 / n) * plastic;  // k2 (dmin^n - dp^n) = -f_min
  const tsg::eepa::PullOff pull = tsg::eepa::pull_off(p, d1);
  EXPECT_NEAR(pull.force, f_min, 1e-12 * f_min);
  EXPECT_NEAR(pull.overlap, delta_min, 1e-12 * delta_min);
  Contact c{p};
  c.step(d1);
  double lowest = std::numeric_limits<double>::infinity();
  for (int i = 10000; i >= 1; --i) lowest = std::min(lowest, c.step(d1 * i / 10000.0).force);
  EXPECT_GE(lowest, p.pull_off_force - f_min * (1 + 1e-12));
  EXPECT_LE(lowest, p.pull_off_force - f_min * (1 - 5e-3));
}

TEST(EepaPullOff, NoSurfaceEnergyMeansNoAdhesiveBranchBeyondF0)
{
  const Parameters p = f0_only();
  const tsg::eepa::PullOff pull = tsg::eepa::pull_off(p, 2e-6);
  EXPECT_EQ(pull.force, 0);
  EXPECT_NEAR(pull.overlap, pw(p.plasticity_ratio, 1 / p.slope_exponent) * 2e-6, 1e-20);
}

// --------------------------------------------------------------------------------------------
// Stiffness and Coulomb load
// --------------------------------------------------------------------------------------------

TEST(EepaStiffness, TangentOfTheActiveBranch)
{
  const Parameters p = seed();
  const double n = p.slope_exponent, k2 = k2_of(p), d1 = 5e-6;
  const HandPullOff h = hand_pull_off(p, d1);
  Contact c{p};
  const State loading = c.step(d1);
  // Hertz: n k1 d^(n-1) = 2 E* sqrt(R* d)
  EXPECT_NEAR(loading.stiffness, 2 * effective_modulus() * std::sqrt(effective_radius() * d1),
              1e-12 * loading.stiffness);
  const State unloading = c.step(0.9 * d1);
  EXPECT_NEAR(unloading.stiffness, n * k2 * pw(0.9 * d1, n - 1), 1e-12 * unloading.stiffness);
  const State adhesive = c.step(0.5 * h.delta_min);
  ASSERT_EQ(adhesive.branch, Branch::Adhesive);
  EXPECT_NEAR(adhesive.stiffness, n * k2 * pw(0.5 * h.delta_min, n - 1), 1e-12 * adhesive.stiffness);
}

TEST(EepaCoulombLoad, ThakurFormWithAdhesionCappedAtFmin)
{
  const Parameters p = seed();
  const double n = p.slope_exponent, X = p.tension_exponent, k1 = p.k1, k2 = k2_of(p), d1 = 5e-6;
  const HandPullOff h = hand_pull_off(p, d1);
  Contact c{p};
  // |f_hys + kadh d^X - f0| with kadh d^X capped at f_min for d >= delta_min
  EXPECT_NEAR(c.step(d1).coulomb_load, k1 * pw(d1, n) + h.f_min, 1e-12 * k1 * pw(d1, n));
  const double d_line = 0.98 * h.delta_min / 0.95;  // just above delta_min on the k2 line
  EXPECT_NEAR(c.step(d_line).coulomb_load, k2 * (pw(d_line, n) - pw(h.plastic, n)) + h.f_min, 1e-9 * h.f_min);
  const double d_adh = 0.95 * h.delta_min;
  const State adhesive = c.step(d_adh);
  ASSERT_EQ(adhesive.branch, Branch::Adhesive);
  EXPECT_EQ(adhesive.coulomb_load, 0);
  const double d_re = 0.96 * h.delta_min;  // reloaded on the new line below delta_min
  const double plastic_n = pw(d_adh, n) + h.kadh / k2 * pw(d_adh, X);
  EXPECT_NEAR(c.step(d_re).coulomb_load, k2 * (pw(d_re, n) - plastic_n) + h.kadh * pw(d_re, X), 1e-9 * h.f_min);
  // without surface energy the load is the elastic part alone
  Contact plain{f0_only()};
  EXPECT_NEAR(plain.step(d1).coulomb_load, k1 * pw(d1, n), 1e-12 * k1 * pw(d1, n));
}

// --------------------------------------------------------------------------------------------
// Restitution
// --------------------------------------------------------------------------------------------

// e^2 = work returned on k2 / work done on k1 =
//       [1 - (n+1) lambda_p + n lambda_p^(1+1/n)] / (1 - lambda_p)    (docs/model.md)
TEST(EepaRestitution, ClosedFormValues)
{
  for (double lambda : {0.0, 0.1, 0.5, 0.8, 0.99})
    EXPECT_NEAR(tsg::eepa::undamped_restitution(lambda, 1.0), std::sqrt(1 - lambda), 1e-14);
  EXPECT_NEAR(tsg::eepa::undamped_restitution(0.5, 1.5), 0.66704, 5e-6);
  EXPECT_NEAR(tsg::eepa::undamped_restitution(0.8, 1.5), 0.41309, 5e-6);
  EXPECT_EQ(tsg::eepa::undamped_restitution(0.0, 1.5), 1.0);
  EXPECT_THROW(tsg::eepa::undamped_restitution(1.0, 1.5), std::invalid_argument);
  EXPECT_THROW(tsg::eepa::undamped_restitution(0.5, 0.5), std::invalid_argument);
}

// Head-on impact at approach speed v0 integrated with velocity Verlet on the overlap (the scheme
// LIGGGHTS uses), 20000 steps per delta_max / v0; returns rebound speed / v0.
double integrated_restitution(const Parameters &p, double speed, double beta)
{
  const double m = reduced_mass(), n = p.slope_exponent;
  const double max_overlap = pw((n + 1) * m * speed * speed / (2 * p.k1), 1 / (n + 1));
  const double dt = max_overlap / speed / 20000;
  History history{};
  double overlap = 0, velocity = speed, acceleration = 0;
  for (int i = 0; i < 10000000; ++i) {
    const double half = velocity + 0.5 * dt * acceleration;
    overlap += dt * half;
    if (overlap <= 0) return -half / speed;  // apart: no force from here on
    const State s = evaluate(p, history, overlap);
    history = s.history;
    acceleration = -(s.force + tsg::eepa::damping_force(beta, s.stiffness, m, half)) / m;
    velocity = half + 0.5 * dt * acceleration;
  }
  ADD_FAILURE() << "impact did not end";
  return std::numeric_limits<double>::quiet_NaN();
}

TEST(EepaRestitution, IntegratedImpactReproducesClosedForm)
{
  for (double n : {1.0, 1.5}) {
    for (double lambda : {0.2, 0.5, 0.8, 0.99}) {
      const double closed = tsg::eepa::undamped_restitution(lambda, n);
      for (double speed : {0.1, 1.0}) {
        const double measured = integrated_restitution(no_adhesion(lambda, n), speed, 0);
        std::cout << std::setprecision(7) << "[ measured ] n = " << n << "  lambda_p = " << lambda << "  v = " << speed
                  << " m/s  e = " << measured << "  closed form " << closed << "  relative deviation "
                  << std::setprecision(2) << measured / closed - 1 << '\n';
        EXPECT_NEAR(measured, closed, 1e-6 * closed) << "n " << n << " lambda " << lambda;
      }
    }
  }
}

TEST(EepaDamping, HertzMindlinDashpotRecoversInputRestitution)
{
  for (double lambda : {0.0, 1e-9}) {
    for (double e : {0.1, 0.5, 0.9}) {
      const double beta = tsg::eepa::damping_ratio_from_restitution(e);
      const double slow = integrated_restitution(no_adhesion(lambda, 1.5), 0.1, beta);
      const double fast = integrated_restitution(no_adhesion(lambda, 1.5), 1.0, beta);
      std::cout << std::setprecision(7) << "[ measured ] damped  lambda_p = " << lambda << "  input e = " << e
                << "  e(0.1 m/s) = " << slow << "  e(1 m/s) = " << fast << '\n';
      EXPECT_NEAR(slow, e, 5e-5);  // the dashpot formula itself is good to ~4e-6
      EXPECT_NEAR(fast, e, 5e-5);
      EXPECT_NEAR(slow, fast, 1e-6);  // speed-independent
    }
  }
}

TEST(EepaDamping, RatioAndForceFormulas)
{
  using tsg::eepa::damping_force;
  using tsg::eepa::damping_ratio_from_restitution;
  EXPECT_EQ(damping_ratio_from_restitution(1.0), 0.0);
  const double l = std::log(0.5);
  EXPECT_NEAR(damping_ratio_from_restitution(0.5), l / std::sqrt(l * l + kPi * kPi), 1e-15);
  EXPECT_NEAR(damping_ratio_from_restitution(0.5), -0.2154538, 1e-7);
  // approaching (v > 0) with beta < 0: repulsive, magnitude 2 sqrt(5/6) |beta| sqrt(S m) v
  const double f = damping_force(-0.2, 400.0, 1e-6, 0.3);
  EXPECT_NEAR(f, 2 * std::sqrt(5.0 / 6.0) * 0.2 * std::sqrt(400.0 * 1e-6) * 0.3, 1e-15);
  EXPECT_GT(f, 0);
  EXPECT_LT(damping_force(-0.2, 400.0, 1e-6, -0.3), 0);
  for (double bad : {0.0, -0.1, 1.5, std::nan("")})
    EXPECT_THROW(damping_ratio_from_restitution(bad), std::invalid_argument) << bad;
  try {
    damping_ratio_from_restitution(1.5);
  } catch (const std::invalid_argument &error) {
    EXPECT_STREQ(error.what(), "restitution = 1.5 is outside the allowed range (0, 1]");
  }
}

// --------------------------------------------------------------------------------------------
// Separation, extremes, validation
// --------------------------------------------------------------------------------------------

TEST(EepaSeparation, NonPositiveOverlapIsSeparatedAndResetsHistory)
{
  const Parameters p = seed();
  const History loaded{3e-6, 2e-6};
  for (double d : {0.0, -1e-9, std::nan("")}) {
    const State s = evaluate(p, loaded, d);
    EXPECT_EQ(s.branch, Branch::Separated);
    EXPECT_EQ(s.force, 0);
    EXPECT_EQ(s.stiffness, 0);
    EXPECT_EQ(s.coulomb_load, 0);
    EXPECT_EQ(s.history.max_overlap, 0);
    EXPECT_EQ(s.history.plastic_overlap, 0);
  }
}

TEST(EepaExtremes, OutputsFiniteAndBoundedForExtremeInputs)
{
  const double r = effective_radius();
  // overlaps from 1e-15 m to R*/2 and back, twice, on a log grid
  std::vector<double> path;
  auto sweep = [&path](double from, double to, int steps) {
    for (int i = 0; i <= steps; ++i) path.push_back(from * std::pow(to / from, double(i) / steps));
  };
  sweep(1e-15, 0.5 * r, 400);
  sweep(0.5 * r, 1e-15, 400);
  sweep(1e-15, 0.25 * r, 300);
  sweep(0.25 * r, 1e-12, 300);
  sweep(1e-12, 0.5 * r, 100);
  int checked = 0;
  for (double lambda : {0.0, 1e-12, 0.5, 0.99})
    for (double n : {1.0, 1.5})
      for (double X : {1.0, 1.5, 20.0})
        for (double gamma : {0.0, 15.0, 1e6})
          for (double f0 : {0.0, -1e-3}) {
            Parameters p = seed();
            p.plasticity_ratio = lambda;
            p.slope_exponent = n;
            p.tension_exponent = X;
            p.surface_energy = gamma;
            p.pull_off_force = f0;
            ASSERT_NO_THROW(tsg::eepa::validate(p));
            const double k2 = k2_of(p);
            Contact c{p};
            double reached = 0;
            for (double d : path) {
              const State s = c.step(d);
              reached = std::max(reached, d);
              ASSERT_TRUE(std::isfinite(s.force) && std::isfinite(s.stiffness) && std::isfinite(s.coulomb_load) &&
                          std::isfinite(s.history.max_overlap) && std::isfinite(s.history.plastic_overlap))
                  << "lambda " << lambda << " n " << n << " X " << X << " gamma " << gamma << " d " << d;
              ASSERT_GE(s.stiffness, 0);
              ASSERT_GE(s.coulomb_load, 0);
              // bounded: f0 - k2 delta_p^n / 2 <= f <= f0 + k1 delta_max^n
              const double top = p.k1 * pw(reached, n);
              const double cap = 0.5 * k2 * lambda * pw(reached, n);
              const double rounding = 1e-12 * (top + std::fabs(f0));  // f0 + x - f0 != x
              ASSERT_LE(s.force - f0, top + rounding) << d;
              ASSERT_GE(s.force - f0, -cap - rounding) << d;
              ++checked;
            }
          }
  EXPECT_GT(checked, 100000);
}

TEST(EepaValidate, AcceptsSeedParameters)
{
  EXPECT_NO_THROW(tsg::eepa::validate(seed()));
  Parameters p = seed();
  p.plasticity_ratio = 0;
  p.pull_off_force = 0;
  p.surface_energy = 0;
  p.slope_exponent = 1;
  p.tension_exponent = 1;
  EXPECT_NO_THROW(tsg::eepa::validate(p));  // closed ends of every range
}

TEST(EepaValidate, RejectsOutOfRangeWithNameValueAndRange)
{
  struct Case {
    double Parameters::*field;
    double value;
    const char *message;
  };
  const std::vector<Case> cases{
      {&Parameters::plasticity_ratio, 1.2, "plasticity_ratio = 1.2 is outside the allowed range [0, 1)"},
      {&Parameters::plasticity_ratio, 1.0, "plasticity_ratio = 1 is outside the allowed range [0, 1)"},
      {&Parameters::plasticity_ratio, -0.1, "plasticity_ratio = -0.1 is outside the allowed range [0, 1)"},
      {&Parameters::slope_exponent, 0.5, "slope_exponent = 0.5 is outside the allowed range [1, inf)"},
      {&Parameters::tension_exponent, 0.9, "tension_exponent = 0.9 is outside the allowed range [1, inf)"},
      {&Parameters::surface_energy, -2.0, "surface_energy = -2 is outside the allowed range [0, inf)"},
      {&Parameters::pull_off_force, 0.001, "pull_off_force = 0.001 is outside the allowed range (-inf, 0]"},
      {&Parameters::effective_radius, 0.0, "effective_radius = 0 is outside the allowed range (0, inf)"},
      {&Parameters::effective_radius, -1e-4, "effective_radius = -1e-4 is outside the allowed range (0, inf)"},
      {&Parameters::k1, 0.0, "k1 = 0 is outside the allowed range (0, inf)"},
      {&Parameters::k1, -3.5e5, "k1 = -350000 is outside the allowed range (0, inf)"},
      {&Parameters::k1, std::nan(""), "k1 = nan is outside the allowed range (0, inf)"},
      {&Parameters::surface_energy, std::numeric_limits<double>::infinity(),
       "surface_energy = inf is outside the allowed range [0, inf)"},
  };
  for (const Case &c : cases) {
    Parameters p = seed();
    p.*c.field = c.value;
    try {
      tsg::eepa::validate(p);
      ADD_FAILURE() << "accepted: " << c.message;
    } catch (const std::invalid_argument &error) {
      EXPECT_STREQ(error.what(), c.message);
    }
  }
}

}  // namespace
