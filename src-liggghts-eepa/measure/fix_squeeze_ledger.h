// fix squeeze/ledger — squeezes counted and recorded, the particles' energy balanced against the
// work of the walls and gravity, and the particle centres that cross a wall surface counted.
//
//   fix ID group squeeze/ledger walls WALL-FIX records FILE [start r (0.1)] [end r (start/2)]
//       [release_steps N (50)] [max_energy_excess r] [max_crossed N] [flush N] [append yes|no]
//
// WALL-FIX: a wall fix that provides tsg::WallContactSource (fix wall/gran/corotating).
// Every step, per particle of the group (physics/squeeze.h): a squeeze opens when its deepest
// overlap δ/R against a wall or another particle exceeds `start` and closes below `end`; its
// release speed is the largest speed in the `release_steps` steps after. Each closed event is a
// record of FILE (sorted by end time): start and end time, particle, position at the deepest
// overlap, radius, peak δ/R against walls and particles, the walls touched (bit mask and names),
// its kind, the speeds before and after, and the particle's event number.
// Energy (J): W_walls = ∫ Σ (power of the moving walls on the particles) dt, W_gravity = ∫ Σ m g·v
// dt, and the budget B = KE(0) + W_walls + W_gravity + KE brought by particles created − KE taken by
// particles deleted. Contacts only dissipate or store: KE <= B. The excess (KE − B) / (S + KE), with
// S the sum of every energy that entered the budget in absolute value plus Σ m |g| R (the elastic
// energy a resting fill can hold is far below it), measures energy created by the integration (at
// most 1: a runaway from nothing); above max_energy_excess the run stops, naming the fastest particle.
// A crossing: a particle whose centre lies behind a face of a wall (counted once until it is in
// front again); the first 10 are named in the log; above max_crossed crossings the run stops.
// Global vector (thermo): [1] events closed  [2] squeezes in progress  [3] distinct particles
// squeezed  [4] largest peak wall δ/R  [5] largest peak pair δ/R  [6] largest release speed (m/s)
// [7] crossings  [8] W_walls  [9] W_gravity  [10] KE  [11] B − KE (dissipated, or stored elastically)
// [12] (KE − B) / (S + KE)  [13] Σ ½ m v² at release over the events (J).
// Restart files keep every counter, the energy budget and each particle's state.
#ifdef FIX_CLASS
// clang-format off
FixStyle(squeeze/ledger,FixSqueezeLedger)
// clang-format on
#else
#ifndef TSG_FIX_SQUEEZE_LEDGER_H
#define TSG_FIX_SQUEEZE_LEDGER_H

#include <string>
#include <vector>

#include "fix_measure_base.h"
#include "pair_depth_sink.h"
#include "squeeze.h"
#include "wall_contact_source.h"

namespace LAMMPS_NS {

class FixSqueezeLedger : public FixMeasureBase, public tsg::PairDepthSink {
public:
  FixSqueezeLedger(class LAMMPS *, int, char **);
  int setmask() override;
  void init() override;
  void setup_pre_force(int) override;
  void pre_force(int) override;
  double *pair_depths_recorded_by_pair_style() override;
  void setup(int) override;
  void end_of_step() override;
  void post_run() override;
  double compute_vector(int) override;
  void write_restart(FILE *fp) override;
  void restart(char *buf) override;

private:
  void refresh(int) override {}
  std::string state_size_hint() const override;
  double excess() const;
  void report_crossings(const std::vector<double> &mine, double count);
  void flush();
  void stop_for_energy();

  std::string wall_fix_id_, records_path_;
  tsg::WallContactSource *walls_ = nullptr;
  std::vector<std::string> wall_names_;
  tsg::squeeze::Thresholds thresholds_;
  double max_energy_excess_ = -1;  // < 0: off
  long max_crossed_ = -1;          // < 0: off
  int flush_every_ = 0;
  double gravity_[3] = {0, 0, 0};
  bool first_setup_done_ = false;

  // global, the same on every rank (restart)
  double events_ = 0, distinct_ = 0, crossings_ = 0;
  double peak_wall_ = 0, peak_pair_ = 0, max_release_ = 0;
  double work_walls_ = 0, work_gravity_ = 0, budget_ = 0, scale_ = 0, kinetic_ = 0, released_ = 0;
  double pressed_now_ = 0, lift_ = 0, power_previous_ = 0;
  int crossings_named_ = 0;

  // this step's deepest pair δ/R per local particle, −1 without a particle contact: recorded by the
  // granular pair style in its force pass (pair_depths_recorded_by_pair_style)
  std::vector<double> pair_ratio_;
  bool pair_depths_recorded_ = false;
  std::vector<double> pending_;  // closed events of this rank, one record (15 values) each
};

}  // namespace LAMMPS_NS

#endif
#endif
