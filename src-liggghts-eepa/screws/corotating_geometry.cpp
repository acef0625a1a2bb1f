// fix wall/gran/corotating: the screws' triangles (gathered on every rank, checked against the axis)
// and the per-particle candidate lists of triangles within reach (fix_wall_gran_corotating.h).
#include "fix_wall_gran_corotating.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "atom.h"
#include "comm.h"
#include "container.h"
#include "domain.h"
#include "fix_mesh_surface.h"
#include "neighbor.h"
#include "tri_mesh.h"

#include "gather.h"

using namespace LAMMPS_NS;
namespace rot = ::tsg::rotation;
namespace tmesh = ::tsg::trimesh;

namespace {
constexpr int kValuesPerTriangle = 32;  // id, nodes 9, edge units 9, edge lengths 3, normal 3, obtuse, active 6
// an empty candidate list stays valid for at most this many list skins of motion (a choice, not
// tuned: docs/performance.md)
constexpr double kFarMargins = 16.0;
// LIGGGHTS' coplanarity threshold for mesh faces (SurfaceMesh: 1 − EPSILON_CURVATURE)
constexpr double kCoplanarCurvature = 1.0 - 1e-5;
// a corotating screw must be (close to) symmetric about its axis: the area centroid of its surface
// may lie at most this fraction of its largest radius from the axis
constexpr double kAxisTolerance = 0.01;
}  // namespace

// Every rank keeps the whole screw: a particle's lab position says nothing about where the part of
// the screw it touches is stored, so the distributed mesh of fix mesh/surface cannot be used.
void FixWallGranCorotating::gather_triangles(Screw &screw)
{
  TriMesh *mesh = all_meshes_[screw.list_index]->triMesh();
  const int nowned = mesh->sizeLocal();
  ScalarContainer<int> *obtuse = mesh->prop().getElementProperty<ScalarContainer<int>>("obtuseAngleIndex");
  if (!obtuse) fail("mesh '" + screw.mesh_id + "' has no obtuse-angle data");
  std::vector<double> mine(static_cast<size_t>(nowned) * kValuesPerTriangle);
  for (int i = 0; i < nowned; ++i) {
    double *v = &mine[static_cast<size_t>(i) * kValuesPerTriangle];
    v[0] = mesh->id(i);
    for (int k = 0; k < 3; ++k) {
      mesh->node(i, k, v + 1 + 3 * k);
      mesh->edgeVec(i, k, v + 10 + 3 * k);
      v[28 + k] = (mesh->edgeActive(i, k) ? 1 : 0) + (mesh->cornerActive(i, k) ? 2 : 0);
    }
    mesh->edgeLen(i, v + 19);
    mesh->surfaceNorm(i, v + 22);
    v[25] = obtuse->get(i);
  }
  const std::vector<double> all = tsg::gather_to_all(world, mine, comm->nprocs);

  const size_t ntri = all.size() / kValuesPerTriangle;
  if (ntri == 0) fail("mesh '" + screw.mesh_id + "' has no triangles");
  std::vector<size_t> order(ntri);
  for (size_t t = 0; t < ntri; ++t) order[t] = t;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return all[a * kValuesPerTriangle] < all[b * kValuesPerTriangle]; });
  screw.triangles.resize(ntri);
  for (size_t t = 0; t < ntri; ++t) {
    const double *v = &all[order[t] * kValuesPerTriangle];
    tmesh::Triangle &tri = screw.triangles[t];
    double centre[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) {
        tri.node[k][d] = v[1 + 3 * k + d];
        tri.edge_unit[k][d] = v[10 + 3 * k + d];
        centre[d] += tri.node[k][d];
      }
    for (int d = 0; d < 3; ++d) centre[d] /= 3.0;
    tri.bound_radius = 0.0;  // as MultiNodeMesh: largest node distance from the node average
    for (int k = 0; k < 3; ++k) {
      tri.edge_length[k] = v[19 + k];
      tri.normal[k] = v[22 + k];
      const int flags = static_cast<int>(v[28 + k]);
      tri.edge_active[k] = flags & 1;
      tri.corner_active[k] = flags & 2;
      const double dx = centre[0] - tri.node[k][0], dy = centre[1] - tri.node[k][1], dz = centre[2] - tri.node[k][2];
      tri.bound_radius = std::max(tri.bound_radius, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    tri.obtuse_corner = static_cast<int>(v[25]);
  }
  screw.precision = mesh->contactPrecision();
  screw.coplanar = tmesh::coplanar_node_neighbours(screw.triangles, kCoplanarCurvature);
}

// The screw must turn about its own axis: the area centroid of its surface on the axis.
void FixWallGranCorotating::check_shares_axis(const Screw &screw)
{
  const rot::RigidRotation &m = screw.motion;
  double area_sum = 0.0, radius_max = 0.0;
  rot::Vec3 moment{0, 0, 0};
  for (const tmesh::Triangle &t : screw.triangles) {
    rot::Vec3 n[3];
    for (int k = 0; k < 3; ++k) n[k] = {t.node[k][0], t.node[k][1], t.node[k][2]};
    const double area = 0.5 * rot::norm(rot::cross(n[1] - n[0], n[2] - n[0]));
    const rot::Vec3 centre = (1.0 / 3.0) * (n[0] + n[1] + n[2]);
    moment = moment + area * centre;
    area_sum += area;
    for (const rot::Vec3 &p : n) {
      const rot::Vec3 r = p - m.origin;
      radius_max = std::max(radius_max, rot::norm(r - rot::dot(r, m.axis) * m.axis));
    }
  }
  const rot::Vec3 r = (1.0 / area_sum) * moment - m.origin;
  const double offset = rot::norm(r - rot::dot(r, m.axis) * m.axis);
  if (offset > kAxisTolerance * radius_max)
    fail("mesh '" + screw.mesh_id + "' does not share the rotation axis: the area centroid of its surface lies " +
         number(offset) + " m from the axis through (" + number(m.origin.x) + ", " + number(m.origin.y) + ", " +
         number(m.origin.z) + ") along (" + number(m.axis.x) + ", " + number(m.axis.y) + ", " + number(m.axis.z) +
         "); allowed is " + number(kAxisTolerance * radius_max) + " m (1 % of its largest radius " +
         number(radius_max) + " m). A corotating screw turns about its own axis: check origin and axis.");
}

// Moves each list to its particle's new local index (by atom ID); particles new to this rank get a
// new list.
void FixWallGranCorotating::follow_lists_to_new_indices(const std::vector<rot::Mat3> &poses)
{
  const int nlocal = atom->nlocal;
  const size_t stride = built_stride();
  std::unordered_map<tagint, size_t> old_index;
  old_index.reserve(list_owner_.size());
  for (size_t k = 0; k < list_owner_.size(); ++k) old_index.emplace(list_owner_[k], k);
  std::vector<Candidate> pool;
  pool.reserve(candidate_pool_.size());
  std::vector<CandidateSpan> spans(nlocal);
  std::vector<double> built(static_cast<size_t>(nlocal) * stride, 0.0);
  std::vector<tagint> owner(nlocal);
  std::vector<bool> fresh(nlocal, true);
  for (int i = 0; i < nlocal; ++i) {
    owner[i] = atom->tag[i];
    const auto found = old_index.find(atom->tag[i]);
    if (found == old_index.end()) continue;
    const CandidateSpan old = candidate_spans_[found->second];
    spans[i] = {pool.size(), old.count, old.count};
    pool.insert(pool.end(), candidate_pool_.begin() + old.begin, candidate_pool_.begin() + old.begin + old.count);
    std::copy(&built_at_[found->second * stride], &built_at_[(found->second + 1) * stride], &built[i * stride]);
    fresh[i] = false;
  }
  candidate_pool_ = std::move(pool);
  candidate_spans_ = std::move(spans);
  built_at_ = std::move(built);
  list_owner_ = std::move(owner);
  for (int i = 0; i < nlocal; ++i)
    if (fresh[i] && (atom->mask[i] & groupbit)) build_candidates(i, poses);
}

namespace {
// height of p above the triangle's plane (along its normal)
double signed_plane_distance(const tmesh::Triangle &t, const double *p)
{
  return (p[0] - t.node[0][0]) * t.normal[0] + (p[1] - t.node[0][1]) * t.normal[1] +
         (p[2] - t.node[0][2]) * t.normal[2];
}
}  // namespace

// Candidates of particle i: the triangles of every screw whose bounding sphere and plane come within
// reach + skin of the particle or of a periodic image of it within that distance of a box face. With them,
// how far the particle may move in each frame before the list can miss a contact (its margin):
//   - a screw with candidates: the list skin (every other triangle was farther than reach + skin;
//     the mesh is at rest in its frame, so the whole skin is the particle's, not half of it);
//   - a screw without: the tree's clearance less the reach, if more than the skin, capped at
//     kFarMargins skins — particles far from a screw keep their empty list for many steps;
//   - lab frame (periodic images): the distance to the nearest periodic face whose image is not
//     in the list, less the reach.
void FixWallGranCorotating::build_candidates(int i, const std::vector<rot::Mat3> &poses)
{
  const double *xi = atom->x[i];
  const double contact_reach = atom->radius[i] * std::max(1.0, neighbor->contactDistanceFactor);
  const double skin = list_skin();
  const double reach = contact_reach + skin;
  const double cap = kFarMargins * skin;
  const int periodic[3] = {domain->xperiodic, domain->yperiodic, domain->zperiodic};
  // images: -1, 0, +1 box lengths per periodic direction within reach of a face
  signed char images[8][3] = {{0, 0, 0}};
  int nimage = 1;
  double lab_margin = cap;
  for (int d = 0; d < 3; ++d) {
    if (!periodic[d]) continue;
    const double below = xi[d] - domain->boxlo[d], above = domain->boxhi[d] - xi[d];
    signed char shift = 0;
    if (below < reach)
      shift = 1;
    else if (above < reach)
      shift = -1;
    const double uncovered = shift == 1 ? above : (shift == -1 ? below : std::min(below, above));
    lab_margin = std::min(lab_margin, uncovered - contact_reach);
    if (shift == 0) continue;
    for (int k = 0; k < nimage; ++k) {
      std::copy(images[k], images[k] + 3, images[nimage + k]);
      images[nimage + k][d] = shift;
    }
    nimage *= 2;
  }
  std::vector<Candidate> &list = candidate_scratch_;
  list.clear();
  ++list_builds_;
  double *built = &built_at_[static_cast<size_t>(i) * built_stride()];
  std::copy(xi, xi + 3, built);
  lab_margin = std::max(lab_margin, 0.0);  // a box shorter than two reaches: rebuild every step
  built[3] = lab_margin * lab_margin;
  for (size_t s = 0; s < screws_.size(); ++s) {
    const Screw &screw = screws_[s];
    const rot::Vec3 body = screw.motion.to_body(poses[s], {xi[0], xi[1], xi[2]});
    double *frame = built + 4 + 4 * s;
    frame[0] = body.x, frame[1] = body.y, frame[2] = body.z;
    double margin = cap;
    for (int k = 0; k < nimage; ++k) {
      const rot::Vec3 lab{xi[0] + images[k][0] * domain->prd[0], xi[1] + images[k][1] * domain->prd[1],
                          xi[2] + images[k][2] * domain->prd[2]};
      const rot::Vec3 image_body = screw.motion.to_body(poses[s], lab);
      const double centre[3] = {image_body.x, image_body.y, image_body.z};
      const size_t before = list.size();
      screw.tree.for_each_near(centre, reach, [&](int tri) {
        const tmesh::Triangle &t = screw.triangles[tri];
        const double *sphere = screw.tree.bounding_sphere(tri);
        const double gap2 = (centre[0] - sphere[0]) * (centre[0] - sphere[0]) +
                            (centre[1] - sphere[1]) * (centre[1] - sphere[1]) +
                            (centre[2] - sphere[2]) * (centre[2] - sphere[2]);
        if (tmesh::out_of_reach(gap2, reach + sphere[3], signed_plane_distance(t, centre), sphere[3], reach,
                                kFilterSlack))
          return;
        const double offset = t.normal[0] * t.node[0][0] + t.normal[1] * t.node[0][1] + t.normal[2] * t.node[0][2];
        list.push_back({static_cast<int>(s),
                        tri,
                        {images[k][0], images[k][1], images[k][2]},
                        {static_cast<float>(sphere[0]), static_cast<float>(sphere[1]), static_cast<float>(sphere[2]),
                         static_cast<float>(sphere[3])},
                        {static_cast<float>(t.normal[0]), static_cast<float>(t.normal[1]),
                         static_cast<float>(t.normal[2]), static_cast<float>(offset)}});
      });
      // every triangle left out is farther than reach + skin (sphere, box or plane), and none is
      // nearer than the clearance
      const double clear =
          list.size() > before ? 0.0 : screw.tree.clearance(centre, cap + contact_reach) - contact_reach;
      margin = std::min(margin, std::max(skin, clear));
    }
    frame[3] = margin * margin;
  }
  // the order of fix wall/gran: mesh by mesh as listed, triangles by index (which contact of two
  // coplanar ones is kept depends on it)
  std::sort(list.begin(), list.end(), [&](const Candidate &a, const Candidate &b) {
    const int la = screws_[a.screw].list_index, lb = screws_[b.screw].list_index;
    if (la != lb) return la < lb;
    if (a.triangle != b.triangle) return a.triangle < b.triangle;
    return std::lexicographical_compare(a.image, a.image + 3, b.image, b.image + 3);
  });
  CandidateSpan &span = candidate_spans_[i];
  if (list.size() > span.capacity) {  // no room in its place: to the pool's end
    span.begin = candidate_pool_.size();
    span.capacity = static_cast<unsigned>(list.size());
    candidate_pool_.insert(candidate_pool_.end(), list.begin(), list.end());
  } else {
    std::copy(list.begin(), list.end(), candidate_pool_.begin() + span.begin);
  }
  span.count = static_cast<unsigned>(list.size());
}
