// fix check/contact — time-step estimate and overlap monitor for granular runs.
//
//   fix ID group check/contact [every N] [step_fraction f] [action warn|error]
//
// At set-up and every N steps: the critical step estimate (Rayleigh time of the smallest particle,
// shortened by sqrt(1 - λp) where EEPA's stiffer unloading branch applies; physics/contact_timestep.h),
// compared with the time step; and the largest particle–particle overlap δ/R (R the smaller radius).
// Global vector for thermo output:
//   f_ID[1] largest δ/R seen so far in the run    f_ID[2] largest δ/R at the last check
//   f_ID[3] critical step estimate (s)            f_ID[4] time step / estimate
#ifdef FIX_CLASS
FixStyle(check/contact,FixCheckContact)
#else
#ifndef TSG_FIX_CHECK_CONTACT_H
#define TSG_FIX_CHECK_CONTACT_H

#include "fix.h"

namespace LAMMPS_NS {

class FixCheckContact : public Fix {
public:
  FixCheckContact(class LAMMPS *, int, char **);
  int setmask();
  void init();
  void setup(int);
  void end_of_step();
  double compute_vector(int);

private:
  void check();
  double critical_step() const;
  double largest_overlap_ratio() const;

  double step_fraction_;       // largest allowed dt / estimate
  bool error_on_violation_;
  bool warned_;
  double max_overlap_ratio_run_;
  double max_overlap_ratio_now_;
  double estimate_;
  class FixPropertyGlobal *youngs_modulus_;
  class FixPropertyGlobal *poisson_ratio_;
  class FixPropertyGlobal *plasticity_ratio_;  // present when EEPA is configured
};

}  // namespace LAMMPS_NS

#endif
#endif
