// Placement of the cuts between P ranks along one axis (x, the screw axis) so that every rank holds
// the same share of the work, dependency-free (fix balance/x, docs/performance.md, "fix balance/x").
//
// The work along x is given as a histogram: nbins equal bins over [lo, hi], bin b holding weight
// w_b, spread uniformly inside the bin. Its cumulative weight W(x) is then piecewise linear and the
// equal-share cuts are its inverse at k/P of the total (k = 1 .. P-1): the inverse-CDF construction
// of recursive coordinate bisection, done along one axis only (Berger & Bokhari 1987, IEEE Trans.
// Comput. C-36, 570).
//
// Cut k may only move within (old cut k-1, old cut k+1), by a margin: LIGGGHTS hands particles and
// mesh triangles that leave a sub-domain to its two neighbours only (Comm::exchange,
// MultiNodeMeshParallel::exchange), so no particle or triangle may change owner by more than one
// rank in one move. The move is a common fraction alpha of the way from the old to the target cuts:
// old and target both keep every slab at least min_width wide, so every blend of them does too.
#ifndef TSG_BALANCE_CUTS_H
#define TSG_BALANCE_CUTS_H

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace tsg::balance {

// Bin of coordinate x among nbins equal bins over [lo, hi]; a coordinate outside (a particle not
// yet wrapped back into a periodic box, or one leaving through a wall) counts in the end bin.
inline std::size_t bin_of(double x, double lo, double hi, std::size_t nbins)
{
  const double f = (x - lo) / (hi - lo) * static_cast<double>(nbins);
  if (!(f > 0.0)) return 0;  // also NaN
  const auto b = static_cast<std::size_t>(f);
  return b >= nbins ? nbins - 1 : b;
}

// P + 1 cuts, cut 0 = lo and cut P = hi, slabs at least min_width wide, the interior cuts where the
// cumulative weight reaches k/P of the total (the leftmost such x). No weight: equal slabs.
inline std::vector<double> equal_weight_cuts(const std::vector<double> &bin_weight, double lo, double hi, int parts,
                                             double min_width)
{
  if (parts < 1) throw std::invalid_argument("balance: need at least one part, got " + std::to_string(parts));
  if (!(hi > lo)) throw std::invalid_argument("balance: need hi > lo");
  if (bin_weight.empty()) throw std::invalid_argument("balance: empty histogram");
  const double length = hi - lo;
  if (min_width < 0 || static_cast<double>(parts) * min_width > length)
    throw std::invalid_argument("balance: " + std::to_string(parts) + " slabs of at least " +
                                std::to_string(min_width) + " do not fit in a length of " + std::to_string(length));
  const std::size_t nbins = bin_weight.size();
  const double width = length / static_cast<double>(nbins);
  double total = 0.0;
  for (double w : bin_weight) {
    if (!(w >= 0.0)) throw std::invalid_argument("balance: negative or NaN bin weight");
    total += w;
  }
  std::vector<double> cut(static_cast<std::size_t>(parts) + 1);
  cut[0] = lo;
  cut[static_cast<std::size_t>(parts)] = hi;
  std::size_t b = 0;
  double below = 0.0;  // weight of bins 0 .. b-1
  for (int k = 1; k < parts; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (total <= 0.0) {
      cut[kk] = lo + length * k / parts;
      continue;
    }
    const double target = total * k / parts;
    // the first bin whose upper end reaches the target holds the cut (targets increase with k)
    while (b + 1 < nbins && below + bin_weight[b] < target) below += bin_weight[b++];
    const double inside = bin_weight[b] > 0.0 ? std::clamp((target - below) / bin_weight[b], 0.0, 1.0) : 0.0;
    cut[kk] = lo + (static_cast<double>(b) + inside) * width;
  }
  // every slab at least min_width: first keep cut k within [lo + k w, hi - (P-k) w] (a non-empty
  // interval as P w <= length), then push each cut up to its lower neighbour + w, which cannot
  // pass hi - (P-k) w because the neighbour is at most hi - (P-k+1) w
  for (int k = 1; k < parts; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    cut[kk] = std::clamp(cut[kk], lo + k * min_width, hi - (parts - k) * min_width);
    cut[kk] = std::max(cut[kk], cut[kk - 1] + min_width);
  }
  return cut;
}

// Largest alpha in [0, 1] for which old + alpha (target - old) keeps every interior cut k inside
// [old[k-1] + margin, old[k+1] - margin]. The old cuts must be at least margin apart (alpha = 0 must
// be allowed), which the caller guarantees by min_width >= margin.
inline double step_fraction(const std::vector<double> &old_cut, const std::vector<double> &target, double margin)
{
  if (old_cut.size() != target.size() || old_cut.size() < 2)
    throw std::invalid_argument("balance: old and target cuts differ in number");
  double alpha = 1.0;
  for (std::size_t k = 1; k + 1 < old_cut.size(); ++k) {
    const double move = target[k] - old_cut[k];
    const double room = move > 0 ? old_cut[k + 1] - margin - old_cut[k] : old_cut[k] - (old_cut[k - 1] + margin);
    if (room < 0) throw std::invalid_argument("balance: old cuts closer than the margin");
    if (move != 0) alpha = std::min(alpha, room / std::abs(move));
  }
  return alpha;
}

// old + alpha (target - old); the end cuts stay where they are.
inline std::vector<double> blend(const std::vector<double> &old_cut, const std::vector<double> &target, double alpha)
{
  std::vector<double> cut = old_cut;
  for (std::size_t k = 1; k + 1 < cut.size(); ++k) cut[k] = old_cut[k] + alpha * (target[k] - old_cut[k]);
  return cut;
}

// Load imbalance: the largest share over the mean share (1 = perfect; 0 work: 1).
inline double imbalance(const std::vector<double> &per_part)
{
  if (per_part.empty()) return 1.0;
  double total = 0.0, largest = 0.0;
  for (double w : per_part) {
    total += w;
    largest = std::max(largest, w);
  }
  return total > 0 ? largest * static_cast<double>(per_part.size()) / total : 1.0;
}

}  // namespace tsg::balance

#endif
