// Unit tests of physics/neighbour_trigger.h: the pairwise rule rebuilds the neighbour lists exactly
// when a pair could have come within reach unseen, and never later than that.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "neighbour_trigger.h"

using tsg::trigger::Box;
using tsg::trigger::Decision;
using tsg::trigger::Moved;

namespace {
const Box kOpen{{1.0, 1.0, 1.0}, {false, false, false}};
}

TEST(NeighbourTrigger, LargestDisplacementDecidesAtHalfAndWholeSkin)
{
  const double skin = 8e-5;
  EXPECT_EQ(tsg::trigger::from_largest(0.0, skin), Decision::keep);
  EXPECT_EQ(tsg::trigger::from_largest(0.5 * skin, skin), Decision::keep);  // the stock rule keeps it too
  EXPECT_EQ(tsg::trigger::from_largest(0.5 * skin * (1 + 1e-12), skin), Decision::check_pairs);
  EXPECT_EQ(tsg::trigger::from_largest(0.999 * skin, skin), Decision::check_pairs);
  EXPECT_EQ(tsg::trigger::from_largest(skin, skin), Decision::rebuild);
  EXPECT_DOUBLE_EQ(tsg::trigger::fast_threshold(0.7 * skin, skin), 0.3 * skin);
}

TEST(NeighbourTrigger, TwoFastParticlesAreApartExactlyWhileTheirReachesDoNotMeet)
{
  // build positions 1 mm apart along x; each moved 0.1 mm: they may have closed to 0.8 mm
  const double reach = 0.8e-3;
  const std::vector<Moved> just_apart{{{0.0, 0.0, 0.0}, 1e-4}, {{1e-3 + 1e-9, 0.0, 0.0}, 1e-4}};
  const std::vector<Moved> touching{{{0.0, 0.0, 0.0}, 1e-4}, {{1e-3 - 1e-9, 0.0, 0.0}, 1e-4}};
  EXPECT_TRUE(tsg::trigger::fast_pairs_apart(just_apart, reach, kOpen));
  EXPECT_FALSE(tsg::trigger::fast_pairs_apart(touching, reach, kOpen));
  EXPECT_TRUE(tsg::trigger::fast_pairs_apart({touching[0]}, reach, kOpen));  // one fast particle: no pair
}

TEST(NeighbourTrigger, PeriodicAxesUseTheMinimumImage)
{
  const Box periodic_x{{0.01, 1.0, 1.0}, {true, false, false}};
  const double a[3] = {0.0005, 0.2, 0.3}, b[3] = {0.0095, 0.2, 0.3};  // 1 mm apart through the boundary
  EXPECT_NEAR(tsg::trigger::separation(a, b, periodic_x), 1e-3, 1e-15);
  EXPECT_NEAR(tsg::trigger::separation(a, b, kOpen), 9e-3, 1e-15);
  const std::vector<Moved> across{{{a[0], a[1], a[2]}, 1e-4}, {{b[0], b[1], b[2]}, 1e-4}};
  EXPECT_FALSE(tsg::trigger::fast_pairs_apart(across, 0.85e-3, periodic_x));
  EXPECT_TRUE(tsg::trigger::fast_pairs_apart(across, 0.85e-3, kOpen));
}

TEST(NeighbourTrigger, ShortPeriodicBoxesFallBackToTheStockRule)
{
  const double reach = 1e-3, skin = 2e-4;
  EXPECT_TRUE(
      tsg::trigger::box_allows_pair_test({{2.0 * (reach + 2 * skin) * 1.01, 1, 1}, {true, false, false}}, reach, skin));
  EXPECT_FALSE(
      tsg::trigger::box_allows_pair_test({{2.0 * (reach + 2 * skin), 1, 1}, {true, false, false}}, reach, skin));
  EXPECT_TRUE(tsg::trigger::box_allows_pair_test({{1e-4, 1, 1}, {false, false, false}}, reach, skin));
}

// The rule against brute force: random build positions and displacements; wherever the rule keeps
// the lists, every pair that the lists left out (build separation > reach + skin) is still beyond
// reach for any motion within the displacements (separation - d_i - d_j > reach).
TEST(NeighbourTrigger, KeepsTheListsOnlyWhenNoLeftOutPairCanBeInReach)
{
  std::mt19937 random(7);
  std::uniform_real_distribution<double> where(0.0, 0.006), fraction(0.0, 1.0);
  const double reach = 0.8e-3, skin = 1.6e-4;
  const Box box{{0.006, 0.006, 0.006}, {true, true, false}};
  int kept = 0, kept_by_pairs = 0, rebuilt = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    std::vector<Moved> all(40);
    for (Moved &p : all) {
      p = {{where(random), where(random), where(random)}, 0.0};
      const double u = fraction(random);
      p.moved = skin * (u < 0.8 ? 0.1 * u : u);  // most slow, a few fast
    }
    double largest = 0.0;
    for (const Moved &p : all) largest = std::max(largest, p.moved);
    bool keep = false;
    const Decision first = tsg::trigger::from_largest(largest, skin);
    if (first == Decision::keep) {
      keep = true;
    } else if (first == Decision::check_pairs) {
      std::vector<Moved> fast;
      for (const Moved &p : all)
        if (p.moved > tsg::trigger::fast_threshold(largest, skin)) fast.push_back(p);
      keep = tsg::trigger::fast_pairs_apart(fast, reach, box);
      if (keep && fast.size() > 1) ++kept_by_pairs;
    }
    (keep ? kept : rebuilt)++;
    if (!keep) continue;
    for (std::size_t i = 0; i < all.size(); ++i)
      for (std::size_t j = i + 1; j < all.size(); ++j) {
        const double at_build = tsg::trigger::separation(all[i].x, all[j].x, box);
        if (at_build <= reach + skin) continue;  // in the lists
        EXPECT_GT(at_build - all[i].moved - all[j].moved, reach) << "trial " << trial << " pair " << i << "," << j;
      }
  }
  EXPECT_GT(kept_by_pairs, 20);  // the test exercises every outcome
  EXPECT_GT(kept, kept_by_pairs);
  EXPECT_GT(rebuilt, 100);
}
