// Unit tests of the axial partition and walk (physics/axial_partition.h), the residence-time
// tracker (physics/residence.h) and plane crossings (physics/plane_crossing.h), on prescribed
// constant-velocity motion where every time is known in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "axial_partition.h"
#include "plane_crossing.h"
#include "residence.h"

namespace {

using tsg::axial::build_partition;
using tsg::axial::kInlet;
using tsg::axial::kOutlet;
using tsg::axial::kReference;
using tsg::axial::locate;
using tsg::axial::Partition;
using tsg::residence::Reason;
using tsg::residence::Record;
using tsg::residence::Settings;
using tsg::residence::Slot;
using tsg::residence::Tracker;

constexpr double kInf = INFINITY;

// zones: 1 conveying [0.01, 0.03), 2 kneading [0.03, 0.04), gap, 3 chopping [0.05, 0.07)
std::vector<tsg::zones::Zone> test_zones()
{
  return tsg::zones::parse_zones_text(
      "1 conveying 0.01 0.03 1e-6\n2 kneading 0.03 0.04 5e-7\n3 chopping 0.05 0.07 1e-6\n", "z");
}

std::vector<tsg::zones::ZoneType> types_of(const std::vector<tsg::zones::Zone> &zones)
{
  std::vector<tsg::zones::ZoneType> types;
  for (const auto &z : zones) types.push_back(z.type);
  return types;
}

TEST(Partition, OpenAxisCellsZonesAndPlanes)
{
  const auto p = build_partition(test_zones(), false, 0, 0, -kInf, kInf, {{0.005, kInlet}, {0.08, kOutlet}});
  // edges: -inf 0.005 0.01 0.03 0.04 0.05 0.07 0.08 +inf -> 8 cells
  ASSERT_EQ(p.cells(), 8);
  EXPECT_EQ(p.zone, (std::vector<int>{-1, -1, 0, 1, -1, 2, -1, -1}));
  EXPECT_EQ(p.flags[1], kInlet);
  EXPECT_EQ(p.flags[7], kOutlet);
  for (unsigned char a : p.analysis) EXPECT_EQ(a, 1);
  int cell = -1;
  long per = 7;
  locate(p, 0.035, cell, per);
  EXPECT_EQ(cell, 3);
  EXPECT_EQ(per, 0);
  locate(p, -5.0, cell, per);
  EXPECT_EQ(cell, 0);
  locate(p, 0.07, cell, per);  // an edge belongs to the cell above it
  EXPECT_EQ(cell, 6);
}

TEST(Partition, PeriodicAxisAndAnalysisDomain)
{
  const auto p = build_partition(test_zones(), true, 0.0, 0.1, 0.02, 0.075, {{0.1, kReference}});
  // a plane at hi is the plane at lo
  EXPECT_EQ(p.flags.front(), kReference);
  EXPECT_EQ(p.flags.back(), kReference);
  int cell = -1;
  long per = 0;
  locate(p, 0.025 + 3 * 0.1, cell, per);
  EXPECT_EQ(per, 3);
  EXPECT_EQ(p.zone[cell], 0);
  EXPECT_EQ(p.analysis[cell], 1);
  locate(p, 0.015 - 2 * 0.1, cell, per);
  EXPECT_EQ(per, -2);
  EXPECT_EQ(p.zone[cell], 0);
  EXPECT_EQ(p.analysis[cell], 0);  // zone 1 below x = 0.02 is a buffer
  // every cell's lower edge locates to that cell, in any period
  for (long q = -3; q <= 3; ++q)
    for (int k = 0; k < p.cells(); ++k) {
      locate(p, p.lower(k, q), cell, per);
      EXPECT_EQ(cell, k);
      EXPECT_EQ(per, q);
    }
}

TEST(Partition, WalkReportsEveryEdgeWithInterpolatedTimes)
{
  const auto p = build_partition(test_zones(), false, 0, 0, -kInf, kInf, {});
  int cell = 0;
  long per = 0;
  locate(p, 0.0, cell, per);
  std::vector<double> times;
  std::vector<int> edges;
  // one big step from x = 0 to 0.1 in 1 s: crosses 0.01 0.03 0.04 0.05 0.07
  tsg::axial::walk(p, cell, per, 0.0, 0.1, 0.0, 1.0, [&](int e, int dir, double t, int, int) {
    EXPECT_EQ(dir, 1);
    edges.push_back(e);
    times.push_back(t);
  });
  ASSERT_EQ(times.size(), 5u);
  const double expected[5] = {0.1, 0.3, 0.4, 0.5, 0.7};
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(times[k], expected[k], 1e-15);
  // and back again
  times.clear();
  tsg::axial::walk(p, cell, per, 0.1, 0.035, 1.0, 2.0, [&](int, int dir, double t, int, int) {
    EXPECT_EQ(dir, -1);
    times.push_back(t);
  });
  ASSERT_EQ(times.size(), 3u);  // 0.07 0.05 0.04
  EXPECT_NEAR(times[0], 1.0 + 0.03 / 0.065, 1e-14);
  EXPECT_EQ(p.zone[cell], 1);
}

// Runs a tracker over straight-line motion u(t) = u0 + v t for nsteps steps of dt; returns records.
std::vector<Record> run_linear(const Tracker &tracker, double u0, double v, double dt, int nsteps, double *state,
                               bool existing = false, long *starts_out = nullptr)
{
  std::vector<Record> records;
  tracker.first_sight(state, 7, u0, 0.0, existing);
  long starts = state[Slot::status] == tsg::residence::kInside ? 1 : 0;
  for (int n = 1; n <= nsteps; ++n)
    tracker.advance(
        state, u0 + v * (n - 1) * dt, u0 + v * n * dt, (n - 1) * dt, n * dt,
        [&](const Record &r) { records.push_back(r); }, starts);
  if (starts_out) *starts_out = starts;
  return records;
}

TEST(Tracker, OpenAxisResidenceIsLengthOverSpeedPerZoneAndInTotal)
{
  const auto zones = test_zones();
  Settings s;
  s.has_inlet = true;
  s.inlet = 0.005;
  s.has_outlet = true;
  s.outlet = 0.08;
  std::vector<tsg::axial::Plane> planes = {{s.inlet, kInlet}, {s.outlet, kOutlet}};
  const Tracker tracker(build_partition(zones, false, 0, 0, -kInf, kInf, planes), types_of(zones), s);
  std::vector<double> state(static_cast<size_t>(tracker.state_size()));
  const double v = 0.13, u0 = 0.001;
  for (double dt : {1e-4, 3.7e-3, 0.05}) {  // the answer does not depend on the step
    long starts = 0;
    const auto records = run_linear(tracker, u0, v, dt, static_cast<int>(1.0 / dt), state.data(), false, &starts);
    ASSERT_EQ(records.size(), 1u) << dt;
    const Record &r = records[0];
    EXPECT_EQ(starts, 1);
    EXPECT_EQ(r.reason, Reason::outlet);
    EXPECT_EQ(r.id, 7);
    EXPECT_NEAR(r.entry_time, (0.005 - u0) / v, 1e-13) << dt;
    EXPECT_NEAR(r.exit_time, (0.08 - u0) / v, 1e-13) << dt;
    EXPECT_NEAR(r.residence_time, 0.075 / v, 1e-13) << dt;
    EXPECT_NEAR(r.zone_time[0], 0.02 / v, 1e-13) << dt;
    EXPECT_NEAR(r.zone_time[1], 0.01 / v, 1e-13) << dt;
    EXPECT_NEAR(r.zone_time[2], 0.02 / v, 1e-13) << dt;
    EXPECT_NEAR(r.type_time[0], 0.02 / v, 1e-13);
    EXPECT_NEAR(r.type_time[1], 0.01 / v, 1e-13);
    EXPECT_NEAR(r.type_time[2], 0.02 / v, 1e-13);
    EXPECT_EQ(state[Slot::status], tsg::residence::kDone);
  }
}

TEST(Tracker, NoInletTagsOnFirstSightAndExistingWaitIgnores)
{
  const auto zones = test_zones();
  Settings s;
  s.has_outlet = true;
  s.outlet = 0.08;
  const Tracker tracker(build_partition(zones, false, 0, 0, -kInf, kInf, {{0.08, kOutlet}}), types_of(zones), s);
  std::vector<double> state(static_cast<size_t>(tracker.state_size()));
  auto records = run_linear(tracker, 0.02, 0.1, 1e-3, 1000, state.data());
  ASSERT_EQ(records.size(), 1u);
  EXPECT_NEAR(records[0].entry_time, 0.0, 0);
  EXPECT_NEAR(records[0].zone_time[0], 0.01 / 0.1, 1e-13);  // from 0.02 to 0.03 only
  Settings wait = s;
  wait.tag_existing = false;
  const Tracker waiting(build_partition(zones, false, 0, 0, -kInf, kInf, {{0.08, kOutlet}}), types_of(zones), wait);
  records = run_linear(waiting, 0.02, 0.1, 1e-3, 1000, state.data(), true);
  EXPECT_TRUE(records.empty());
  // first sight downstream of the outlet: never entered
  EXPECT_EQ(tracker.first_sight(state.data(), 1, 0.09, 0.0, false), tsg::residence::kDone);
}

TEST(Tracker, BackflowTimeCountsInTheZoneWhereItIsSpent)
{
  const auto zones = test_zones();
  Settings s;
  const Tracker tracker(build_partition(zones, false, 0, 0, -kInf, kInf, {}), types_of(zones), s);
  std::vector<double> st(static_cast<size_t>(tracker.state_size()));
  std::vector<Record> records;
  long starts = 0;
  auto sink = [&](const Record &r) {
    records.push_back(r);
  };
  tracker.first_sight(st.data(), 3, 0.025, 0.0, false);              // zone 1
  tracker.advance(st.data(), 0.025, 0.035, 0.0, 1.0, sink, starts);  // crosses 0.03 at t = 0.5
  tracker.advance(st.data(), 0.035, 0.015, 1.0, 2.0, sink, starts);  // back across 0.03 at t = 1.25
  const Record r = tracker.close(st.data(), 3.0, Reason::deleted);
  EXPECT_EQ(r.reason, Reason::deleted);
  EXPECT_NEAR(r.zone_time[0], 0.5 + 1.75, 1e-14);
  EXPECT_NEAR(r.zone_time[1], 0.75, 1e-14);
  EXPECT_NEAR(r.residence_time, 3.0, 1e-14);
  EXPECT_TRUE(records.empty());
}

Tracker periodic_tracker(double alo, double ahi, bool tag_existing = false)
{
  const auto zones = test_zones();
  Settings s;
  s.periodic = true;
  s.tag_existing = tag_existing;
  return Tracker(build_partition(zones, true, 0.0, 0.1, alo, ahi, {{0.0, kReference}}), types_of(zones), s);
}

TEST(Tracker, PeriodicPassesKRecordsOfLengthOverSpeed)
{
  const Tracker tracker = periodic_tracker(-kInf, kInf);
  std::vector<double> state(static_cast<size_t>(tracker.state_size()));
  const double v = 0.07, u0 = 0.045, dt = 1e-3;
  // u crosses 0.1 (first tagging) at (0.1 - u0)/v, then a pass ends every 0.1/v
  const int k = 4;
  const double t_first = (0.1 - u0) / v, period = 0.1 / v;
  const int nsteps = static_cast<int>((t_first + k * period + 0.5 * period) / dt);
  long starts = 0;
  const auto records = run_linear(tracker, u0, v, dt, nsteps, state.data(), false, &starts);
  ASSERT_EQ(records.size(), static_cast<size_t>(k));
  EXPECT_EQ(starts, k + 1);  // balance: k records + 1 inside
  for (int j = 0; j < k; ++j) {
    EXPECT_EQ(records[j].reason, Reason::pass);
    EXPECT_NEAR(records[j].entry_time, t_first + j * period, 1e-12);
    EXPECT_NEAR(records[j].exit_time, t_first + (j + 1) * period, 1e-12);
    EXPECT_NEAR(records[j].residence_time, period, 1e-12);
    EXPECT_NEAR(records[j].zone_time[0], 0.02 / v, 1e-12);
    EXPECT_NEAR(records[j].zone_time[1], 0.01 / v, 1e-12);
    EXPECT_NEAR(records[j].zone_time[2], 0.02 / v, 1e-12);
  }
}

TEST(Tracker, PeriodicBuffersAreExcludedFromTheAnalysis)
{
  const Tracker tracker = periodic_tracker(0.02, 0.06);  // zone 1 half in the buffer, zone 3 partly
  std::vector<double> state(static_cast<size_t>(tracker.state_size()));
  const double v = 0.1;
  const auto records = run_linear(tracker, 0.05, v, 1e-3, 2600, state.data());
  ASSERT_EQ(records.size(), 2u);
  for (const auto &r : records) {
    EXPECT_NEAR(r.exit_time - r.entry_time, 1.0, 1e-12);
    EXPECT_NEAR(r.residence_time, 0.04 / v, 1e-12);
    EXPECT_NEAR(r.zone_time[0], 0.01 / v, 1e-12);
    EXPECT_NEAR(r.zone_time[1], 0.01 / v, 1e-12);
    EXPECT_NEAR(r.zone_time[2], 0.01 / v, 1e-12);
  }
}

TEST(Tracker, OscillationAcrossTheReferencePlaneIsNotAPass)
{
  const Tracker tracker = periodic_tracker(-kInf, kInf);
  std::vector<double> st(static_cast<size_t>(tracker.state_size()));
  std::vector<Record> records;
  long starts = 0;
  auto sink = [&](const Record &r) {
    records.push_back(r);
  };
  tracker.first_sight(st.data(), 1, 0.095, 0.0, false);
  // 0.095 -> 0.105 (tagged at 0.1), then back and forth across 0.1 many times
  double u = 0.095, t = 0.0;
  for (int n = 0; n < 50; ++n) {
    const double next = (n % 2 == 0) ? 0.105 : 0.097;
    tracker.advance(st.data(), u, next, t, t + 0.1, sink, starts);
    u = next;
    t += 0.1;
  }
  EXPECT_TRUE(records.empty());
  EXPECT_EQ(starts, 1);
  // then it moves on: one pass when it reaches the next image of the plane, x = 0.2
  tracker.advance(st.data(), u, 0.21, t, t + 1.0, sink, starts);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_NEAR(records[0].exit_time, t + (0.2 - u) / (0.21 - u), 1e-12);
}

TEST(Tracker, ExistingParticlesInAPeriodicDomain)
{
  const Tracker tagged = periodic_tracker(-kInf, kInf, true);
  std::vector<double> st(static_cast<size_t>(tagged.state_size()));
  const auto records = run_linear(tagged, 0.045, 0.1, 1e-3, 1000, st.data(), true);
  ASSERT_EQ(records.size(), 1u);  // the partial first pass ends at x = 0.1
  EXPECT_NEAR(records[0].entry_time, 0.0, 0);
  EXPECT_NEAR(records[0].exit_time, 0.55, 1e-12);
}

TEST(Tracker, FormatHasOneColumnPerHeaderName)
{
  const auto zones = test_zones();
  Record r;
  r.id = 12;
  r.entry_time = 0.1;
  r.exit_time = 0.35;
  r.residence_time = 0.25;
  r.reason = Reason::lost;
  r.zone_time = {0.1, 0.05, 0.0};
  const std::string line = tsg::residence::format_record(r);
  const std::string header = tsg::residence::record_columns(3);
  auto words = [](const std::string &text) {
    size_t n = 0;
    bool in_word = false;
    for (char c : text) {
      if (c != ' ' && !in_word) ++n;
      in_word = c != ' ';
    }
    return n;
  };
  EXPECT_EQ(words(line), words(header));
  EXPECT_EQ(line.substr(0, 27), "12 0.1 0.35 0.25 lost 0 0 0");
}

TEST(PlaneCrossing, OpenAndPeriodic)
{
  using tsg::flow::net_crossings;
  EXPECT_EQ(net_crossings(0.1, 0.2, 0.15, 0), 1);
  EXPECT_EQ(net_crossings(0.2, 0.1, 0.15, 0), -1);
  EXPECT_EQ(net_crossings(0.1, 0.12, 0.15, 0), 0);
  EXPECT_EQ(net_crossings(0.1, 0.15, 0.15, 0), 1);  // reaching the plane counts once ...
  EXPECT_EQ(net_crossings(0.15, 0.2, 0.15, 0), 0);  // ... and leaving it downstream not again
  EXPECT_EQ(net_crossings(0.15, 0.1, 0.15, 0), -1);
  // periodic, L = 0.1: every image of the plane
  EXPECT_EQ(net_crossings(0.05, 0.36, 0.02, 0.1), 3);  // 0.12 0.22 0.32
  EXPECT_EQ(net_crossings(0.36, 0.05, 0.02, 0.1), -3);
  EXPECT_EQ(net_crossings(-0.25, -0.15, 0.02, 0.1), 1);  // -0.18
}

}  // namespace
