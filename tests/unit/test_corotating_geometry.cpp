// Unit tests of the dependency-free geometry behind fix wall/gran/corotating:
// rigid_rotation.h (pose, surface velocity, phase from time), triangle_contact.h (closest feature),
// triangle_lookup.h (bounding-volume tree, coplanar neighbours). References are independent: closed-form
// rotations, brute-force minimisation over a dense sampling of the triangle, and exhaustive search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "rigid_rotation.h"
#include "triangle_contact.h"
#include "triangle_lookup.h"

namespace rot = tsg::rotation;
namespace tmesh = tsg::trimesh;

namespace {

tmesh::Triangle make_triangle(const double a[3], const double b[3], const double c[3])
{
  tmesh::Triangle t{};
  const double *n[3] = {a, b, c};
  double centre[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d) t.node[k][d] = n[k][d], centre[d] += n[k][d] / 3.0;
  for (int k = 0; k < 3; ++k) {
    const int next = (k + 1) % 3;
    double len = 0.0;
    for (int d = 0; d < 3; ++d) len += (n[next][d] - n[k][d]) * (n[next][d] - n[k][d]);
    len = std::sqrt(len);
    t.edge_length[k] = len;
    for (int d = 0; d < 3; ++d) t.edge_unit[k][d] = (n[next][d] - n[k][d]) / len;
    t.edge_active[k] = t.corner_active[k] = true;
  }
  const rot::Vec3 e0{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e1{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const rot::Vec3 normal = rot::cross(e0, e1);
  const double len = rot::norm(normal);
  t.normal[0] = normal.x / len, t.normal[1] = normal.y / len, t.normal[2] = normal.z / len;
  t.obtuse_corner = -1;
  for (int k = 0; k < 3; ++k) {
    const int prev = (k + 2) % 3;
    double dot = 0.0;  // angle at node k between edges k and (prev reversed)
    for (int d = 0; d < 3; ++d) dot += t.edge_unit[k][d] * (-t.edge_unit[prev][d]);
    if (dot < 0.0) t.obtuse_corner = k;
  }
  t.bound_radius = 0.0;
  for (int k = 0; k < 3; ++k) {
    double r2 = 0.0;
    for (int d = 0; d < 3; ++d) r2 += (n[k][d] - centre[d]) * (n[k][d] - centre[d]);
    t.bound_radius = std::max(t.bound_radius, std::sqrt(r2));
  }
  return t;
}

// the surface z = height(x, y) over nx x ny squares of side h from the origin, two triangles each
template <class Height>
std::vector<tmesh::Triangle> height_field(int nx, int ny, double h, Height height)
{
  std::vector<tmesh::Triangle> tris;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const double x0 = i * h, x1 = (i + 1) * h, y0 = j * h, y1 = (j + 1) * h;
      const double p00[3] = {x0, y0, height(x0, y0)}, p10[3] = {x1, y0, height(x1, y0)};
      const double p01[3] = {x0, y1, height(x0, y1)}, p11[3] = {x1, y1, height(x1, y1)};
      tris.push_back(make_triangle(p00, p10, p11));
      tris.push_back(make_triangle(p00, p11, p01));
    }
  return tris;
}

// distance from p to the triangle by dense sampling of barycentric coordinates (independent)
double sampled_distance(const tmesh::Triangle &t, const double p[3], int samples = 600)
{
  double best = 1e300;
  for (int i = 0; i <= samples; ++i)
    for (int j = 0; i + j <= samples; ++j) {
      const double u = double(i) / samples, v = double(j) / samples, w = 1.0 - u - v;
      double d2 = 0.0;
      for (int d = 0; d < 3; ++d) {
        const double q = w * t.node[0][d] + u * t.node[1][d] + v * t.node[2][d];
        d2 += (q - p[d]) * (q - p[d]);
      }
      best = std::min(best, d2);
    }
  return std::sqrt(best);
}

}  // namespace

TEST(RigidRotation, QuarterTurnAboutXMapsYToZ)
{
  const rot::Mat3 r = rot::rotation_matrix({1, 0, 0}, M_PI / 2);
  const rot::Vec3 y = r.apply({0, 1, 0});
  EXPECT_NEAR(y.x, 0.0, 1e-15);
  EXPECT_NEAR(y.y, 0.0, 1e-15);
  EXPECT_NEAR(y.z, 1.0, 1e-15);
}

TEST(RigidRotation, MatrixIsOrthonormalAndTransposeUndoesIt)
{
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 100; ++k) {
    rot::Vec3 axis{u(rng), u(rng), u(rng)};
    axis = (1.0 / rot::norm(axis)) * axis;
    const rot::Mat3 r = rot::rotation_matrix(axis, 10 * u(rng));
    const rot::Vec3 v{u(rng), u(rng), u(rng)};
    const rot::Vec3 back = r.apply_transpose(r.apply(v));
    EXPECT_NEAR(rot::norm(back - v), 0.0, 1e-14);
    EXPECT_NEAR(rot::norm(r.apply(v)), rot::norm(v), 1e-14);
    // the axis is fixed
    EXPECT_NEAR(rot::norm(r.apply(axis) - axis), 0.0, 1e-14);
  }
}

TEST(RigidRotation, BodyAndLabFramesAreInverse)
{
  const rot::RigidRotation screw{{0.0, -0.009655, 0.0}, {1, 0, 0}, 2 * M_PI / 0.1};
  const rot::Mat3 pose = rot::rotation_matrix(screw.axis, screw.angle(0.0123));
  const rot::Vec3 lab{0.01, 0.002, -0.004};
  const rot::Vec3 body = screw.to_body(pose, lab);
  const rot::Vec3 again = screw.origin + rot::RigidRotation::vector_to_lab(pose, body - screw.origin);
  EXPECT_NEAR(rot::norm(again - lab), 0.0, 1e-17);
  // distance from the axis and axial position are invariant
  EXPECT_NEAR(body.x, lab.x, 1e-18);
  EXPECT_NEAR(std::hypot(body.y - screw.origin.y, body.z), std::hypot(lab.y - screw.origin.y, lab.z), 1e-17);
}

TEST(RigidRotation, SurfaceVelocityIsOmegaCrossRadius)
{
  // 600 rpm about +x through (0, a, 0): a point at radius 10 mm straight above the axis (+z) moves
  // towards -y at ω r
  const double omega = 2 * M_PI * 10.0;
  const rot::RigidRotation screw{{0.0, 0.005, 0.0}, {1, 0, 0}, omega};
  const rot::Vec3 v = screw.surface_velocity({0.3, 0.005, 0.01});
  EXPECT_NEAR(v.x, 0.0, 1e-15);
  EXPECT_NEAR(v.y, -omega * 0.01, 1e-14);
  EXPECT_NEAR(v.z, 0.0, 1e-15);
}

TEST(RigidRotation, PhaseFromTimeDoesNotDriftWhereIncrementsDo)
{
  // 10 million steps of 2.5e-6 s at 600 rpm (25 s, 250 revolutions)
  const double omega = 2 * M_PI / 0.1, dt = 2.5e-6;
  const long steps = 10000000;
  double accumulated = 0.0;
  for (long n = 0; n < steps; ++n) accumulated += omega * dt;
  const rot::RigidRotation screw{{0, 0, 0}, {1, 0, 0}, omega};
  const double from_time = screw.angle(static_cast<double>(steps) * dt);
  const double exact = 2 * M_PI * 250.0;
  EXPECT_LE(std::fabs(from_time - exact), 4 * std::numeric_limits<double>::epsilon() * exact);
  // the sum of increments is what a per-step rotation accumulates: orders of magnitude worse
  EXPECT_GT(std::fabs(accumulated - exact), 100 * std::fabs(from_time - exact));
}

TEST(TriangleContact, FaceEdgeAndCornerDistancesMatchBruteForce)
{
  const double a[3] = {0, 0, 0}, b[3] = {1e-3, 0, 0}, c[3] = {0.3e-3, 0.8e-3, 0};
  const tmesh::Triangle t = make_triangle(a, b, c);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1e-3, 2e-3);
  int features[4] = {0, 0, 0, 0};
  for (int k = 0; k < 400; ++k) {
    const double p[3] = {u(rng), u(rng), 0.5 * u(rng)};
    const tmesh::Contact hit = tmesh::closest_feature(t, p, 1e-8);
    ASSERT_NE(hit.feature, tmesh::Feature::none);
    ++features[static_cast<int>(hit.feature)];
    EXPECT_NEAR(hit.distance, sampled_distance(t, p), 3e-6);  // sampling resolution 1e-3/600
    // the closest point lies on the triangle: sampled distance from it is ~0
    const double q[3] = {p[0] + hit.delta[0], p[1] + hit.delta[1], p[2] + hit.delta[2]};
    EXPECT_LT(sampled_distance(t, q), 3e-6);
  }
  EXPECT_GT(features[1], 10);  // face
  EXPECT_GT(features[2], 10);  // edge
  EXPECT_GT(features[3], 10);  // corner
}

TEST(TriangleContact, ObtuseCornerRegionCanBeClosestToAnEdge)
{
  // obtuse at node 0: points beyond both edges at node 0 but closest to an edge interior
  const double a[3] = {0, 0, 0}, b[3] = {1e-3, 0.1e-3, 0}, c[3] = {-1e-3, 0.1e-3, 0};
  const tmesh::Triangle t = make_triangle(a, b, c);
  ASSERT_EQ(t.obtuse_corner, 0);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.5e-3, 1.5e-3);
  for (int k = 0; k < 300; ++k) {
    const double p[3] = {u(rng), -std::fabs(u(rng)), 0.3 * u(rng)};
    const tmesh::Contact hit = tmesh::closest_feature(t, p, 1e-8);
    EXPECT_NEAR(hit.distance, sampled_distance(t, p), 6e-6) << p[0] << " " << p[1] << " " << p[2];
  }
}

TEST(TriangleContact, InactiveEdgesAndCornersAreLeftToTheirOwner)
{
  const double a[3] = {0, 0, 0}, b[3] = {1e-3, 0, 0}, c[3] = {0, 1e-3, 0};
  tmesh::Triangle t = make_triangle(a, b, c);
  const double beyond_edge0[3] = {0.5e-3, -0.2e-3, 0.1e-3};
  EXPECT_EQ(tmesh::closest_feature(t, beyond_edge0, 1e-8).feature, tmesh::Feature::edge);
  t.edge_active[0] = false;
  EXPECT_EQ(tmesh::closest_feature(t, beyond_edge0, 1e-8).feature, tmesh::Feature::none);
  const double beyond_corner1[3] = {1.3e-3, -0.2e-3, 0.0};
  EXPECT_EQ(tmesh::closest_feature(t, beyond_corner1, 1e-8).feature, tmesh::Feature::corner);
  t.corner_active[1] = false;
  EXPECT_EQ(tmesh::closest_feature(t, beyond_corner1, 1e-8).feature, tmesh::Feature::none);
  const double above[3] = {0.2e-3, 0.2e-3, 0.4e-3};
  const tmesh::Contact face = tmesh::closest_feature(t, above, 1e-8);
  EXPECT_EQ(face.feature, tmesh::Feature::face);
  EXPECT_NEAR(face.delta[2], -0.4e-3, 1e-18);
}

// The reach test of the candidate lists: "out of reach" only where the exact closest distance
// (closest_feature, itself checked against sampling above) is beyond reach, also with inputs off by
// their slack; and it leaves out most of the triangles around a sphere resting on a flat mesh finer
// than it.
TEST(TriangleContact, OutOfReachOnlyBeyondReachAndSkipsTheTouchedFacesNeighbours)
{
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  auto distance_to = [](const double *a, const double *b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  };
  int rejected_within_sphere = 0;
  for (int k = 0; k < 4000; ++k) {
    const double a[3] = {u(rng), u(rng), u(rng)}, b[3] = {u(rng), u(rng), u(rng)}, c[3] = {u(rng), u(rng), u(rng)};
    const tmesh::Triangle t = make_triangle(a, b, c);
    double centroid[3];
    for (int d = 0; d < 3; ++d) centroid[d] = (a[d] + b[d] + c[d]) / 3.0;
    const double p[3] = {2 * u(rng), 2 * u(rng), 2 * u(rng)};
    const double exact = tmesh::closest_feature(t, p, 1e-8).distance;
    const double gap = distance_to(p, centroid);
    const double height =
        (p[0] - centroid[0]) * t.normal[0] + (p[1] - centroid[1]) * t.normal[1] + (p[2] - centroid[2]) * t.normal[2];
    const double reach = exact * std::uniform_real_distribution<double>(0.5, 1.5)(rng);
    const double gap_max = reach + t.bound_radius;
    if (gap > gap_max) continue;  // the bounding-sphere test comes first
    const bool out = tmesh::out_of_reach(gap * gap, gap_max, height, t.bound_radius, reach, 0.0);
    if (out) {
      ASSERT_GT(exact, reach) << "triangle " << k;
      ++rejected_within_sphere;
    }
    // inputs off by up to the slack s (as the single-precision copies are): still never a wrong "out"
    const double s = 1e-7;
    const double off_gap = gap + s, off_height = height > 0 ? height - s : height + s, off_bound = t.bound_radius - s;
    if (tmesh::out_of_reach(off_gap * off_gap, gap_max + s, off_height, off_bound, reach, s)) {
      ASSERT_GT(exact, reach) << "triangle " << k << " (inputs off by the slack)";
    }
  }
  EXPECT_GT(rejected_within_sphere, 200);  // it decides, beyond the bounding sphere

  // a sphere of radius 0.2 mm resting 10 um deep on a flat mesh of 0.1 mm squares: of the triangles
  // whose bounding sphere is within reach, the test keeps those that can touch
  const double h = 0.1e-3, radius = 0.2e-3;
  const std::vector<tmesh::Triangle> mesh = height_field(20, 20, h, [](double, double) { return 0.0; });
  const double centre[3] = {1.03e-3, 0.97e-3, radius - 10e-6};
  int by_sphere = 0, kept = 0, touching = 0;
  for (const tmesh::Triangle &t : mesh) {
    double centroid[3] = {0, 0, 0};
    for (const auto &n : t.node)
      for (int d = 0; d < 3; ++d) centroid[d] += n[d] / 3.0;
    const double gap = distance_to(centre, centroid);
    const double height = (centre[0] - centroid[0]) * t.normal[0] + (centre[1] - centroid[1]) * t.normal[1] +
                          (centre[2] - centroid[2]) * t.normal[2];
    const bool near_sphere = gap <= radius + t.bound_radius;
    const bool keep =
        near_sphere && !tmesh::out_of_reach(gap * gap, radius + t.bound_radius, height, t.bound_radius, radius, 1e-7);
    const bool touches = tmesh::closest_feature(t, centre, 1e-8).distance <= radius;
    by_sphere += near_sphere, kept += keep, touching += touches;
    EXPECT_TRUE(!touches || keep);  // no touching triangle is left out
  }
  EXPECT_GE(by_sphere, 15);
  EXPECT_LT(kept, by_sphere / 2);
  EXPECT_GE(kept, touching);
  EXPECT_GT(touching, 0);
}

TEST(TriangleTree, VisitsEveryTriangleWithinReachOnce)
{
  // a wavy surface of 2 x 40 x 40 triangles
  const int n = 40;
  const double h = 0.25e-3;
  const std::vector<tmesh::Triangle> tris =
      height_field(n, n, h, [](double x, double y) { return 0.5e-3 * std::sin(3000 * x) * std::cos(2000 * y); });
  tmesh::TriangleTree tree;
  tree.build(tris);
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> ux(-1e-3, n * h + 1e-3), uz(-1.5e-3, 1.5e-3), ur(0.1e-3, 0.8e-3);
  int near_pairs = 0;
  std::size_t visited_total = 0;
  for (int k = 0; k < 300; ++k) {
    const double p[3] = {ux(rng), ux(rng), uz(rng)};
    const double reach = ur(rng);
    std::vector<int> visited;
    tree.for_each_near(p, reach, [&](int tri) { visited.push_back(tri); });
    std::vector<int> sorted = visited;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "a triangle visited twice";
    visited_total += visited.size();
    for (int tri = 0; tri < static_cast<int>(tris.size()); ++tri) {
      const tmesh::Contact c = tmesh::closest_feature(tris[tri], p, 1e-8);
      if (c.feature != tmesh::Feature::none && c.distance <= reach) {
        ++near_pairs;
        EXPECT_TRUE(std::binary_search(sorted.begin(), sorted.end(), tri)) << "triangle " << tri;
      }
    }
  }
  EXPECT_GT(near_pairs, 100);
  // the pre-test keeps the visits close to the triangles that matter (not the whole mesh)
  EXPECT_LT(visited_total, 300u * tris.size() / 20);
  // a query far outside visits nothing
  const double far[3] = {1.0, 1.0, 1.0};
  int count = 0;
  tree.for_each_near(far, 1e-3, [&](int) { ++count; });
  EXPECT_EQ(count, 0);
}

TEST(TriangleTree, ClearanceIsALowerBoundWithinTheBoundingSpheres)
{
  // a tilted, folded strip of 2 x 30 x 10 triangles; points near it and far from it
  const std::vector<tmesh::Triangle> tris = height_field(
      30, 10, 0.3e-3, [](double x, double y) { return 0.2 * x + (y > 1.5e-3 ? 0.5 * (y - 1.5e-3) : 0.0); });
  tmesh::TriangleTree tree;
  tree.build(tris);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> ux(-1e-3, 10e-3), uy(-1e-3, 4e-3), uz(-1.5e-3, 3.5e-3);
  const double cap = 0.8e-3;
  int capped = 0, below_cap = 0;
  for (int k = 0; k < 400; ++k) {
    const double p[3] = {ux(rng), uy(rng), uz(rng)};
    double nearest = 1e9, sphere_bound = 1e9;  // brute force: distance, and |p - c| - r
    for (const tmesh::Triangle &t : tris) {
      const tmesh::Contact hit = tmesh::closest_feature(t, p, 1e-8);  // every edge and corner active: exact
      ASSERT_NE(hit.feature, tmesh::Feature::none);
      nearest = std::min(nearest, hit.distance);
      double c[3];
      for (int d = 0; d < 3; ++d) c[d] = (t.node[0][d] + t.node[1][d] + t.node[2][d]) / 3.0;
      sphere_bound = std::min(sphere_bound, std::sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                                                      (p[2] - c[2]) * (p[2] - c[2])) -
                                                t.bound_radius);
    }
    const double clearance = tree.clearance(p, cap);
    EXPECT_LE(clearance, cap);
    EXPECT_LE(clearance, nearest + 1e-12) << "not a lower bound at " << p[0] << " " << p[1] << " " << p[2];
    EXPECT_GE(clearance, std::min(cap, sphere_bound) - 1e-12);
    if (sphere_bound > cap) {
      EXPECT_EQ(clearance, cap);
      ++capped;
    } else {
      ++below_cap;
    }
  }
  EXPECT_GT(capped, 20);
  EXPECT_GT(below_cap, 100);
}

TEST(TriangleTree, RejectsAnEmptyMesh)
{
  tmesh::TriangleTree tree;
  EXPECT_THROW(tree.build({}), std::invalid_argument);
}

TEST(CoplanarNeighbours, FlatSquareIsOneRegionAFoldIsNot)
{
  // two triangles of a flat square share an edge and are coplanar; a third folded by 45 degrees
  // shares a node but is not coplanar
  const double p0[3] = {0, 0, 0}, p1[3] = {1, 0, 0}, p2[3] = {1, 1, 0}, p3[3] = {0, 1, 0};
  const double q[3] = {2, 0, 1};
  std::vector<tmesh::Triangle> tris{make_triangle(p0, p1, p2), make_triangle(p0, p2, p3), make_triangle(p1, q, p2)};
  const tmesh::CompressedLists lists = tmesh::coplanar_node_neighbours(tris, 1.0 - 1e-5);
  ASSERT_EQ(lists.end(0) - lists.begin(0), 1);
  EXPECT_EQ(*lists.begin(0), 1);
  EXPECT_EQ(*lists.begin(1), 0);
  EXPECT_EQ(lists.end(2) - lists.begin(2), 0);
}
