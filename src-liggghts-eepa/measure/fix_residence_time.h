// fix residence/time — residence-time records per particle, per zone and per zone type.
//
//   fix ID group residence/time zones ZONES_FILE records RECORDS_FILE [keyword value ...]
//     inlet X            open axis: particles upstream of X are tagged when they cross it towards +x
//     outlet X           open axis: crossing X towards +x ends the residence (reason "outlet")
//     periodic X         periodic x: a pass runs from one crossing of X (or an image) to the next
//     analysis XLO XHI   analysis domain along x; time outside it (buffer zones) is not counted
//     existing tag|wait  particles present when the fix starts: tagged at once or wait for an entry
//                        (default: tag on an open axis, wait on a periodic one)
//     inside yes|no      at the end of every run write a record with reason "inside" for every
//                        particle still inside (snapshot; default no; also fix_modify ID inside ...)
//     flush N            write buffered records every N steps (default: the thermo interval)
//     append yes|no      append to RECORDS_FILE, or start it anew (default: append when the fix continues
//                        from a restart file; 'no' then refuses to overwrite a file that holds data)
//
// Records file: see docs/measurement.md. Global vector for thermo (f_ID[i]):
//   1 records (outlet + pass + deleted + lost)   2 complete records (outlet + pass)
//   3 mean residence time of complete records, s  4 entries (particles tagged + passes started)
//   5 particles inside now                        6 outlet records   7 pass records
//   8 deleted records                             9 lost records
// Balance: entries = records + inside.
#ifdef FIX_CLASS
// clang-format off
FixStyle(residence/time,FixResidenceTime)
// clang-format on
#else
#ifndef TSG_FIX_RESIDENCE_TIME_H
#define TSG_FIX_RESIDENCE_TIME_H

#include <cstdio>
#include <string>
#include <vector>

#include "fix_measure_base.h"
#include "ledger.h"
#include "residence.h"
#include "zones.h"

namespace LAMMPS_NS {

class FixResidenceTime : public FixMeasureBase {
public:
  FixResidenceTime(class LAMMPS *, int, char **);
  void init() override;
  void setup(int) override;
  void end_of_step() override;
  void post_run() override;
  int modify_param(int, char **) override;
  double compute_vector(int) override;
  void write_restart(FILE *) override;
  void restart(char *) override;
  double memory_usage() override;

private:
  enum Counter { kEntered, kOutlet, kPass, kDeleted, kLost, kRecordsInside, kSumResidence, kCounters };
  // state_: the per-particle state of residence.h (Slot layout); hot_: its cell bounds lo, hi and
  // 1 when inside, the only data read every step (lo, hi) and on reneighbouring steps (inside)
  enum HotSlot { kHotLo = 0, kHotHi = 1, kHotInside = 2, kHotSlots = 3 };
  void refresh(int i) override
  {
    hot_[i][kHotLo] = state_[i][tsg::residence::Slot::lo];
    hot_[i][kHotHi] = state_[i][tsg::residence::Slot::hi];
    hot_[i][kHotInside] = state_[i][tsg::residence::Slot::status] == tsg::residence::kInside;
  }
  void leaving(int i) override;
  void arrived(int i) override;
  std::string state_size_hint() const override { return "a zones file with a different number of zones?"; }
  void track(double t0, double t1, bool at_setup);
  void track_one(int i, double t0, double t1, bool at_setup, long &starts);
  void reconcile(double t);
  void check_ids();
  void remember(int i);
  void add_record(const tsg::residence::Record &record);
  void flush();
  void sync_counters();
  void open_records_file();

  std::string zones_path_;
  std::vector<tsg::zones::Zone> zones_;
  tsg::residence::Tracker tracker_;
  tsg::residence::Settings settings_;
  std::vector<double> partition_edges_;  // of the first init(), to detect a changed box
  double plane_reference_;
  double analysis_lo_, analysis_hi_;
  bool has_analysis_;
  bool existing_given_;
  bool write_inside_;
  int flush_every_;
  bool flush_given_;
  bool first_setup_done_;

  std::string records_path_;

  tsg::residence::Ledger ledger_;  // inside particles owned here, by id (physics/ledger.h)

  std::vector<tsg::residence::Record> pending_;
  double local_[kCounters];  // since the last sync, this rank
  double total_[kCounters];  // all ranks, as of the last sync (restart-safe)
  bool cache_valid_;
  double inside_now_;
};

}  // namespace LAMMPS_NS

#endif
#endif
