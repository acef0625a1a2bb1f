// fix balance/x — load balance along the screw axis: moves the x cuts between the ranks of a
// `processors N 1 1` grid so that every rank holds the same number of particles.
//
//   fix ID all balance/x N
//
// The cuts move at the start of every run and then every N steps (a re-neighbouring step is forced
// there). Each move takes the cuts a common fraction of the way to the equal-count cuts
// (physics/balance_cuts.h) such that no particle or mesh triangle changes owner by more than one
// rank, as LIGGGHTS' Comm and mesh exchange hand them to the neighbours only; a fill that moved far
// is followed over several moves. Slabs are never thinner than the neighbour cutoff (cut + skin).
// The fix marks the sub-domains as changing (box_change_domain), so that LIGGGHTS re-sets up its
// communication on every re-neighbouring step; fixed meshes are re-distributed only on the steps
// whose cuts moved (patches/fix-mesh-cpp.patch: the stock code did it on every re-neighbouring,
// which made a 2-rank full granulator 3 x slower than 1 rank).
// Cuts are not stored in restart files: a run continued from one starts from equal slabs and the
// first move of the run balances it again.
// With one rank the fix does nothing.
//
// Output: f_ID = the particle imbalance now (largest count per rank / mean count, 1 = balanced);
// f_ID[k], k = 1 .. P+1 (P ranks along x), = the x position of cut k-1 (cut 0 = box low end, cut P =
// high end), m.
#ifdef FIX_CLASS
// clang-format off
FixStyle(balance/x,FixBalanceX)
// clang-format on
#else
#ifndef TSG_FIX_BALANCE_X_H
#define TSG_FIX_BALANCE_X_H

#include <string>
#include <vector>

#include "fix.h"

namespace LAMMPS_NS {

class FixBalanceX : public Fix {
public:
  FixBalanceX(class LAMMPS *, int, char **);
  int setmask() override;
  void init() override;
  void setup_pre_exchange() override;
  void pre_exchange() override;
  double compute_scalar() override;
  double compute_vector(int) override;

private:
  void move_cuts();
  std::string who_;
  int every_;
  int parts_;
};

}  // namespace LAMMPS_NS

#endif
#endif
