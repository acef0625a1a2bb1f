// fix check/contact — time-step estimate, overlap monitors and guards that stop a bad run.
//
//   fix ID group check/contact [every N] [pair_every M] [step_fraction f] [action error|warn]
//       [max_speed v] [fast_speed u] [max_pair_overlap r] [walls wall-fix-ID] [max_wall_overlap r]
//
// Every N steps (and at set-up):
// - the critical step estimate (Rayleigh time of the smallest particle, shortened by sqrt(1 - λp)
//   where EEPA's stiffer unloading branch applies; physics/contact_timestep.h), compared with the
//   time step: above step_fraction f of it the run stops (action error, the default) or warns
//   once (action warn);
// - the largest particle–particle overlap δ/R (R the smaller radius), also every M steps in between
//   (pair_every; a contact lasts 10 steps or more at the cases' time steps, so M of a few steps sees
//   its peak; default M = N); above max_pair_overlap the run stops naming both particles;
// - with walls: the largest overlap δ/R of any particle with each mesh of that fix wall/gran or
//   wall/gran/corotating. A wall/gran/corotating fix records it at every step between checks for
//   its corotate/fixed meshes; other meshes are measured at the check (triangles from the wall
//   fix's own mesh neighbour lists). Above max_wall_overlap the run stops naming the particle and
//   the mesh.
// At every step: a non-finite position, velocity or force, or a particle faster than max_speed,
// stops the run with the step, the particle and its deepest contacts. A particle faster than
// fast_speed (below max_speed) is counted, once per excursion above it: an event. Hertz contact
// gives such speeds physically to a particle squeezed through a gap narrower than itself and
// released (converged in the time step; docs/stability.md, "Pinch releases"), so an event is
// counted and reported, not stopped: the first 10 are named in the log with their contacts (at
// most one per step). The
// count and each particle's state (above fast_speed or not) go into restart files.
// Keywords not given switch their guard off (the time-step check and the non-finite check are
// always on). Global vector for thermo output:
//   f_ID[1] largest pair δ/R seen so far in the run   f_ID[2] largest pair δ/R at the last check
//   f_ID[3] critical step estimate (s)                f_ID[4] time step / estimate
//   f_ID[5] largest particle speed since the previous check (m/s)
//   f_ID[5+k] largest δ/R against the k-th mesh of the walls fix since the previous check
//   f_ID[6+M] fast_speed events so far in the run (M meshes in the walls fix; 0 without fast_speed)
#ifdef FIX_CLASS
// clang-format off
FixStyle(check/contact,FixCheckContact)
// clang-format on
#else
#ifndef TSG_FIX_CHECK_CONTACT_H
#define TSG_FIX_CHECK_CONTACT_H

#include <string>
#include <vector>

#include "fix.h"

#include "wall_contact_source.h"

namespace LAMMPS_NS {

class FixCheckContact : public Fix {
public:
  FixCheckContact(class LAMMPS *, int, char **);
  ~FixCheckContact() override;
  int setmask() override;
  void init() override;
  void setup(int) override;
  void end_of_step() override;
  double compute_vector(int) override;
  void grow_arrays(int nmax) override;
  void copy_arrays(int i, int j, int delflag) override;
  void set_arrays(int i) override;
  int pack_exchange(int i, double *buf) override;
  int unpack_exchange(int nlocal, double *buf) override;
  int pack_restart(int i, double *buf) override;
  void unpack_restart(int nlocal, int nth) override;
  int maxsize_restart() override { return 2; }
  int size_restart(int) override { return 2; }
  void write_restart(FILE *fp) override;
  void restart(char *buf) override;

private:
  struct Deepest {  // a largest overlap and who has it
    double overlap_ratio = 0;
    tagint atom_id = 0;
    tagint partner_id = 0;  // the other particle of a pair contact
  };

  void check();
  void check_time_step();
  void check_motion();
  void check_pair_overlap();
  void check_wall_overlap();
  double critical_step() const;
  Deepest deepest_pair_contact(int only_atom) const;
  Deepest deepest_stock_wall_contact(int mesh, int only_atom) const;
  std::string contacts_of(int i) const;
  // the walls fix reports its contacts with mesh k itself (tsg::WallContactSource)
  bool reported(int k) const { return contact_source_ && contact_source_->reports_wall(k); }

  int check_every_;
  int pair_every_ = 0;    // steps between pair-overlap checks; 0 until parsed: check_every_
  double step_fraction_;  // largest allowed dt / estimate
  bool error_on_violation_;
  bool warned_;
  double max_speed_;          // m/s; 0: off
  double fast_speed_;         // m/s; 0: off
  double *above_fast_;        // per particle: 1 while it moves faster than fast_speed_ (the event is counted)
  double fast_events_;        // all ranks, up to the last check (restart files carry it)
  double fast_events_local_;  // this rank, since the last check
  int fast_events_named_;     // events named in the log so far (the same on every rank)
  int fast_event_to_name_;    // a local particle whose new event could be named this step; -1: none
  double max_pair_overlap_;   // δ/R; 0: off
  double max_wall_overlap_;   // δ/R; 0: off
  std::string wall_fix_id_;   // empty: no wall monitor
  class FixWallGran *walls_;
  tsg::WallContactSource *contact_source_;  // walls_ as a contact reporter (nullptr: stock fix wall/gran)
  std::vector<std::string> mesh_ids_;
  std::vector<double> wall_overlap_now_;
  double max_overlap_ratio_run_;
  double max_overlap_ratio_now_;
  double max_speed_squared_window_;  // this rank, since the previous check
  double max_speed_now_;
  double estimate_;
  class FixPropertyGlobal *youngs_modulus_;
  class FixPropertyGlobal *poisson_ratio_;
  class FixPropertyGlobal *plasticity_ratio_;  // present when EEPA is configured
};

}  // namespace LAMMPS_NS

#endif
#endif
