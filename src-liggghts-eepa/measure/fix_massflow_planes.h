// fix massflow/planes — signed mass flow rate through axial planes (mass-flow sensors), kg/h.
//
//   fix ID group massflow/planes planes K X1 ... XK window N [file FILE] [append yes|no]
//     append: as fix residence/time (default: append when continuing from a restart file)
//
// Every step each particle's unwrapped axial coordinate is compared with the previous step's; each
// crossing of a plane x = Xk (on a periodic x axis: of any image Xk + jL) adds the particle's mass,
// + towards +x, - towards -x (physics/plane_crossing.h). Windows are N steps long and end on steps
// that are multiples of N; at the end of each window the rate = net mass / window duration, in kg/h,
// becomes the fix's global vector (f_ID[k], sensor k; 0 until the first window ends) and is written
// to FILE ("# tsg-dem mass flow v1", "# columns: step time sensor_1 ... sensor_K").
// Particles inserted during a step start counting at the next step; moves between runs (set,
// displace_atoms) are not counted. Restart-safe (per-particle positions, the open window).
#ifdef FIX_CLASS
// clang-format off
FixStyle(massflow/planes,FixMassflowPlanes)
// clang-format on
#else
#ifndef TSG_FIX_MASSFLOW_PLANES_H
#define TSG_FIX_MASSFLOW_PLANES_H

#include <string>
#include <vector>

#include "fix_measure_base.h"

namespace LAMMPS_NS {

class FixMassflowPlanes : public FixMeasureBase {
public:
  FixMassflowPlanes(class LAMMPS *, int, char **);
  void init() override;
  void setup(int) override;
  void end_of_step() override;
  void post_run() override;
  double compute_vector(int) override;
  void write_restart(FILE *) override;
  void restart(char *) override;

private:
  // per-particle state (migrates, restarted): the interval [lo, hi) between plane images it lies in,
  // shrunk by a rounding margin on a periodic axis, inside which no crossing can happen; 1 once
  // seen; then for each plane k the side it is on, floor((u - X_k)/L) on a periodic axis or
  // [u >= X_k] on an open one: the net crossings of a step are the change of these numbers.
  // hot_ holds the copy of [lo, hi), the only data read every step.
  enum StateSlot { kLo = 0, kHi = 1, kSeen = 2, kSides = 3 };
  void refresh(int i) override;
  std::string state_size_hint() const override { return "a different number of planes?"; }
  void place(int i, double u);
  void count_one(int i, double length);
  void consolidate();
  void open_mass_flow_file();

  std::vector<double> planes_;
  int window_ = 0;
  std::string path_;
  std::vector<double> mass_;  // net mass through each plane in the open window, this rank, kg
  double window_time_ = 0;    // duration of the open window so far, s
  std::vector<double> rate_;  // last completed window, kg/h
};

}  // namespace LAMMPS_NS

#endif
#endif
