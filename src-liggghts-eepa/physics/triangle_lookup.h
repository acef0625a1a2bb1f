// Static look-ups over a mesh that never moves (a screw in its own frame), dependency-free:
//   - TriangleTree: a bounding-volume hierarchy (axis-aligned boxes, median splits, leaves of four
//     triangles) built once. A query visits the boxes within `reach` of a point; near a surface the
//     boxes it opens grow with the mesh resolution only as the square root of the triangle count
//     (a uniform grid of fixed cells grows linearly: measured in docs/performance.md, "Screw contacts"), and the
//     reach is the querying particle's own, so no rebuild is needed when larger particles arrive.
//   - coplanar_node_neighbours: for each triangle, the triangles that share a node with it and are
//     coplanar (|n_a · n_b| > curvature), as LIGGGHTS' areCoplanarNodeNeighs decides; the contact
//     history uses them so that a particle sliding over a flat region keeps one contact.
#ifndef TSG_TRIANGLE_LOOKUP_H
#define TSG_TRIANGLE_LOOKUP_H

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
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

class TriangleTree {
public:
  // Builds the tree over the triangles (indices into `triangles`); throws std::invalid_argument for
  // an empty mesh.
  void build(const std::vector<Triangle> &triangles)
  {
    if (triangles.empty()) throw std::invalid_argument("triangle tree: the mesh has no triangles");
    const std::size_t n = triangles.size();
    spheres_.resize(4 * n);
    order_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int d = 0; d < 3; ++d)
        spheres_[4 * i + d] = (triangles[i].node[0][d] + triangles[i].node[1][d] + triangles[i].node[2][d]) / 3.0;
      spheres_[4 * i + 3] = triangles[i].bound_radius;
      order_[i] = static_cast<int>(i);
    }
    nodes_.clear();
    nodes_.reserve(2 * n / kLeafSize + 2);
    build_node(triangles, 0, n);
  }

  // Calls visit(i) for every triangle i whose bounding sphere comes within `reach` of the point p
  // (a superset of the triangles within reach of p), in a fixed order.
  template <class Visit>
  void for_each_near(const double *p, double reach, Visit visit) const
  {
    const double reach2 = reach * reach;
    std::size_t stack[kMaxDepth];
    std::size_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node &node = nodes_[stack[--top]];
      double gap2 = 0.0;  // squared distance from p to the node's box
      for (int d = 0; d < 3; ++d) {
        const double below = node.lo[d] - p[d], above = p[d] - node.hi[d];
        const double gap = below > 0.0 ? below : (above > 0.0 ? above : 0.0);
        gap2 += gap * gap;
      }
      if (gap2 > reach2) continue;
      if (node.count > 0) {
        for (std::size_t k = node.first; k < node.first + node.count; ++k) {
          const int tri = order_[k];
          const double *sphere = &spheres_[4 * static_cast<std::size_t>(tri)];
          const double dx = p[0] - sphere[0], dy = p[1] - sphere[1], dz = p[2] - sphere[2];
          const double limit = reach + sphere[3];
          if (dx * dx + dy * dy + dz * dz <= limit * limit) visit(tri);
        }
      } else {
        stack[top++] = node.second;  // visited after the first child
        stack[top++] = node.first;
      }
    }
  }

  // A lower bound on the distance from p to the nearest triangle, or `cap` when every triangle is
  // farther than cap. Per triangle the bound is the larger of the gap to its leaf's box and
  // |p − c| − r (bounding sphere); boxes no nearer than the best bound so far are skipped (branch
  // and bound, nearer child first), so the cost stays near one root-to-leaf descent.
  double clearance(const double *p, double cap) const
  {
    double best = cap;
    std::size_t stack[kMaxDepth];
    std::size_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node &node = nodes_[stack[--top]];
      const double gap = box_gap(node, p);
      if (gap >= best) continue;
      if (node.count > 0) {
        for (std::size_t k = node.first; k < node.first + node.count; ++k) {
          const double *sphere = &spheres_[4 * static_cast<std::size_t>(order_[k])];
          const double dx = p[0] - sphere[0], dy = p[1] - sphere[1], dz = p[2] - sphere[2];
          const double bound = std::max(gap, std::sqrt(dx * dx + dy * dy + dz * dz) - sphere[3]);
          best = std::min(best, bound);
        }
      } else {
        const bool first_nearer = box_gap(nodes_[node.first], p) <= box_gap(nodes_[node.second], p);
        stack[top++] = first_nearer ? node.second : node.first;  // the nearer child is visited first
        stack[top++] = first_nearer ? node.first : node.second;
      }
    }
    return best;
  }

  // bounding sphere of triangle i: centre xyz (node average), radius (largest node distance)
  const double *bounding_sphere(int i) const { return &spheres_[4 * static_cast<std::size_t>(i)]; }

  std::size_t nodes() const { return nodes_.size(); }
  std::size_t memory_bytes() const
  {
    return nodes_.size() * sizeof(Node) + order_.size() * sizeof(int) + spheres_.size() * sizeof(double);
  }

private:
  static constexpr std::size_t kLeafSize = 4;
  static constexpr std::size_t kMaxDepth = 128;
  // inner node: first/second = child node indices, count = 0; leaf: triangles order_[first, first + count)
  struct Node {
    double lo[3], hi[3];
    std::size_t first, second, count;
  };

  // distance from p to the node's box (0 inside)
  static double box_gap(const Node &node, const double *p)
  {
    double gap2 = 0.0;
    for (int d = 0; d < 3; ++d) {
      const double below = node.lo[d] - p[d], above = p[d] - node.hi[d];
      const double gap = below > 0.0 ? below : (above > 0.0 ? above : 0.0);
      gap2 += gap * gap;
    }
    return std::sqrt(gap2);
  }

  // Median split of order_[begin, end) along the longest extent of the triangle centres.
  std::size_t build_node(const std::vector<Triangle> &triangles, std::size_t begin, std::size_t end)
  {
    const std::size_t index = nodes_.size();
    nodes_.push_back(Node{});
    Node node{};
    double centre_lo[3], centre_hi[3];
    for (int d = 0; d < 3; ++d) {
      node.lo[d] = centre_lo[d] = std::numeric_limits<double>::max();
      node.hi[d] = centre_hi[d] = -std::numeric_limits<double>::max();
    }
    for (std::size_t k = begin; k < end; ++k) {
      const int tri = order_[k];
      for (int d = 0; d < 3; ++d) {
        for (const auto &n : triangles[tri].node)
          node.lo[d] = std::min(node.lo[d], n[d]), node.hi[d] = std::max(node.hi[d], n[d]);
        const double c = spheres_[4 * static_cast<std::size_t>(tri) + d];
        centre_lo[d] = std::min(centre_lo[d], c), centre_hi[d] = std::max(centre_hi[d], c);
      }
    }
    if (end - begin <= kLeafSize) {
      node.first = begin, node.count = end - begin, node.second = 0;
      nodes_[index] = node;
      return index;
    }
    int axis = 0;
    for (int d = 1; d < 3; ++d)
      if (centre_hi[d] - centre_lo[d] > centre_hi[axis] - centre_lo[axis]) axis = d;
    const std::size_t middle = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + static_cast<std::ptrdiff_t>(begin),
                     order_.begin() + static_cast<std::ptrdiff_t>(middle),
                     order_.begin() + static_cast<std::ptrdiff_t>(end), [&](int a, int b) {
                       const double ca = spheres_[4 * static_cast<std::size_t>(a) + axis];
                       const double cb = spheres_[4 * static_cast<std::size_t>(b) + axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    node.count = 0;
    node.first = build_node(triangles, begin, middle);
    node.second = build_node(triangles, middle, end);
    nodes_[index] = node;
    return index;
  }

  std::vector<Node> nodes_;
  std::vector<int> order_;       // triangle indices, grouped by leaf
  std::vector<double> spheres_;  // centre xyz, bound radius per triangle
};

// Triangles sharing at least one node (identical coordinates) with triangle i and coplanar with it.
inline CompressedLists coplanar_node_neighbours(const std::vector<Triangle> &triangles, double curvature)
{
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

#endif
