// What a wall fix tells the guards (fix check/contact) and the squeeze ledger (fix squeeze/ledger)
// about its particle–wall contacts, without their knowing the fix's class: any wall fix can provide
// it (fix wall/gran/corotating does). Walls are numbered as the fix's meshes (0 .. wall_count() - 1);
// the per-particle arrays are indexed by local atom and valid from the fix's post_force to the next one.
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

  // Whether the fix reports the contacts with wall k (the per-particle arrays above, take_deepest,
  // walls_in_contact); a wall it does not report (a mesh fix wall/gran/corotating leaves to the stock
  // path of fix wall/gran) is measured by the reader itself, e.g. from the mesh's neighbour lists.
  virtual bool reports_wall(int wall) const = 0;
  // The largest overlap δ/R of a particle of this rank with wall k since the previous call (every
  // step counted) and that particle's atom ID (0: none); the record starts again.
  struct DeepestContact {
    double overlap_ratio = 0.0;
    long long atom_id = 0;
  };
  virtual DeepestContact take_deepest(int wall) = 0;
  // bit k set: local particle i has a contact with wall k at present (a contact of the wall model,
  // within the contact distance: with cohesion also a touch without overlap)
  virtual unsigned walls_in_contact(int i) const = 0;
};

}  // namespace tsg

#endif
