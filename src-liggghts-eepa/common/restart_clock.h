// A simulation clock that survives a restart, for fixes that report or integrate time.
#ifndef TSG_RESTART_CLOCK_H
#define TSG_RESTART_CLOCK_H

#include "lmptype.h"
#include "update.h"

namespace tsg {

// LIGGGHTS 3.8 does not keep the simulation time in restart files (it starts again from 0 after
// read_restart): a fix that reports times keeps its own clock across a restart,
// now() = get_cur_time() + offset, the offset found at the first set-up after the restart.
class RestartClock {
public:
  double now(const LAMMPS_NS::Update *update) const { return update->get_cur_time() + offset_; }
  // what write_restart stores: the time and the step
  void save(const LAMMPS_NS::Update *update, double *time, double *step) const
  {
    *time = now(update);
    *step = static_cast<double>(update->ntimestep);
  }
  // what restart() reads back; load(0, step now) also starts a clock that reads 0 at this step
  void load(double time, double step)
  {
    restart_time_ = time;
    restart_step_ = step;
    pending_ = true;
  }
  // the time stored in the restart file this clock continues from (0 for a new clock)
  double restart_time() const { return restart_time_; }
  // call at set-up: continues the clock of the run that wrote the restart file
  void resume(const LAMMPS_NS::Update *update)
  {
    if (!pending_) return;
    offset_ = restart_time_ +
              static_cast<double>(update->ntimestep - static_cast<LAMMPS_NS::bigint>(restart_step_)) * update->dt -
              update->get_cur_time();
    pending_ = false;
  }

private:
  double offset_ = 0;
  bool pending_ = false;
  double restart_time_ = 0, restart_step_ = 0;
};

}  // namespace tsg

#endif
