// Unit tests of the cut placement along x (physics/balance_cuts.h): cuts against closed-form
// inverse cumulative weights, slab counts of sampled particles counted independently, the one-rank
// move limit and its convergence.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "balance_cuts.h"

namespace bal = tsg::balance;

namespace {
// Histogram of a density f over [lo, hi] in nbins bins, each bin's weight its exact integral F.
template <class Primitive>
std::vector<double> histogram_of(Primitive F, double lo, double hi, std::size_t nbins)
{
  std::vector<double> w(nbins);
  const double h = (hi - lo) / static_cast<double>(nbins);
  for (std::size_t b = 0; b < nbins; ++b)
    w[b] = F(lo + h * static_cast<double>(b + 1)) - F(lo + h * static_cast<double>(b));
  return w;
}
}  // namespace

TEST(BalanceCuts, UniformWeightGivesEqualSlabs)
{
  const std::vector<double> w(40, 3.0);
  const auto cut = bal::equal_weight_cuts(w, -1.0, 3.0, 4, 0.0);
  ASSERT_EQ(cut.size(), 5u);
  for (int k = 0; k <= 4; ++k) EXPECT_NEAR(cut[static_cast<std::size_t>(k)], -1.0 + k, 1e-12);
}

TEST(BalanceCuts, NoWeightGivesEqualSlabs)
{
  const std::vector<double> w(7, 0.0);
  const auto cut = bal::equal_weight_cuts(w, 0.0, 0.3, 3, 0.0);
  EXPECT_NEAR(cut[1], 0.1, 1e-15);
  EXPECT_NEAR(cut[2], 0.2, 1e-15);
}

// density 2x on [0, 1]: W(x) = x^2, cut k = sqrt(k/P). Bins hold the exact integral and the
// interpolation is linear inside a bin, so the cut is off by less than one bin width.
TEST(BalanceCuts, LinearDensityMatchesInverseCdf)
{
  const std::size_t nbins = 1000;
  const auto w = histogram_of([](double x) { return x * x; }, 0.0, 1.0, nbins);
  const int parts = 8;
  const auto cut = bal::equal_weight_cuts(w, 0.0, 1.0, parts, 0.0);
  for (int k = 1; k < parts; ++k)
    EXPECT_NEAR(cut[static_cast<std::size_t>(k)], std::sqrt(static_cast<double>(k) / parts), 1.0 / nbins);
}

// The full granulator fed at element 7: particles only downstream of the feed. Uniform fill on
// [0.6, 1.0] of [0, 1]: cuts at 0.6 + 0.4 k / P (exactly, the fill edges being bin edges).
TEST(BalanceCuts, HalfEmptyDomainCutsTheFilledPart)
{
  std::vector<double> w(50, 0.0);
  for (std::size_t b = 30; b < 50; ++b) w[b] = 1.0;
  const auto cut = bal::equal_weight_cuts(w, 0.0, 1.0, 4, 0.0);
  EXPECT_DOUBLE_EQ(cut[0], 0.0);
  EXPECT_NEAR(cut[1], 0.7, 1e-12);
  EXPECT_NEAR(cut[2], 0.8, 1e-12);
  EXPECT_NEAR(cut[3], 0.9, 1e-12);
  EXPECT_DOUBLE_EQ(cut[4], 1.0);
}

// Sampled particles, binned with bin_of, counted per slab by direct comparison with the cuts: each
// slab holds N/P give or take the content of the bin its cuts fall in.
TEST(BalanceCuts, SampledParticlesAreSharedEqually)
{
  std::mt19937_64 rng(12345);
  std::gamma_distribution<double> gamma(3.0, 0.05);  // skewed, like a hold-up profile
  const double lo = 0.0, hi = 1.0;
  const std::size_t nbins = 2000;
  const int parts = 6;
  std::vector<double> x(60000);
  for (double &xi : x) xi = std::min(gamma(rng), 0.999999);
  std::vector<double> w(nbins, 0.0);
  for (double xi : x) w[bal::bin_of(xi, lo, hi, nbins)] += 1.0;
  const auto cut = bal::equal_weight_cuts(w, lo, hi, parts, 0.0);
  std::vector<double> count(parts, 0.0);
  for (double xi : x)
    for (int k = 0; k < parts; ++k)
      if (xi >= cut[static_cast<std::size_t>(k)] && xi < cut[static_cast<std::size_t>(k) + 1]) count[k] += 1.0;
  double largest_bin = 0;
  for (double b : w) largest_bin = std::max(largest_bin, b);
  const double share = static_cast<double>(x.size()) / parts;
  for (double c : count) EXPECT_LE(std::abs(c - share), 2 * largest_bin + 1);
  EXPECT_LT(bal::imbalance(count), 1.0 + 2 * (2 * largest_bin + 1) / share);
}

TEST(BalanceCuts, MinimumWidthIsKeptWhenAllWorkIsInOneBin)
{
  std::vector<double> w(100, 0.0);
  w[50] = 10.0;
  const double min_width = 0.03;
  const auto cut = bal::equal_weight_cuts(w, 0.0, 1.0, 5, min_width);
  for (std::size_t k = 0; k + 1 < cut.size(); ++k) EXPECT_GE(cut[k + 1] - cut[k], min_width - 1e-15);
  // the interior cuts crowd in and around bin 50 = [0.50, 0.51), as close as min_width lets them
  EXPECT_GT(cut[1], 0.45);
  EXPECT_LT(cut[4], 0.6);
  // all work at the wall: the slabs pile up against it
  std::vector<double> wall(100, 0.0);
  wall[99] = 1.0;
  const auto end = bal::equal_weight_cuts(wall, 0.0, 1.0, 5, min_width);
  EXPECT_NEAR(end[4], 1.0 - min_width, 1e-12);
  EXPECT_NEAR(end[1], 1.0 - 4 * min_width, 1e-12);
}

TEST(BalanceCuts, RejectsWhatCannotBeCut)
{
  const std::vector<double> w(10, 1.0);
  EXPECT_THROW(bal::equal_weight_cuts(w, 0.0, 1.0, 0, 0.0), std::invalid_argument);
  EXPECT_THROW(bal::equal_weight_cuts(w, 1.0, 1.0, 2, 0.0), std::invalid_argument);
  EXPECT_THROW(bal::equal_weight_cuts(w, 0.0, 1.0, 4, 0.26), std::invalid_argument);
  EXPECT_THROW(bal::equal_weight_cuts({1.0, -1.0}, 0.0, 1.0, 2, 0.0), std::invalid_argument);
  EXPECT_THROW(bal::equal_weight_cuts({}, 0.0, 1.0, 2, 0.0), std::invalid_argument);
}

TEST(BalanceCuts, BinOfHandlesEdgesAndStrays)
{
  EXPECT_EQ(bal::bin_of(0.0, 0.0, 1.0, 10), 0u);
  EXPECT_EQ(bal::bin_of(0.15, 0.0, 1.0, 10), 1u);
  EXPECT_EQ(bal::bin_of(-0.2, 0.0, 1.0, 10), 0u);
  EXPECT_EQ(bal::bin_of(1.0, 0.0, 1.0, 10), 9u);
  EXPECT_EQ(bal::bin_of(7.0, 0.0, 1.0, 10), 9u);
  EXPECT_EQ(bal::bin_of(std::nan(""), 0.0, 1.0, 10), 0u);
}

// Random old and target cut sets: the blended cuts stay inside the old neighbours' cuts less the
// margin, and alpha is the largest such fraction (1, or one cut exactly on its limit).
TEST(BalanceCuts, StepKeepsEveryCutBetweenItsOldNeighbours)
{
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int parts = 7;
  const double margin = 0.01, min_width = 0.02;
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> wa(100), wb(100);
    for (auto &v : wa) v = std::pow(u(rng), 4);
    for (auto &v : wb) v = std::pow(u(rng), 4);
    const auto old_cut = bal::equal_weight_cuts(wa, 0.0, 1.0, parts, min_width);
    const auto target = bal::equal_weight_cuts(wb, 0.0, 1.0, parts, min_width);
    const double alpha = bal::step_fraction(old_cut, target, margin);
    ASSERT_GE(alpha, 0.0);
    ASSERT_LE(alpha, 1.0);
    const auto cut = bal::blend(old_cut, target, alpha);
    bool tight = false;
    for (std::size_t k = 1; k + 1 < cut.size(); ++k) {
      EXPECT_GE(cut[k], old_cut[k - 1] + margin - 1e-12);
      EXPECT_LE(cut[k], old_cut[k + 1] - margin + 1e-12);
      EXPECT_GE(cut[k] - cut[k - 1], min_width - 1e-12);
      tight = tight || std::abs(cut[k] - (old_cut[k - 1] + margin)) < 1e-12 ||
              std::abs(cut[k] - (old_cut[k + 1] - margin)) < 1e-12;
    }
    EXPECT_TRUE(alpha == 1.0 || tight) << "alpha " << alpha << " is not the largest allowed";
  }
}

// From equal slabs to a fill crowded at the far end, repeated limited steps reach the target (the
// room each step gives is at least the margin-reduced old slab width, which never shrinks to 0).
TEST(BalanceCuts, RepeatedStepsReachTheTarget)
{
  std::vector<double> w(400, 0.0);
  for (std::size_t b = 380; b < 400; ++b) w[b] = 1.0;  // all in the last 5 %
  const int parts = 8;
  const double min_width = 0.004, margin = 0.002;
  const auto target = bal::equal_weight_cuts(w, 0.0, 1.0, parts, min_width);
  std::vector<double> cut = bal::equal_weight_cuts(std::vector<double>(400, 1.0), 0.0, 1.0, parts, min_width);
  int steps = 0;
  while (steps < 100) {
    const double alpha = bal::step_fraction(cut, target, margin);
    cut = bal::blend(cut, target, alpha);
    ++steps;
    if (alpha == 1.0) break;
  }
  EXPECT_LT(steps, 100);
  for (std::size_t k = 0; k < cut.size(); ++k) EXPECT_NEAR(cut[k], target[k], 1e-12);
}

TEST(BalanceCuts, ImbalanceIsLargestOverMean)
{
  EXPECT_DOUBLE_EQ(bal::imbalance({1, 1, 1, 1}), 1.0);
  EXPECT_DOUBLE_EQ(bal::imbalance({0, 0, 0, 8}), 4.0);
  EXPECT_DOUBLE_EQ(bal::imbalance({1, 3}), 1.5);
  EXPECT_DOUBLE_EQ(bal::imbalance({0, 0}), 1.0);
}
