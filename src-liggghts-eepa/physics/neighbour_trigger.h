// When must the neighbour lists be rebuilt? Dependency-free (tests/unit/test_neighbour_trigger.cpp).
//
// A list built with skin s holds every pair closer than its interaction reach c plus s. Between builds
// particle i has moved d_i; a pair left out had |r| > c + s at the build, so now |r| > c + s - d_i - d_j:
// the lists hold every interacting pair while d_i + d_j <= s for the pairs that can meet. LAMMPS and
// LIGGGHTS rebuild when the largest d exceeds s/2 (then d_i + d_j <= s for every pair): one particle
// fired out of a squeeze rebuilds the lists of all 53 940 every few steps (docs/performance.md).
//
// The pairwise rule rebuilds only when a pair could have been missed:
//   d_max <= s/2                                   keep (the stock rule's own case)
//   d_max >= s                                     rebuild (a margin: the rule is meant for a few fast
//                                                  particles, not for one that crossed a whole skin)
//   otherwise, with tau = s - d_max, the "fast" set F = {i : d_i > tau}:
//     i in F, j not in F:  d_i + d_j <= d_max + tau = s                 safe
//     i, j not in F:       d_i + d_j <= 2 tau < s (as d_max > s/2)       safe
//     i, j in F:           safe when their build positions are apart:
//                          |r_ij at build| - d_i - d_j > c  (minimum image on periodic axes)
//   rebuild when F holds more than a cap of particles (the pair test is |F|^2) or a pair of F fails.
// So a fired particle may cross almost the whole skin while the others stay within s - d_max of their
// build positions, and particles fired far apart do not rebuild for each other. LIGGGHTS' granular
// ghost shells obey the same pair condition (a particle is sent to a neighbouring rank within its
// radius + the largest radius + s of the boundary: two particles that can meet share a rank while
// d_i + d_j <= s); its mesh neighbour lists (fix wall/gran with a mesh) need d <= s/2 and are refused.
#ifndef TSG_NEIGHBOUR_TRIGGER_H
#define TSG_NEIGHBOUR_TRIGGER_H

#include <cmath>
#include <cstddef>
#include <vector>

namespace tsg::trigger {

// A particle that moved more than tau: its position at the last build and its displacement since.
struct Moved {
  double x[3];
  double moved;
};

// The orthogonal box: its lengths, and which axes are periodic.
struct Box {
  double length[3];
  bool periodic[3];
};

enum class Decision { keep, rebuild, check_pairs };

// The decision from the largest displacement alone: keep, rebuild, or look at the fast set.
inline Decision from_largest(double largest, double skin)
{
  if (largest <= 0.5 * skin) return Decision::keep;
  if (largest >= skin) return Decision::rebuild;
  return Decision::check_pairs;
}

// The displacement above which a particle belongs to the fast set.
inline double fast_threshold(double largest, double skin) { return skin - largest; }

// The shortest separation of a and b on this box (minimum image on the periodic axes).
inline double separation(const double *a, const double *b, const Box &box)
{
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    double d = a[k] - b[k];
    if (box.periodic[k]) d -= box.length[k] * std::round(d / box.length[k]);
    sum += d * d;
  }
  return std::sqrt(sum);
}

// True when no two particles of the fast set can have come within `reach` of each other (the largest
// interaction distance of any pair, without the skin). The minimum image is the only image that can
// be near when every periodic length exceeds 2 (reach + 2 d_max): below that, the caller rebuilds.
inline bool fast_pairs_apart(const std::vector<Moved> &fast, double reach, const Box &box)
{
  for (std::size_t i = 0; i < fast.size(); ++i)
    for (std::size_t j = i + 1; j < fast.size(); ++j)
      if (separation(fast[i].x, fast[j].x, box) - fast[i].moved - fast[j].moved <= reach) return false;
  return true;
}

// Whether the minimum image is enough on this box (see fast_pairs_apart).
inline bool box_allows_pair_test(const Box &box, double reach, double skin)
{
  for (int k = 0; k < 3; ++k)
    if (box.periodic[k] && box.length[k] <= 2.0 * (reach + 2.0 * skin)) return false;
  return true;
}

}  // namespace tsg::trigger

#endif
