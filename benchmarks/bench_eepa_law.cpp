// Evaluations per second of the EEPA law (eepa_law.h) against a plain Hertz force, both with
// the Hertz-Mindlin dashpot, on the same overlap/velocity sequence; prints EEPA/Hertz ratios.
//
//   bench_eepa_law [--benchmark_min_time=1]
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "eepa_law.h"

namespace {

using tsg::eepa::Parameters;

constexpr double kPi = 3.14159265358979323846;

// Seed-paper pair (Table 3/4): R* = 100 um, E* = 2.27e7 Pa, lambda_p = 0.8, n = 1.5, X = 20,
// f0 = -1 mN, 15 J/m^2; reduced mass of two 400 um spheres of density 1263 kg/m^3.
const Parameters kCohesive{4.0 / 3.0 * 2.2667e7 * 1e-2, 0.8, 1.5, 20, -1e-3, 15, 1e-4};
const Parameters kConstantPullOff{kCohesive.k1, 0.8, 1.5, 20, -1e-3, 0, 1e-4};
const double kReducedMass = 0.5 * 4.0 / 3.0 * kPi * 8e-12 * 1263;
const double kBeta = tsg::eepa::damping_ratio_from_restitution(0.5);

// 256 load-unload cycles of different depth (0.2 to 6 um), 64 samples each, always in contact
// (down to 1e-9 of the depth), so that every branch is visited: loading, unloading, adhesive,
// reloading.
struct Trajectory {
  std::vector<double> overlap, velocity;
};
Trajectory make_trajectory() {
  Trajectory t;
  const int cycles = 256, samples = 64;
  const double dt = 1e-7;
  for (int c = 0; c < cycles; ++c) {
    const double depth = 0.2e-6 + 5.8e-6 * std::fmod(0.618034 * c, 1.0);
    for (int s = 0; s < samples; ++s) {
      const double phase = kPi * s / samples;
      t.overlap.push_back(depth * (1e-9 + std::sin(phase) * std::sin(phase)));
      t.velocity.push_back(depth * std::sin(2 * phase) * kPi / (samples * dt));
    }
  }
  return t;
}
const Trajectory kTrajectory = make_trajectory();

// A pair loop: 1024 contacts, each following the trajectory from its own starting sample; one
// benchmark iteration is one time step over all contacts. Contacts are independent, as in
// LIGGGHTS, so the timing is throughput, not the latency of one contact's history chain.
constexpr std::size_t kContacts = 1024;
std::size_t sample_of(std::size_t contact, std::size_t step) {
  return (contact * 997 + step) % kTrajectory.overlap.size();
}

// Plain Hertz: f = k1 d^1.5 with the Hertz-Mindlin dashpot on S = 1.5 k1 d^0.5.
double hertz_force(double k1, double overlap, double velocity) {
  const double root = std::sqrt(overlap);
  return k1 * overlap * root +
         tsg::eepa::damping_force(kBeta, 1.5 * k1 * root, kReducedMass, velocity);
}

void BM_Hertz(benchmark::State& state) {
  std::size_t step = 0;
  for (auto _ : state) {
    double sum = 0;
    for (std::size_t c = 0; c < kContacts; ++c) {
      const std::size_t i = sample_of(c, step);
      sum += hertz_force(kCohesive.k1, kTrajectory.overlap[i], kTrajectory.velocity[i]);
    }
    benchmark::DoNotOptimize(sum);
    ++step;
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * kContacts));
}

void run_eepa(benchmark::State& state, const Parameters& p) {
  std::vector<tsg::eepa::History> history(kContacts);
  std::size_t step = 0;
  for (auto _ : state) {
    double sum = 0;
    for (std::size_t c = 0; c < kContacts; ++c) {
      const std::size_t i = sample_of(c, step);
      const tsg::eepa::State s = tsg::eepa::evaluate(p, history[c], kTrajectory.overlap[i]);
      history[c] = s.history;
      sum += s.force +
             tsg::eepa::damping_force(kBeta, s.stiffness, kReducedMass, kTrajectory.velocity[i]);
    }
    benchmark::DoNotOptimize(sum);
    ++step;
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * kContacts));
}
void BM_EEPA_Cohesive(benchmark::State& state) { run_eepa(state, kCohesive); }
void BM_EEPA_ConstantPullOff(benchmark::State& state) { run_eepa(state, kConstantPullOff); }

BENCHMARK(BM_Hertz);
BENCHMARK(BM_EEPA_Cohesive);
BENCHMARK(BM_EEPA_ConstantPullOff);

// Console reporter that also keeps each benchmark's evaluations per second (the mean over
// repetitions when --benchmark_repetitions is given).
class RateReporter : public benchmark::ConsoleReporter {
 public:
  RateReporter() : ConsoleReporter(OO_Tabular) {}
  std::map<std::string, double> rate;
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name != "mean") continue;
      const auto it = run.counters.find("items_per_second");
      if (it != run.counters.end()) rate[run.run_name.function_name] = it->second.value;
    }
    ConsoleReporter::ReportRuns(runs);
  }
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RateReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  const auto hertz = reporter.rate.find("BM_Hertz");
  if (hertz == reporter.rate.end()) return 0;
  std::printf("\nevaluations/s: BM_Hertz %.3g\n", hertz->second);
  for (const auto& [name, rate] : reporter.rate)
    if (name != "BM_Hertz")
      std::printf("evaluations/s: %s %.3g, ratio EEPA/Hertz %.3f (Hertz %.1f x faster)\n",
                  name.c_str(), rate, rate / hertz->second, hertz->second / rate);
  int visits[4] = {0, 0, 0, 0};  // Separated, Loading, Unloading, Adhesive
  tsg::eepa::History history{};
  for (double overlap : kTrajectory.overlap) {
    const tsg::eepa::State s = tsg::eepa::evaluate(kCohesive, history, overlap);
    history = s.history;
    ++visits[static_cast<int>(s.branch)];
  }
  std::printf("cohesive trajectory: %d samples, loading %d, unloading %d, adhesive %d\n",
              static_cast<int>(kTrajectory.overlap.size()), visits[1], visits[2], visits[3]);
  return 0;
}
