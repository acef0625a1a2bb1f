// Each particle's deepest particle-particle overlap of a step, recorded by the granular pair style in
// its own force pass (patches/pair-gran-base-h.patch): the fix that needs them (fix squeeze/ledger)
// need not pass over the neighbour list a second time. δ / min(R_i, R_j) with δ = R_i + R_j − r, as
// common/pair_contacts.h computes it for the guards, to the last bit.
#ifndef TSG_PAIR_DEPTH_SINK_H
#define TSG_PAIR_DEPTH_SINK_H

#include <algorithm>

#include "fix.h"
#include "lammps.h"
#include "modify.h"

namespace tsg {

class PairDepthSink {
public:
  virtual ~PairDepthSink() = default;
  // This step's array, one value per local particle: its deepest pair overlap δ / min(R_i, R_j) so
  // far, −1 while it has no particle contact. Calling it tells the sink that the pair style records.
  virtual double *pair_depths_recorded_by_pair_style() = 0;
};

// The fix that takes the pair depths, or nullptr.
inline PairDepthSink *find_pair_depth_sink(LAMMPS_NS::LAMMPS *lmp)
{
  for (int k = 0; k < lmp->modify->nfix; ++k)
    if (auto *sink = dynamic_cast<PairDepthSink *>(lmp->modify->fix[k])) return sink;
  return nullptr;
}

// A contact of local particle i with j (local or ghost; a ghost's owner records it for its own).
inline void record_pair_depth(double *depth, int nlocal, int i, int j, double ratio)
{
  depth[i] = std::max(depth[i], ratio);
  if (j < nlocal) depth[j] = std::max(depth[j], ratio);
}

}  // namespace tsg

#endif
