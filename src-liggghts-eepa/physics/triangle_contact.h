// Sphere–triangle contact against one triangle of a mesh with shared edges and corners,
// dependency-free.
//
// The decisions follow LIGGGHTS 3.8's triangle-mesh contact (TriMesh::resolveTriSphereContactBary,
// tri_mesh_I.h), so that a contact found in a screw's own frame is the contact the stock
// moving-mesh path finds in the lab frame:
//   - barycentric coordinates of the sphere centre in the triangle's plane select the region:
//     inside (face), beyond one edge (edge), or beyond two edges (corner), with a tolerance of
//     precision / (2 r_bound) on each coordinate;
//   - an edge or corner belongs to one of the triangles that share it: where it is inactive for
//     this triangle the contact is left to the triangle that owns it (no double counting);
//   - at a corner whose angle is obtuse the closest feature may be one of the two adjacent edges.
// The result is the vector from the sphere centre to the closest point of the active feature.
#ifndef TSG_TRIANGLE_CONTACT_H
#define TSG_TRIANGLE_CONTACT_H

#include <cmath>

namespace tsg::trimesh {

// LIGGGHTS' tolerance on edge parameters (SMALL_TRIMESH in tri_mesh_I.h)
constexpr double kEdgeTolerance = 1e-10;

struct Triangle {
  double node[3][3];
  double edge_unit[3][3];  // edge k: unit vector from node k to node (k+1) mod 3
  double edge_length[3];
  double normal[3];     // unit
  int obtuse_corner;    // index of the corner with an obtuse angle, -1 if none
  double bound_radius;  // largest distance of a node from the node average
  bool edge_active[3];
  bool corner_active[3];
};

enum class Feature { none, face, edge, corner };

struct Contact {
  Feature feature = Feature::none;
  double distance = 0.0;        // |closest point − centre|
  double delta[3] = {0, 0, 0};  // closest point − centre
};

namespace detail {
inline double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

inline Contact to_point(const double *centre, const double *point, Feature feature)
{
  Contact c;
  c.feature = feature;
  for (int k = 0; k < 3; ++k) c.delta[k] = point[k] - centre[k];
  c.distance = std::sqrt(dot(c.delta, c.delta));
  return c;
}

inline Contact corner(const Triangle &t, int k, const double *centre)
{
  if (!t.corner_active[k]) return {};
  return to_point(centre, t.node[k], Feature::corner);
}

// point at distance `along` from node `base` in the direction of edge k, if edge k is active
inline Contact edge_point(const Triangle &t, int k, int base, double along, const double *centre)
{
  if (!t.edge_active[k]) return {};
  double point[3];
  for (int d = 0; d < 3; ++d) point[d] = t.node[base][d] + along * t.edge_unit[k][d];
  return to_point(centre, point, Feature::edge);
}

// centre beyond edge k only: the closest point is on the edge or at one of its ends
inline Contact beyond_edge(const Triangle &t, int k, const double *centre)
{
  const int next = (k + 1) % 3;
  double rel[3];
  for (int d = 0; d < 3; ++d) rel[d] = centre[d] - t.node[k][d];
  const double along = dot(rel, t.edge_unit[k]);
  if (along < -kEdgeTolerance) return corner(t, k, centre);
  if (along > t.edge_length[k] + kEdgeTolerance) return corner(t, next, centre);
  return edge_point(t, k, k, along, centre);
}

// centre beyond the two edges meeting at corner k; an obtuse corner may still be closest to an edge
inline Contact beyond_corner(const Triangle &t, int k, const double *centre)
{
  const int next = (k + 1) % 3, prev = (k + 2) % 3;
  if (t.obtuse_corner == k) {
    double rel[3];
    for (int d = 0; d < 3; ++d) rel[d] = centre[d] - t.node[k][d];
    // edge prev runs from node prev to node k: negative parameter walks back along it
    const double back = dot(rel, t.edge_unit[prev]);
    if (back < kEdgeTolerance) {
      if (back > -t.edge_length[prev]) return edge_point(t, prev, k, back, centre);
      return corner(t, prev, centre);
    }
    const double ahead = dot(rel, t.edge_unit[k]);
    if (ahead > -kEdgeTolerance) {
      if (ahead < t.edge_length[k]) return edge_point(t, k, k, ahead, centre);
      return corner(t, next, centre);
    }
  }
  return corner(t, k, centre);
}
}  // namespace detail

// Whether every point of a triangle is farther than `reach` from a point, decided from what a
// candidate list keeps of the triangle: the squared distance `gap2` from the point to its node average
// (a point of its plane; gap ≤ gap_max known), the point's signed height above the plane and the
// triangle's bound radius. The triangle lies in its plane within the circle of that radius about the
// node average, so the distance within the plane is at least sqrt(gap² − height²) − bound. `slack`
// bounds the error of each input (single-precision copies): "out of reach" holds for the exact values
// too. One square root, independent of the inputs' other arithmetic.
inline bool out_of_reach(double gap2, double gap_max, double height, double bound, double reach, double slack)
{
  const double vertical = std::fabs(height);
  if (vertical - slack > reach) return true;
  const double vertical_low = vertical > slack ? vertical - slack : 0.0;
  const double vertical_high = vertical + slack;
  // (gap − slack)² − (|height| + slack)², with (gap − slack)² ≥ gap2 − 2 slack gap_max
  const double across = gap2 - 2.0 * slack * gap_max - vertical_high * vertical_high;
  const double allowed = std::sqrt(reach * reach - vertical_low * vertical_low) + bound + slack;
  return across > allowed * allowed;
}

// Closest active feature of the triangle to the sphere centre `centre` (body frame), with the
// mesh precision `precision` (LIGGGHTS' fix mesh/surface precision, default 1e-8 m).
inline Contact closest_feature(const Triangle &t, const double *centre, double precision)
{
  double rel[3];
  for (int d = 0; d < 3; ++d) rel[d] = centre[d] - t.node[0][d];
  // barycentric coordinates from the projections on edges 0 and 2 (both unit vectors)
  const double a = detail::dot(rel, t.edge_unit[0]);
  const double b = detail::dot(rel, t.edge_unit[2]);
  const double c = detail::dot(t.edge_unit[0], t.edge_unit[2]);
  const double one_minus_c2 = 1.0 - c * c;
  const double bary1 = (a - b * c) / (t.edge_length[0] * one_minus_c2);
  const double bary2 = (a * c - b) / (t.edge_length[2] * one_minus_c2);
  const double bary0 = 1.0 - bary1 - bary2;
  const double tolerance = precision / (2.0 * t.bound_radius);
  const bool within[3] = {bary0 > -tolerance, bary1 > -tolerance, bary2 > -tolerance};
  const int count = within[0] + within[1] + within[2];
  if (count == 3) {  // inside: foot of the perpendicular on the plane
    const double height = detail::dot(rel, t.normal);
    double foot[3];
    for (int d = 0; d < 3; ++d) foot[d] = centre[d] - height * t.normal[d];
    return detail::to_point(centre, foot, Feature::face);
  }
  // node k is the odd one out: with its coordinate the only negative one, the nearest feature is the
  // edge opposite it, edge (k + 1) mod 3; with the only coordinate not negative, node k itself
  const int k = within[0] == within[1] ? 2 : within[0] == within[2] ? 1 : 0;
  if (count == 2) return detail::beyond_edge(t, (k + 1) % 3, centre);
  if (count == 1) return detail::beyond_corner(t, k, centre);
  return {};  // all three negative: cannot occur for a non-degenerate triangle
}

}  // namespace tsg::trimesh

#endif
