// What a wall fix tells the guards and the squeeze ledger about this step's particle–wall contacts,
// without their knowing the fix's class: any wall fix can provide it (fix wall/gran/corotating does).
// Walls are numbered as the fix's meshes (0 .. wall_count() - 1); the per-particle arrays are indexed
// by local atom and valid from the fix's post_force to the next one.
#ifndef TSG_WALL_CONTACT_SOURCE_H
#define TSG_WALL_CONTACT_SOURCE_H

#include <string>

namespace tsg {

class WallContactSource {
public:
  virtual ~WallContactSource() = default;
  virtual int wall_count() const = 0;
  virtual std::string wall_name(int wall) const = 0;
  // this step, per local particle: the deepest overlap δ/R against any wall (0: no contact)
  virtual const double *step_overlap_ratio() const = 0;
  // bit k set: the particle overlaps wall k
  virtual const unsigned *step_walls_touched() const = 0;
  // bit k set: the particle's centre lies behind a face of wall k (it has crossed that surface)
  virtual const unsigned *step_walls_crossed() const = 0;
  // this step, this rank: the power of the walls' motion on the particles, W (the rate of work of the
  // contact forces at the moving surfaces; 0 for fixed walls)
  virtual double step_power() const = 0;
};

}  // namespace tsg

#endif
