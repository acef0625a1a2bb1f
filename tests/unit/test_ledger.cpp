// Unit tests of the residence ledger (src-liggghts-eepa/physics/ledger.h): deleted and lost
// particles are found from the bookkeeping alone; migrated ones are neither.
#include <gtest/gtest.h>

#include <algorithm>
#include <unordered_set>
#include <vector>

#include "ledger.h"

namespace {

using tsg::residence::Ledger;

const double kState[3] = {7.0, 1.5, 2.5};

Ledger holding(std::vector<long long> ids)
{
  Ledger ledger;
  for (long long id : ids) ledger.remember(id, kState, 3);
  return ledger;
}

TEST(Ledger, ADeletedParticleIsTakenWithItsLastState)
{
  Ledger ledger = holding({3, 1, 2});
  double newer[3] = {7.0, 4.0, 5.0};
  ledger.remember(2, newer, 3);  // refreshed after a zone-edge crossing
  EXPECT_EQ(ledger.resident(), 3);
  const auto gone = ledger.take_deleted({1});  // 2 and 3 vanished without a pack
  ASSERT_EQ(gone.size(), 2u);
  EXPECT_EQ(gone[0].first, 2);  // sorted by id
  EXPECT_EQ(gone[0].second, std::vector<double>(newer, newer + 3));
  EXPECT_EQ(gone[1].first, 3);
  EXPECT_EQ(ledger.resident(), 1);
  EXPECT_TRUE(ledger.take_deleted({1}).empty());
}

TEST(Ledger, AMigratedParticleIsNeitherDeletedNorLost)
{
  Ledger sender = holding({5, 6});
  Ledger receiver;
  sender.packed(5);
  receiver.arrived();
  receiver.remember(5, kState, 3);
  EXPECT_EQ(sender.resident(), 1);
  EXPECT_TRUE(sender.take_deleted({6}).empty());                                  // 5 is in transit, not deleted
  EXPECT_EQ(sender.packs_minus_arrivals() + receiver.packs_minus_arrivals(), 0);  // nothing lost
  sender.end_exchange();
  receiver.end_exchange();
  EXPECT_EQ(sender.size(), 1u);
  EXPECT_TRUE(receiver.holds(5));
}

TEST(Ledger, ALostParticleIsClaimedByTheRankThatPackedIt)
{
  // rank 0 packs 8 (arrives on rank 1) and 9 (arrives nowhere: it left the box)
  Ledger rank0 = holding({8, 9});
  Ledger rank1;
  rank0.packed(8);
  rank0.packed(9);
  rank1.arrived();
  rank1.remember(8, kState, 3);
  EXPECT_EQ(rank0.packs_minus_arrivals() + rank1.packs_minus_arrivals(), 1);
  auto ids = rank0.transit_ids();
  std::sort(ids.begin(), ids.end());
  ASSERT_EQ(ids, (std::vector<long long>{8, 9}));
  const int nobody = 2;
  // the lowest claim over the ranks decides: -1 owned somewhere, else the rank that records it
  EXPECT_EQ(std::min(rank0.claim(8, 0, nobody), rank1.claim(8, 1, nobody)), -1);
  EXPECT_EQ(std::min(rank0.claim(9, 0, nobody), rank1.claim(9, 1, nobody)), 0);
  ASSERT_NE(rank0.state(9), nullptr);
  EXPECT_EQ((*rank0.state(9))[0], 7.0);
  rank0.end_exchange();
  EXPECT_EQ(rank0.size(), 0u);
  EXPECT_EQ(rank0.packs_minus_arrivals(), 0);
}

TEST(Ledger, APacketThatComesBackIsResidentAgain)
{
  Ledger ledger = holding({4});
  ledger.packed(4);
  EXPECT_FALSE(ledger.holds(4));
  ledger.arrived();
  ledger.remember(4, kState, 3);  // migrated back within the same exchange
  EXPECT_TRUE(ledger.holds(4));
  EXPECT_EQ(ledger.resident(), 1);
  EXPECT_EQ(ledger.packs_minus_arrivals(), 0);
}

TEST(Ledger, ForgettingEndsTheEntry)
{
  Ledger ledger = holding({1, 2});
  ledger.forget(1);   // its residence ended with a record (outlet, pass)
  ledger.forget(42);  // unknown ids are ignored
  EXPECT_EQ(ledger.resident(), 1);
  EXPECT_TRUE(ledger.take_deleted({2}).empty());
}

}  // namespace
