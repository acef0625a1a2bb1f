// physics/squeeze.h: the squeeze events of one particle, driven by scripted contact histories.
#include <gtest/gtest.h>

#include <vector>

#include "squeeze.h"

namespace sq = tsg::squeeze;

namespace {
struct Step {
  double wall, pair;
  unsigned walls;
  double speed;
};

// Feeds the steps at times 1, 2, 3 ... and returns the closed events.
std::vector<sq::Event> feed(sq::Track &track, const std::vector<Step> &steps, const sq::Thresholds &th)
{
  std::vector<sq::Event> events;
  double time = 0;
  for (const Step &s : steps) {
    sq::Sample sample;
    sample.wall_ratio = s.wall;
    sample.pair_ratio = s.pair;
    sample.walls = s.walls;
    sample.with_particles = s.pair > 0;
    sample.speed = s.speed;
    time += 1;
    sample.position[0] = time;  // the position records when the peak was reached
    sq::Event e{};
    if (sq::advance(track, sample, th, time, e)) events.push_back(e);
  }
  return events;
}
}  // namespace

TEST(Squeeze, OnePinchBetweenTwoWallsIsOneEventWithItsPeakAndRelease)
{
  sq::Thresholds th;  // start 0.1, end 0.05, release over 50 steps
  th.release_steps = 3;
  sq::Track track;
  const std::vector<Step> steps = {{0.02, 0, 1, 0.5}, {0.12, 0, 1, 0.4}, {0.30, 0, 3, 0.3},
                                   {0.20, 0, 2, 0.3}, {0.04, 0, 2, 2.0}, {0.0, 0, 0, 7.0},
                                   {0.0, 0, 0, 5.0},  {0.0, 0, 0, 4.0},  {0.0, 0, 0, 9.0}};
  const auto events = feed(track, steps, th);
  ASSERT_EQ(events.size(), 1u);
  const sq::Event &e = events[0];
  EXPECT_DOUBLE_EQ(e.start_time, 2);
  EXPECT_DOUBLE_EQ(e.end_time, 8);  // closed at the end of the 3 release steps, before the speed of 9
  EXPECT_DOUBLE_EQ(e.peak_wall, 0.30);
  EXPECT_DOUBLE_EQ(e.peak_pair, 0);
  EXPECT_DOUBLE_EQ(e.position[0], 3);  // the deepest step
  EXPECT_DOUBLE_EQ(e.start_speed, 0.4);
  EXPECT_DOUBLE_EQ(e.release_speed, 7.0);
  EXPECT_EQ(e.walls, 3u);
  EXPECT_EQ(sq::kind(e), sq::Kind::two_walls);
  EXPECT_EQ(e.number, 1);
  EXPECT_EQ(track.phase, sq::kFree);
  EXPECT_DOUBLE_EQ(track.events, 1);
}

TEST(Squeeze, ADepthOscillatingAboutTheStartThresholdIsOneEvent)
{
  sq::Thresholds th;
  th.release_steps = 0;
  sq::Track track;
  std::vector<Step> steps;
  for (int k = 0; k < 20; ++k) steps.push_back({k % 2 ? 0.08 : 0.12, 0, 1, 0.1});
  steps.push_back({0.01, 0, 0, 0.1});
  const auto events = feed(track, steps, th);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_DOUBLE_EQ(events[0].peak_wall, 0.12);
  EXPECT_EQ(sq::kind(events[0]), sq::Kind::wall_alone);
}

TEST(Squeeze, ASecondSqueezeDuringTheReleaseClosesTheFirstAndCountsTheReturn)
{
  sq::Thresholds th;
  th.release_steps = 10;
  sq::Track track;
  const std::vector<Step> steps = {{0.2, 0.15, 1, 0.1}, {0.0, 0.0, 0, 3.0}, {0.0, 0.3, 0, 1.0}, {0.0, 0.0, 0, 1.0}};
  auto events = feed(track, steps, th);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].number, 1);
  EXPECT_DOUBLE_EQ(events[0].release_speed, 3.0);
  EXPECT_EQ(sq::kind(events[0]), sq::Kind::wall_and_particles);
  EXPECT_EQ(track.phase, sq::kReleasing);
  EXPECT_DOUBLE_EQ(track.events, 2);
  EXPECT_DOUBLE_EQ(track.peak_pair, 0.3);
  EXPECT_EQ(static_cast<unsigned>(track.walls), 0u);  // the second squeeze: particles only
}

TEST(Squeeze, ShallowContactsOpenNoEvent)
{
  sq::Thresholds th;
  sq::Track track;
  std::vector<Step> steps(100, {0.1, 0.1, 1, 1.0});  // at the threshold, not above it
  EXPECT_TRUE(feed(track, steps, th).empty());
  EXPECT_DOUBLE_EQ(track.events, 0);
}

TEST(Squeeze, ThresholdsAreValidated)
{
  sq::Thresholds th;
  th.end = 0.2;  // above start
  EXPECT_THROW(sq::validate(th), std::invalid_argument);
  th = sq::Thresholds{};
  th.start = 0;
  EXPECT_THROW(sq::validate(th), std::invalid_argument);
  th = sq::Thresholds{};
  th.release_steps = -1;
  EXPECT_THROW(sq::validate(th), std::invalid_argument);
  EXPECT_NO_THROW(sq::validate(sq::Thresholds{}));
}
