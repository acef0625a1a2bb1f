// Partition of the axial (x) coordinate into cells, and a walk of a particle across it, dependency-free.
//
// The cell edges are every zone boundary, the analysis-domain bounds and every measurement plane
// (inlet, outlet, periodic reference plane), so that inside one cell the zone, the in-analysis flag
// and the side of every plane are constant. A particle is tracked by its cell and, in a periodic
// domain, the number of periods its unwrapped coordinate u is away from the base period [lo, hi):
// in unwrapped coordinates cell k of period p is [edge[k] + p L, edge[k+1] + p L).
//
// Open axis: edge[0] = -inf, edge[M] = +inf, cells 0..M-1 cover the whole line, p = 0 always.
// Periodic axis: edge[0] = lo, edge[M] = hi, L = hi - lo; leaving cell M-1 upwards enters cell 0 of
// the next period; edge M is the same plane as edge 0 and is reported as edge 0.
//
// walk() moves a particle from u0 (time t0) to u1 (time t1) assuming constant velocity over the
// step, reporting each edge crossed, in order, with the interpolated crossing time.
#ifndef TSG_AXIAL_PARTITION_H
#define TSG_AXIAL_PARTITION_H

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "zones.h"

namespace tsg::axial {

// flags of an edge: which measurement planes lie on it
enum PlaneFlag : unsigned { kInlet = 1u, kOutlet = 2u, kReference = 4u };

struct Plane {
  double x;
  unsigned flag;
};

struct Partition {
  bool periodic = false;
  double lo = 0, hi = 0, period = 0;    // periodic: base period [lo, hi), period = hi - lo; open: 0
  std::vector<double> edge;             // M + 1 edges
  std::vector<int> zone;                // per cell: 0-based zone index or -1
  std::vector<unsigned char> analysis;  // per cell: 1 inside the analysis domain
  std::vector<unsigned> flags;          // per edge (periodic: flags[M] == flags[0])

  int cells() const { return static_cast<int>(zone.size()); }
  double lower(int cell, long per) const { return edge[cell] + static_cast<double>(per) * period; }
  // the upper edge of the last periodic cell is computed as the lower edge of cell 0 one period on,
  // so that a particle exactly on that plane is in one cell only, whichever way it is reached
  double upper(int cell, long per) const
  {
    if (periodic && cell + 1 == cells()) return lower(0, per + 1);
    return edge[cell + 1] + static_cast<double>(per) * period;
  }
};

// Builds the partition. Zones must lie in [lo, hi] when periodic; analysis bounds may be infinite
// (no restriction); planes must lie in [lo, hi) when periodic (a plane at hi is the plane at lo).
inline Partition build_partition(const std::vector<zones::Zone> &zones, bool periodic, double lo, double hi,
                                 double analysis_lo, double analysis_hi, const std::vector<Plane> &planes)
{
  Partition p;
  p.periodic = periodic;
  std::vector<double> cuts;
  for (const auto &z : zones) {
    cuts.push_back(z.x_start);
    cuts.push_back(z.x_end);
  }
  if (std::isfinite(analysis_lo)) cuts.push_back(analysis_lo);
  if (std::isfinite(analysis_hi)) cuts.push_back(analysis_hi);
  std::vector<Plane> normalised = planes;
  if (periodic) {
    if (!(hi > lo)) throw std::invalid_argument("periodic axis needs hi > lo");
    p.lo = lo;
    p.hi = hi;
    p.period = hi - lo;
    for (auto &plane : normalised)
      if (plane.x == hi) plane.x = lo;
    for (double c : cuts)
      if (c < lo || c > hi) throw std::invalid_argument("partition edge outside the periodic box");
    cuts.push_back(lo);
    cuts.push_back(hi);
  }
  for (const auto &plane : normalised) cuts.push_back(plane.x);
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  if (periodic) {
    p.edge = cuts;  // starts with lo, ends with hi
  } else {
    p.edge.push_back(-std::numeric_limits<double>::infinity());
    p.edge.insert(p.edge.end(), cuts.begin(), cuts.end());
    p.edge.push_back(std::numeric_limits<double>::infinity());
  }
  const int ncells = static_cast<int>(p.edge.size()) - 1;
  p.zone.assign(ncells, -1);
  p.analysis.assign(ncells, 0);
  for (int k = 0; k < ncells; ++k) {
    double a = p.edge[k], b = p.edge[k + 1];
    const double mid = !std::isfinite(a) ? b - 1.0 : !std::isfinite(b) ? a + 1.0 : 0.5 * (a + b);
    p.zone[k] = zones::find_zone(zones, mid);
    p.analysis[k] = (mid >= analysis_lo && mid < analysis_hi) ? 1 : 0;
  }
  p.flags.assign(p.edge.size(), 0u);
  for (const auto &plane : normalised) {
    const auto it = std::lower_bound(p.edge.begin(), p.edge.end(), plane.x);
    const auto e = static_cast<std::size_t>(it - p.edge.begin());
    p.flags[e] |= plane.flag;
    if (periodic && e == 0) p.flags.back() |= plane.flag;
  }
  return p;
}

// Cell and period of the unwrapped coordinate u, consistent with Partition::lower/upper.
inline void locate(const Partition &p, double u, int &cell, long &per)
{
  const int m = p.cells();
  per = 0;
  if (p.periodic) per = static_cast<long>(std::floor((u - p.lo) / p.period));
  for (int guard = 0; guard < 4; ++guard) {
    if (u < p.lower(0, per)) {
      --per;
      continue;
    }
    if (u >= p.upper(m - 1, per)) {
      ++per;
      continue;
    }
    int a = 0, b = m - 1;  // largest k with lower(k) <= u
    while (a < b) {
      const int mid = (a + b + 1) / 2;
      if (p.lower(mid, per) <= u)
        a = mid;
      else
        b = mid - 1;
    }
    cell = a;
    return;
  }
  throw std::invalid_argument("axial coordinate " + std::to_string(u) + " cannot be located");
}

// Moves (cell, per) from u0 to u1; on_cross(edge, direction, time, from_cell, to_cell) for every
// edge crossed, in the order crossed. Edges are reported in [0, M) for a periodic axis.
template <class OnCross>
inline void walk(const Partition &p, int &cell, long &per, double u0, double u1, double t0, double t1,
                 OnCross &&on_cross)
{
  const int m = p.cells();
  const double du = u1 - u0;
  auto crossing_time = [&](double x) {
    if (du == 0) return t1;
    const double f = std::min(1.0, std::max(0.0, (x - u0) / du));
    return t0 + f * (t1 - t0);
  };
  while (u1 >= p.upper(cell, per)) {
    const double x = p.upper(cell, per);
    int next = cell + 1;
    long next_per = per;
    int reported = next;
    if (next == m) {  // only reachable on a periodic axis (open: upper of the last cell is +inf)
      next = 0;
      ++next_per;
      reported = 0;
    }
    on_cross(reported, +1, crossing_time(x), cell, next);
    cell = next;
    per = next_per;
  }
  while (u1 < p.lower(cell, per)) {
    const double x = p.lower(cell, per);
    int next = cell - 1;
    long next_per = per;
    if (next < 0) {  // periodic only (open: lower of cell 0 is -inf)
      next = m - 1;
      --next_per;
    }
    on_cross(cell, -1, crossing_time(x), cell, next);
    cell = next;
    per = next_per;
  }
}

}  // namespace tsg::axial

#endif
