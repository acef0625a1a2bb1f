// fix outlet/sink — removes the particles that have passed an open outlet, within a step of their
// passing, and counts them.
//
//   fix ID group outlet/sink x X
//
// Past the open outlet end of a barrel nothing holds a particle: thrown off the screw tips it
// leaves the bore sideways, and the box around the barrel has little room there (1 mm at the demo
// and paper scales). Removing particles between run segments (`run N every M "delete_atoms ..."`)
// comes too late for any M worth a segment's set-up: the particle leaves the box first and the run
// stops with lost atoms. This fix looks at every step: when a particle of the group has its centre
// past x = X (X > the barrel end, inside the box; a non-periodic x axis), the next step is a
// re-neighbouring step and the particle is deleted before the exchange (pre_exchange), as
// `delete_atoms` would (fix residence/time records it, with the outlet crossing it made before).
//
// Output: f_ID[1] particles removed, f_ID[2] their mass, kg, since the run sequence began (kept in
// restart files).
#ifdef FIX_CLASS
// clang-format off
FixStyle(outlet/sink,FixOutletSink)
// clang-format on
#else
#ifndef TSG_FIX_OUTLET_SINK_H
#define TSG_FIX_OUTLET_SINK_H

#include <string>

#include "fix.h"

namespace LAMMPS_NS {

class FixOutletSink : public Fix {
public:
  FixOutletSink(class LAMMPS *, int, char **);
  int setmask() override;
  void init() override;
  void setup(int) override;
  void end_of_step() override;
  void pre_exchange() override;
  double compute_vector(int) override;
  void write_restart(FILE *) override;
  void restart(char *) override;

private:
  bool any_past() const;
  void remove_past();
  std::string who_;
  double outlet_x_;
  double removed_ = 0;       // particles, all ranks
  double removed_mass_ = 0;  // kg, all ranks
};

}  // namespace LAMMPS_NS

#endif
#endif
