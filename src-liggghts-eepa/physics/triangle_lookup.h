// Static look-ups over a mesh that never moves (a screw in its own frame), dependency-free:
//   - TriangleGrid: uniform grid of cells; each cell lists every triangle whose bounding box,
//     grown by `reach`, overlaps the cell. The triangles that can lie within `reach` of a point are
//     then all in the list of the point's cell, and a query costs one cell, whatever the mesh size.
//   - coplanar_node_neighbours: for each triangle, the triangles that share a node with it and are
//     coplanar (|n_a · n_b| > curvature), as LIGGGHTS' areCoplanarNodeNeighs decides; the contact
//     history uses them so that a particle sliding over a flat region keeps one contact.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "triangle_contact.h"

namespace tsg::trimesh {

// Compressed lists: the items of list i are items[offsets[i] .. offsets[i+1]).
struct CompressedLists {
  std::vector<std::int64_t> offsets;
  std::vector<int> items;
  const int *begin(std::size_t i) const { return items.data() + offsets[i]; }
  const int *end(std::size_t i) const { return items.data() + offsets[i + 1]; }
};

class TriangleGrid {
 public:
  // reach > 0: largest centre-to-surface distance a query must see; cell_size >= reach.
  // Throws std::invalid_argument for an empty mesh or bad sizes, std::length_error if the grid
  // would need more than max_cells cells.
  void build(const std::vector<Triangle> &triangles, double reach, double cell_size,
             std::int64_t max_cells = 64LL << 20) {
    if (triangles.empty()) throw std::invalid_argument("triangle grid: the mesh has no triangles");
    if (!(reach > 0.0) || !(cell_size >= reach))
      throw std::invalid_argument("triangle grid: need reach > 0 and cell_size >= reach (reach " +
                                  std::to_string(reach) + ", cell size " + std::to_string(cell_size) + ")");
    reach_ = reach;
    cell_ = cell_size;
    for (int d = 0; d < 3; ++d) {
      lo_[d] = triangles[0].node[0][d];
      double hi = lo_[d];
      for (const Triangle &t : triangles)
        for (const auto &n : t.node) lo_[d] = std::min(lo_[d], n[d]), hi = std::max(hi, n[d]);
      lo_[d] -= reach;
      hi += reach;
      count_[d] = static_cast<std::int64_t>(std::floor((hi - lo_[d]) / cell_)) + 1;
    }
    const std::int64_t cells = count_[0] * count_[1] * count_[2];
    if (cells > max_cells)
      throw std::length_error("triangle grid: " + std::to_string(cells) + " cells of " + std::to_string(cell_) +
                              " m exceed the limit of " + std::to_string(max_cells));
    // two passes: count the entries of each cell, then fill
    lists_.offsets.assign(cells + 1, 0);
    for_each_cell_of_each_triangle(triangles, [&](std::int64_t cell, int) { ++lists_.offsets[cell + 1]; });
    for (std::int64_t c = 0; c < cells; ++c) lists_.offsets[c + 1] += lists_.offsets[c];
    lists_.items.assign(lists_.offsets[cells], -1);
    std::vector<std::int64_t> fill(lists_.offsets.begin(), lists_.offsets.end() - 1);
    for_each_cell_of_each_triangle(triangles, [&](std::int64_t cell, int tri) { lists_.items[fill[cell]++] = tri; });
  }

  // Triangles that may lie within reach() of the point p; empty range outside the grid.
  std::pair<const int *, const int *> candidates(const double *p) const {
    std::int64_t index[3];
    for (int d = 0; d < 3; ++d) {
      const double s = std::floor((p[d] - lo_[d]) / cell_);
      if (!(s >= 0.0) || s >= static_cast<double>(count_[d])) return {nullptr, nullptr};
      index[d] = static_cast<std::int64_t>(s);
    }
    const std::int64_t cell = (index[2] * count_[1] + index[1]) * count_[0] + index[0];
    return {lists_.begin(cell), lists_.end(cell)};
  }

  double reach() const { return reach_; }
  std::int64_t cells() const { return count_[0] * count_[1] * count_[2]; }
  std::size_t entries() const { return lists_.items.size(); }
  std::size_t memory_bytes() const {
    return lists_.offsets.size() * sizeof(std::int64_t) + lists_.items.size() * sizeof(int);
  }

 private:
  template <class Visit>
  void for_each_cell_of_each_triangle(const std::vector<Triangle> &triangles, Visit visit) const {
    for (int tri = 0; tri < static_cast<int>(triangles.size()); ++tri) {
      std::int64_t first[3], last[3];
      for (int d = 0; d < 3; ++d) {
        double lo = triangles[tri].node[0][d], hi = lo;
        for (const auto &n : triangles[tri].node) lo = std::min(lo, n[d]), hi = std::max(hi, n[d]);
        first[d] = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor((lo - reach_ - lo_[d]) / cell_)));
        last[d] = std::min<std::int64_t>(count_[d] - 1,
                                         static_cast<std::int64_t>(std::floor((hi + reach_ - lo_[d]) / cell_)));
      }
      for (std::int64_t k = first[2]; k <= last[2]; ++k)
        for (std::int64_t j = first[1]; j <= last[1]; ++j)
          for (std::int64_t i = first[0]; i <= last[0]; ++i) visit((k * count_[1] + j) * count_[0] + i, tri);
    }
  }

  double reach_ = 0.0, cell_ = 0.0;
  double lo_[3] = {0, 0, 0};
  std::int64_t count_[3] = {0, 0, 0};
  CompressedLists lists_;
};

// Triangles sharing at least one node (identical coordinates) with triangle i and coplanar with it.
inline CompressedLists coplanar_node_neighbours(const std::vector<Triangle> &triangles, double curvature) {
  std::map<std::array<double, 3>, std::vector<int>> at_node;
  for (int tri = 0; tri < static_cast<int>(triangles.size()); ++tri)
    for (const auto &n : triangles[tri].node) at_node[{n[0], n[1], n[2]}].push_back(tri);
  CompressedLists out;
  out.offsets.assign(triangles.size() + 1, 0);
  std::vector<std::vector<int>> lists(triangles.size());
  for (int tri = 0; tri < static_cast<int>(triangles.size()); ++tri) {
    std::vector<int> &mine = lists[tri];
    for (const auto &n : triangles[tri].node)
      for (int other : at_node[{n[0], n[1], n[2]}]) {
        if (other == tri) continue;
        const double *a = triangles[tri].normal, *b = triangles[other].normal;
        if (std::fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) > curvature) mine.push_back(other);
      }
    std::sort(mine.begin(), mine.end());
    mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
    out.offsets[tri + 1] = out.offsets[tri] + static_cast<std::int64_t>(mine.size());
  }
  out.items.reserve(out.offsets.back());
  for (const auto &l : lists) out.items.insert(out.items.end(), l.begin(), l.end());
  return out;
}

}  // namespace tsg::trimesh
