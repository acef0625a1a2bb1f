// fix wall/gran/corotating: see fix_wall_gran_corotating.h and docs/rotating-screws.md.
#include "fix_wall_gran_corotating.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <unordered_map>

#include "atom.h"
#include "comm.h"
#include "container.h"
#include "domain.h"
#include "error.h"
#include "fix_mesh_surface.h"
#include "fix_wall_gran_base.h"
#include "force.h"
#include "memory.h"
#include "neighbor.h"
#include "tri_mesh.h"
#include "update.h"

#include "gather.h"
#include "numbers.h"

using namespace LAMMPS_NS;
using namespace FixConst;
namespace rot = ::tsg::rotation;
namespace tmesh = ::tsg::trimesh;

namespace {
constexpr int kValuesPerTriangle = 32;  // id, nodes 9, edge units 9, edge lengths 3, normal 3, obtuse, active 6
constexpr int kOutputsPerScrew = 7;     // load values and the angle
// an empty candidate list stays valid for at most this many list skins of motion (a choice, not
// tuned: docs/performance.md)
constexpr double kFarMargins = 16.0;
// Slack of the single-precision reach tests on a candidate (Candidate::sphere, ::plane), m: far above
// their rounding (float coordinates of a machine of 0.1 m: 1e-8 m), far below a particle's radius, so
// that no triangle within reach is ever skipped; survivors are tested in double precision.
constexpr double kFilterSlack = 1e-7;
// LIGGGHTS' coplanarity threshold for mesh faces (SurfaceMesh: 1 − EPSILON_CURVATURE)
constexpr double kCoplanarCurvature = 1.0 - 1e-5;
// a corotating screw must be (close to) symmetric about its axis: the area centroid of its surface
// may lie at most this fraction of its largest radius from the axis
constexpr double kAxisTolerance = 0.01;
}  // namespace

// The arguments of fix wall/gran end where the first keyword of this fix starts.
int FixWallGranCorotating::wall_gran_arguments(int narg, char **arg)
{
  for (int i = 3; i < narg; ++i)
    if (strcmp(arg[i], "corotate") == 0 || strcmp(arg[i], "fixed") == 0 || strcmp(arg[i], "max_contacts") == 0 ||
        strcmp(arg[i], "screw_dump") == 0 || strcmp(arg[i], "list_skin") == 0 ||
        strcmp(arg[i], "restart_contacts") == 0)
      return i;
  return narg;
}

FixWallGranCorotating::FixWallGranCorotating(LAMMPS *lmp, int narg, char **arg)
    : FixWallGran(lmp, wall_gran_arguments(narg, arg), arg)
{
  if (!is_mesh_wall()) fail("needs mesh walls ('mesh n_meshes N meshes ...')");
  if (n_FixMesh_ > 32)
    fail("n_meshes = " + std::to_string(n_FixMesh_) + " is not allowed: at most 32 meshes (one bit each per particle)");
  parse_corotate(narg, arg, wall_gran_arguments(narg, arg));
  for (int i = 0; i < n_FixMesh_; ++i) all_meshes_.push_back(FixMesh_list_[i]);
  for (int i = 0; i < n_FixMesh_; ++i) {
    bool rotating = false;
    for (const Screw &s : screws_) rotating = rotating || s.list_index == i;
    if (!rotating) static_meshes_.push_back(FixMesh_list_[i]);
  }
  int offset = 0;
  for (Screw &s : screws_) s.key_offset = offset, offset += 1 << 26;  // room for 67 M triangles per screw
  if (screws_.size() > 30) fail("at most 30 corotating meshes are supported");
  load_all_.assign(kOutputsPerScrew * screws_.size(), 0.0);

  history_size_ = dnum();
  clock_.load(0.0, static_cast<double>(update->ntimestep));  // reads 0 at this step; a restart file overrides

  vector_flag = 1;
  size_vector = kOutputsPerScrew * static_cast<int>(screws_.size());
  global_freq = 1;
  extvector = -1;  // forces and torques are extensive, angles are not
  extensive_.assign(size_vector, 1);
  for (int s = 0; s < static_cast<int>(screws_.size()); ++s) extensive_[kOutputsPerScrew * s + 6] = 0;
  extlist = extensive_.data();
  restart_global = 1;
  restart_peratom = 1;
  create_attribute = 1;
  grow_arrays(atom->nmax);
  atom->add_callback(0);
  atom->add_callback(1);
  for (int i = 0; i < atom->nlocal; ++i) set_arrays(i);
}

FixWallGranCorotating::~FixWallGranCorotating()
{
  report_cost();
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(contact_count_);
  memory->destroy(contact_key_);
  memory->destroy(contact_history_);
  memory->destroy(contact_kept_);
}

void FixWallGranCorotating::fail(const std::string &message)
{
  error->all(FLERR, (std::string("fix ") + id + " wall/gran/corotating: " + message).c_str());
  throw;  // not reached: error->all exits
}

void FixWallGranCorotating::add_mesh(Screw screw)
{
  for (int i = 0; i < n_FixMesh_; ++i)
    if (screw.mesh_id == FixMesh_list_[i]->id) screw.list_index = i;
  if (screw.list_index < 0) fail("mesh '" + screw.mesh_id + "' is not one of the meshes of this wall");
  for (const Screw &other : screws_)
    if (other.list_index == screw.list_index) fail("mesh '" + screw.mesh_id + "' is named twice");
  screws_.push_back(screw);
}

void FixWallGranCorotating::parse_corotate(int narg, char **arg, int iarg)
{
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (key == "screw_dump") {
      if (iarg + 3 > narg) fail("screw_dump needs: N prefix");
      set_screw_dump(arg[iarg + 1], arg[iarg + 2]);
      iarg += 3;
      continue;
    }
    if (key == "list_skin") {
      if (iarg + 2 > narg) fail("list_skin needs a value");
      double v = 0.0;
      if (!tsg::scan_real(arg[iarg + 1], v) || !(v > 0.0) || !std::isfinite(v))
        fail(std::string("list_skin = ") + arg[iarg + 1] + " is not allowed: a length > 0 (m)");
      list_skin_ = v;
      iarg += 2;
      continue;
    }
    if (key == "max_contacts") {
      if (iarg + 2 > narg) fail("max_contacts needs a value");
      long k = 0;
      if (!tsg::parse_integer(arg[iarg + 1], 1, 1000, k))
        fail(std::string("max_contacts = ") + arg[iarg + 1] + " is not allowed: an integer from 1 to 1000");
      max_contacts_ = static_cast<int>(k);
      iarg += 2;
      continue;
    }
    if (key == "restart_contacts") {
      if (iarg + 2 > narg) fail("restart_contacts needs 'keep' or 'reset'");
      const std::string value = arg[iarg + 1];
      if (value != "keep" && value != "reset")
        fail("restart_contacts = '" + value +
             "' is not allowed: 'keep' (continue the contacts of a restart file) or "
             "'reset' (start every particle-wall contact afresh, e.g. after a change of wall model)");
      reset_restart_contacts_ = value == "reset";
      iarg += 2;
      continue;
    }
    if (key == "fixed") {
      if (iarg + 2 > narg) fail("fixed needs a mesh fix ID");
      Screw s;
      s.mesh_id = arg[iarg + 1];
      s.turning = false;
      s.motion = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, 0.0};
      add_mesh(s);
      iarg += 2;
      continue;
    }
    if (key != "corotate")
      fail("unknown keyword '" + key +
           "' after the wall/gran arguments (allowed: corotate, fixed, max_contacts, "
           "list_skin, screw_dump, restart_contacts)");
    if (iarg + 11 > narg) fail("corotate needs: <mesh fix ID> origin x y z axis ax ay az period T");
    Screw s;
    s.mesh_id = arg[iarg + 1];
    if (strcmp(arg[iarg + 2], "origin") || strcmp(arg[iarg + 6], "axis") || strcmp(arg[iarg + 10], "period"))
      fail("corotate " + s.mesh_id + ": expected 'origin x y z axis ax ay az period T'");
    auto value = [&](int k, const char *what) {
      double v = 0.0;
      if (!tsg::scan_real(arg[k], v) || !std::isfinite(v))
        fail("corotate " + s.mesh_id + ": " + what + " = '" + arg[k] + "' is not a finite number");
      return v;
    };
    s.motion.origin = {value(iarg + 3, "origin x"), value(iarg + 4, "origin y"), value(iarg + 5, "origin z")};
    rot::Vec3 axis{value(iarg + 7, "axis x"), value(iarg + 8, "axis y"), value(iarg + 9, "axis z")};
    const double length = rot::norm(axis);
    if (!(length > 0.0)) fail("corotate " + s.mesh_id + ": the axis (0, 0, 0) has no direction");
    s.motion.axis = (1.0 / length) * axis;
    if (iarg + 12 > narg) fail("corotate " + s.mesh_id + ": period needs a value");
    const double period = value(iarg + 11, "period");
    if (period == 0.0)
      fail("corotate " + s.mesh_id +
           ": period = 0 is not allowed (seconds per revolution, non-zero; "
           "negative turns the other way)");
    s.motion.omega = 2.0 * M_PI / period;  // as fix move/mesh rotate
    add_mesh(s);
    iarg += 12;
  }
  bool any_turning = false;
  for (const Screw &s : screws_) any_turning = any_turning || s.turning;
  if (!any_turning) fail("no 'corotate' mesh given: use fix wall/gran for walls that do not turn");
  if (track_energy_) fail("track_energy is not supported for corotating meshes");
  if (store_force_contact_ || store_force_contact_stress_)
    fail("store_force_contact and store_force_contact_stress are not supported for corotating meshes");
}

// FixWallGran creates a mesh neighbour list and a contact tracker for every mesh; a corotating
// screw uses neither (both would cost per triangle), so they are removed again.
void FixWallGranCorotating::post_create()
{
  FixWallGran::post_create();
  for (const Screw &s : screws_) {
    FixMesh_list_[s.list_index]->deleteWallNeighList();
    FixMesh_list_[s.list_index]->deleteContactHistory();
  }
}

void FixWallGranCorotating::init()
{
  FixWallGran::init();
  for (const Screw &s : screws_) {
    FixMeshSurface *mesh = all_meshes_[s.list_index];
    if (mesh->mesh()->isMoving())
      fail("mesh '" + s.mesh_id +
           "' is also moved by another fix (move/mesh); a corotating screw is turned "
           "by this fix alone and must not be moved otherwise");
    if (mesh->trackStress() || mesh->meshMulticontactData())
      fail("mesh '" + s.mesh_id +
           "': stress tracking and multicontact are not supported for corotating meshes "
           "(the screw's force and torque are this fix's output vector)");
  }
  if (cwl_) fail("compute wall/gran/local does not see corotating meshes");
}

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

void FixWallGranCorotating::setup(int vflag)
{
  if (!triangles_gathered_) {
    for (Screw &s : screws_) {
      gather_triangles(s);
      if (s.turning) check_shares_axis(s);
      s.tree.build(s.triangles);
    }
    triangles_gathered_ = true;
  }
  clock_.resume(update);
  FixWallGran::setup(vflag);
  if (dump_every_ > 0 && update->ntimestep % dump_every_ == 0) write_screw_dumps();
}

int FixWallGranCorotating::setmask()
{
  // always: fix_modify screw_dump can switch the dumps on after the fix is made
  return FixWallGran::setmask() | END_OF_STEP;
}

void FixWallGranCorotating::end_of_step()
{
  if (dump_every_ > 0 && update->ntimestep % dump_every_ == 0) write_screw_dumps();
}

// The interval and prefix of the screw dumps; nevery makes Modify call end_of_step only on dump
// steps (1 when the dumps are off: end_of_step then returns at once).
void FixWallGranCorotating::set_screw_dump(const char *every, const char *prefix)
{
  long n = 0;
  if (!tsg::parse_integer(every, 0, MAXSMALLINT, n))
    fail(std::string("screw_dump every = ") + every + " is not allowed: an integer >= 0 (0: no dumps)");
  dump_every_ = static_cast<int>(n);
  dump_prefix_ = prefix;
  nevery = dump_every_ > 0 ? dump_every_ : 1;
}

// fix_modify ID screw_dump N prefix: e.g. one dump at the current step before a `run 0` (the
// cases' snapshot.in). Takes effect at the next run's set-up.
int FixWallGranCorotating::modify_param(int narg, char **arg)
{
  if (narg < 1 || strcmp(arg[0], "screw_dump") != 0) return 0;
  if (narg < 3) fail("fix_modify screw_dump needs: N prefix");
  set_screw_dump(arg[1], arg[2]);
  return 3;
}

// Legacy VTK polydata of each screw in its pose at this step, written by rank 0 (every rank holds
// the whole screw).
void FixWallGranCorotating::write_screw_dumps()
{
  if (comm->me != 0) return;
  const double time = clock_.now(update);
  for (const Screw &s : screws_) {
    const std::string path =
        dump_prefix_ + "_" + s.mesh_id + "_" + std::to_string(static_cast<long long>(update->ntimestep)) + ".vtk";
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    std::error_code ignored;  // fopen reports the failure that matters
    if (!parent.empty()) std::filesystem::create_directories(parent, ignored);
    FILE *out = fopen(path.c_str(), "w");
    if (!out) error->one(FLERR, (std::string("fix ") + id + " wall/gran/corotating: cannot write " + path).c_str());
    const rot::Mat3 pose = rot::rotation_matrix(s.motion.axis, s.motion.angle(time));
    const size_t n = s.triangles.size();
    fprintf(out, "# vtk DataFile Version 2.0\n%s at step %lld, angle %.17g rad\nASCII\nDATASET POLYDATA\n",
            s.mesh_id.c_str(), static_cast<long long>(update->ntimestep), s.motion.angle(time));
    fprintf(out, "POINTS %zu double\n", 3 * n);
    for (const tmesh::Triangle &t : s.triangles)
      for (const auto &node : t.node) {
        const rot::Vec3 body{node[0], node[1], node[2]};
        const rot::Vec3 lab = s.motion.origin + pose.apply(body - s.motion.origin);
        fprintf(out, "%.17g %.17g %.17g\n", lab.x, lab.y, lab.z);
      }
    fprintf(out, "POLYGONS %zu %zu\n", n, 4 * n);
    for (size_t t = 0; t < n; ++t) fprintf(out, "3 %zu %zu %zu\n", 3 * t, 3 * t + 1, 3 * t + 2);
    fclose(out);
  }
}

void FixWallGranCorotating::post_force(int vflag)
{
  // the static meshes through the stock path of fix wall/gran
  FixMeshSurface **all = FixMesh_list_;  // owned by FixWallGran
  const int nall = n_FixMesh_;
  FixMesh_list_ = static_meshes_.data();
  n_FixMesh_ = static_cast<int>(static_meshes_.size());
  FixWallGran::post_force(vflag);
  FixMesh_list_ = all;
  n_FixMesh_ = nall;

  const double start = MPI_Wtime();
  corotating_contacts();
  contact_seconds_ += MPI_Wtime() - start;
  ++timed_steps_;
}

// Cost report, once for the fix's lifetime (a `run N every M` would otherwise report per chunk):
// time in this fix's own contact handling per step on the slowest rank, candidate lists built.
void FixWallGranCorotating::report_cost()
{
  double slowest = 0.0;
  MPI_Allreduce(&contact_seconds_, &slowest, 1, MPI_DOUBLE, MPI_MAX, world);
  double builds = static_cast<double>(list_builds_), builds_all = 0.0;
  MPI_Allreduce(&builds, &builds_all, 1, MPI_DOUBLE, MPI_SUM, world);
  int most = 0;
  MPI_Allreduce(&most_contacts_, &most, 1, MPI_INT, MPI_MAX, world);
  if (comm->me == 0 && timed_steps_ > 0) {
    char line[320];
    snprintf(line, sizeof line,
             "fix %s wall/gran/corotating: contact handling %.4g ms/step (slowest rank, %lld steps), "
             "%.0f candidate lists built, at most %d contacts of one particle (max_contacts %d)\n",
             id, 1e3 * slowest / static_cast<double>(timed_steps_), static_cast<long long>(timed_steps_), builds_all,
             most, max_contacts_);
    if (screen) fputs(line, screen);
    if (logfile) fputs(line, logfile);
  }
}

// Atoms are exchanged and reordered at re-neighbouring: the lists follow their particles after it.
void FixWallGranCorotating::pre_neighbor()
{
  FixWallGran::pre_neighbor();
  reindex_lists_ = true;
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
  std::vector<std::vector<Candidate>> lists(nlocal);
  std::vector<double> built(static_cast<size_t>(nlocal) * stride, 0.0);
  std::vector<tagint> owner(nlocal);
  std::vector<bool> fresh(nlocal, true);
  for (int i = 0; i < nlocal; ++i) {
    owner[i] = atom->tag[i];
    const auto found = old_index.find(atom->tag[i]);
    if (found == old_index.end()) continue;
    lists[i] = std::move(candidates_[found->second]);
    std::copy(&built_at_[found->second * stride], &built_at_[(found->second + 1) * stride], &built[i * stride]);
    fresh[i] = false;
  }
  candidates_ = std::move(lists);
  built_at_ = std::move(built);
  list_owner_ = std::move(owner);
  for (int i = 0; i < nlocal; ++i)
    if (fresh[i] && (atom->mask[i] & groupbit)) build_candidates(i, poses);
}

namespace {
// distance from p to the triangle's plane: a lower bound on its distance to the triangle
double plane_distance(const tmesh::Triangle &t, const double *p)
{
  return std::fabs((p[0] - t.node[0][0]) * t.normal[0] + (p[1] - t.node[0][1]) * t.normal[1] +
                   (p[2] - t.node[0][2]) * t.normal[2]);
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
  std::vector<Candidate> &list = candidates_[i];
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
        if (plane_distance(t, centre) > reach) return;
        const double *sphere = screw.tree.bounding_sphere(tri);
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
}

void FixWallGranCorotating::corotating_contacts()
{
  const int nlocal = atom->nlocal;
  double **x = atom->x, **f = atom->f, **torque = atom->torque;
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  const double touch_factor = neighbor->contactDistanceFactor - 1.0;  // contacts without overlap (cohesion)
  const double time = clock_.now(update);
  const size_t nscrews = screws_.size();
  const size_t stride = built_stride();

  std::vector<rot::Mat3> poses(nscrews);
  for (size_t s = 0; s < nscrews; ++s) {
    Screw &screw = screws_[s];
    std::fill(screw.load, screw.load + kLoadValues, 0.0);
    screw.angle = screw.motion.angle(time);
    poses[s] = rot::rotation_matrix(screw.motion.axis, screw.angle);
  }
  if (reindex_lists_ || static_cast<int>(candidates_.size()) != nlocal) {
    follow_lists_to_new_indices(poses);
    reindex_lists_ = false;
  }

  mark_all_contacts();
  if (step_overlap_.size() < static_cast<size_t>(atom->nmax)) {
    step_overlap_.resize(atom->nmax);
    step_touched_.resize(atom->nmax);
    step_crossed_.resize(atom->nmax);
  }
  std::fill(step_overlap_.begin(), step_overlap_.begin() + nlocal, 0.0);
  std::fill(step_touched_.begin(), step_touched_.begin() + nlocal, 0u);
  std::fill(step_crossed_.begin(), step_crossed_.begin() + nlocal, 0u);
  LIGGGHTS::ContactModels::SurfacesIntersectData sidata;
  sidata.is_wall = true;
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    // moved beyond its margin in the lab or in a screw's frame since the list was built: rebuild
    const double *built = &built_at_[static_cast<size_t>(i) * stride];
    auto beyond = [](const double *frame, const rot::Vec3 &now) {
      const double dx = frame[0] - now.x, dy = frame[1] - now.y, dz = frame[2] - now.z;
      return dx * dx + dy * dy + dz * dz > frame[3];
    };
    const rot::Vec3 xlab{x[i][0], x[i][1], x[i][2]};
    bool stale = beyond(built, xlab);
    for (size_t s = 0; s < nscrews && !stale; ++s)
      stale = beyond(built + 4 + 4 * s, screws_[s].turning ? screws_[s].motion.to_body(poses[s], xlab) : xlab);
    if (stale) build_candidates(i, poses);
    const double reach = radius[i] * std::max(1.0, neighbor->contactDistanceFactor);

    int current_screw = -1;
    signed char current_image[3] = {0, 0, 0};
    rot::Vec3 lab{0, 0, 0};
    double centre[3] = {0, 0, 0};
    for (const Candidate &cand : candidates_[i]) {
      Screw &s = screws_[cand.screw];
      if (cand.screw != current_screw || !std::equal(cand.image, cand.image + 3, current_image)) {
        current_screw = cand.screw;
        std::copy(cand.image, cand.image + 3, current_image);
        lab = {x[i][0] + cand.image[0] * domain->prd[0], x[i][1] + cand.image[1] * domain->prd[1],
               x[i][2] + cand.image[2] * domain->prd[2]};
        const rot::Vec3 body = s.motion.to_body(poses[cand.screw], lab);
        centre[0] = body.x, centre[1] = body.y, centre[2] = body.z;
      }
      // the list was built with reach + skin: most candidates are out of reach now
      const float *sphere = cand.sphere, *plane = cand.plane;
      const double gx = centre[0] - sphere[0], gy = centre[1] - sphere[1], gz = centre[2] - sphere[2];
      const double limit = reach + sphere[3] + kFilterSlack;
      if (gx * gx + gy * gy + gz * gz > limit * limit) continue;
      const double height = centre[0] * plane[0] + centre[1] * plane[1] + centre[2] * plane[2] - plane[3];
      if (std::fabs(height) > reach + kFilterSlack) continue;  // its plane is out of reach
      const tmesh::Contact c = tmesh::closest_feature(s.triangles[cand.triangle], centre, s.precision);
      if (c.feature == tmesh::Feature::none) continue;
      const double deltan = c.distance - radius[i];
      if (!(deltan <= 0.0 || deltan < touch_factor * radius[i])) continue;
      const bool intersect = deltan <= 0.0;
      if (-deltan > s.deepest.overlap_ratio * radius[i]) s.deepest = {-deltan / radius[i], atom->tag[i]};
      if (intersect) {
        const unsigned bit = 1u << s.list_index;
        step_overlap_[i] = std::max(step_overlap_[i], -deltan / radius[i]);
        step_touched_[i] |= bit;
        // the centre behind a face (the normals face the particles): pushed on, it goes through
        const double *normal = s.triangles[cand.triangle].normal;
        if (c.feature == tmesh::Feature::face &&
            c.delta[0] * normal[0] + c.delta[1] * normal[1] + c.delta[2] * normal[2] > 0.0)
          step_crossed_[i] |= bit;
      }
      bool accepted = false;
      double *history = handle_contact(i, s, cand.triangle, c.feature == tmesh::Feature::face, accepted);
      if (!accepted) continue;
      const rot::Mat3 &pose = poses[cand.screw];
      const rot::Vec3 delta = rot::RigidRotation::vector_to_lab(pose, {c.delta[0], c.delta[1], c.delta[2]});
      const rot::Vec3 v_surface = s.motion.surface_velocity(lab + delta);
      double v_wall[3] = {v_surface.x, v_surface.y, v_surface.z};
      atom_type_wall_ = all_meshes_[s.list_index]->atomTypeWall();
      sidata.i = i;
      sidata.radi = radius[i];
      sidata.deltan = -deltan;
      sidata.delta[0] = -delta.x;
      sidata.delta[1] = -delta.y;
      sidata.delta[2] = -delta.z;
      sidata.contact_history = history;
      sidata.mesh = nullptr;
      sidata.fix_mesh = all_meshes_[s.list_index];
      const double f_before[3] = {f[i][0], f[i][1], f[i][2]};
      const double t_before[3] = {torque[i][0], torque[i][1], torque[i][2]};
      impl->compute_force(this, sidata, intersect, v_wall, nullptr, s.list_index, nullptr, cand.triangle);
      // reaction on the screw: force −Δf, torque about the origin −[(x − p) × Δf + Δτ]
      const rot::Vec3 df{f[i][0] - f_before[0], f[i][1] - f_before[1], f[i][2] - f_before[2]};
      const rot::Vec3 dt{torque[i][0] - t_before[0], torque[i][1] - t_before[1], torque[i][2] - t_before[2]};
      const rot::Vec3 moment = rot::cross(lab - s.motion.origin, df) + dt;
      s.load[0] -= df.x, s.load[1] -= df.y, s.load[2] -= df.z;
      s.load[3] -= moment.x, s.load[4] -= moment.y, s.load[5] -= moment.z;
    }
  }
  // the power of the screws on the particles: ω · (torque of the contact forces on the particles)
  step_power_ = 0.0;
  for (const Screw &screw : screws_)
    if (screw.turning)
      step_power_ -= screw.motion.omega * (screw.motion.axis.x * screw.load[3] + screw.motion.axis.y * screw.load[4] +
                                           screw.motion.axis.z * screw.load[5]);
  clean_up_contacts();
}

// Contact bookkeeping as LIGGGHTS' mesh contact tracker: a known contact keeps its history; a new
// face contact is skipped when a coplanar neighbour of the triangle already has this step's contact,
// and otherwise inherits the history of a coplanar neighbour the particle touched before (sliding
// over a flat region is one contact, not a string of new ones).
double *FixWallGranCorotating::handle_contact(int i, const Screw &screw, int tri, bool face, bool &accepted)
{
  const int key = screw.key_offset + tri;
  int *keys = contact_key_[i];
  // the slots holding keys, at most contact_count_[i] of them, scanned until all were seen
  const int known = contact_count_[i];
  for (int k = 0, seen = 0; k < max_contacts_ && seen < known; ++k) {
    if (keys[k] < 0) continue;
    ++seen;
    if (keys[k] == key) {
      contact_kept_[i][k] = 1;
      accepted = true;
      return history_size_ ? &contact_history_[i][k * history_size_] : nullptr;
    }
  }
  auto is_coplanar_neighbour = [&](int other_key) {
    const int other = other_key - screw.key_offset;
    if (other < 0 || other >= static_cast<int>(screw.triangles.size())) return false;
    return std::binary_search(screw.coplanar.begin(tri), screw.coplanar.end(tri), other);
  };
  if (face)
    for (int k = 0, seen = 0; k < max_contacts_ && seen < known; ++k) {
      if (keys[k] < 0) continue;
      ++seen;
      if (contact_kept_[i][k] && is_coplanar_neighbour(keys[k])) {
        accepted = false;
        return nullptr;
      }
    }
  int slot = -1;
  for (int k = 0; k < max_contacts_ && slot < 0; ++k)
    if (keys[k] < 0) slot = k;
  if (slot < 0)
    error->one(FLERR, (std::string("fix ") + id + " wall/gran/corotating: particle " +
                       std::to_string(static_cast<long long>(atom->tag[i])) + " touches more than max_contacts = " +
                       std::to_string(max_contacts_) + " screw triangles at once; raise max_contacts")
                          .c_str());
  keys[slot] = key;
  contact_kept_[i][slot] = 1;
  ++contact_count_[i];
  most_contacts_ = std::max(most_contacts_, contact_count_[i]);
  double *history = history_size_ ? &contact_history_[i][slot * history_size_] : nullptr;
  if (history) {
    std::fill(history, history + history_size_, 0.0);
    if (face)
      for (int k = 0, seen = 0; k < max_contacts_ && seen < known; ++k) {
        if (k == slot || keys[k] < 0) continue;
        ++seen;
        if (is_coplanar_neighbour(keys[k]))
          std::copy(&contact_history_[i][k * history_size_], &contact_history_[i][(k + 1) * history_size_], history);
      }
  }
  accepted = true;
  return history;
}

// Only particles with contacts have marks to clear: a mark is set only with a key, and a key without
// a mark is freed at the end of the step (most particles touch no mesh; sweeping all max_contacts
// slots of every particle twice a step cost more than the contacts themselves: docs/performance.md).
void FixWallGranCorotating::mark_all_contacts()
{
  for (int i = 0; i < atom->nlocal; ++i)
    if (contact_count_[i] > 0) std::fill(contact_kept_[i], contact_kept_[i] + max_contacts_, 0);
}

void FixWallGranCorotating::clean_up_contacts()
{
  for (int i = 0; i < atom->nlocal; ++i) {
    int left = contact_count_[i];  // keys still to be seen
    for (int k = 0; k < max_contacts_ && left > 0; ++k) {
      if (contact_key_[i][k] < 0) continue;
      --left;
      if (contact_kept_[i][k]) continue;
      contact_key_[i][k] = -1;
      --contact_count_[i];
      if (history_size_)
        std::fill(&contact_history_[i][k * history_size_], &contact_history_[i][(k + 1) * history_size_], 0.0);
    }
  }
}

std::string FixWallGranCorotating::wall_name(int wall) const { return mesh_list()[wall]->id; }

const FixWallGranCorotating::Screw *FixWallGranCorotating::screw_of_wall(int wall) const
{
  for (const Screw &s : screws_)
    if (s.list_index == wall) return &s;
  return nullptr;
}

tsg::WallContactSource::DeepestContact FixWallGranCorotating::take_deepest(int wall)
{
  for (Screw &s : screws_)
    if (s.list_index == wall) {
      const DeepestContact deepest = s.deepest;
      s.deepest = DeepestContact{};
      return deepest;
    }
  return DeepestContact{};
}

// the meshes of the contact keys particle i holds (its contacts at the last force evaluation)
unsigned FixWallGranCorotating::walls_in_contact(int i) const
{
  unsigned walls = 0;
  for (const Screw &s : screws_)
    for (int k = 0; k < max_contacts_; ++k) {
      const int key = contact_key_[i][k];
      if (key >= s.key_offset && key < s.key_offset + static_cast<int>(s.triangles.size())) {
        walls |= 1u << s.list_index;
        break;
      }
    }
  return walls;
}

// [7 s + 0..2]: force on screw s (N); [7 s + 3..5]: torque on it about its origin (N m);
// [7 s + 6]: its angle (rad)
double FixWallGranCorotating::compute_vector(int n)
{
  if (load_step_ != update->ntimestep) {
    std::vector<double> mine(kOutputsPerScrew * screws_.size(), 0.0);
    for (size_t s = 0; s < screws_.size(); ++s)
      std::copy(screws_[s].load, screws_[s].load + kLoadValues, &mine[kOutputsPerScrew * s]);
    MPI_Allreduce(mine.data(), load_all_.data(), static_cast<int>(mine.size()), MPI_DOUBLE, MPI_SUM, world);
    for (size_t s = 0; s < screws_.size(); ++s) load_all_[kOutputsPerScrew * s + 6] = screws_[s].angle;
    load_step_ = update->ntimestep;
  }
  return load_all_[n];
}

// ---- per-particle contact history ------------------------------------------------------------------

void FixWallGranCorotating::grow_arrays(int nmax)
{
  memory->grow(contact_count_, nmax, "wall/gran/corotating:count");
  memory->grow(contact_key_, nmax, max_contacts_, "wall/gran/corotating:key");
  memory->grow(contact_history_, nmax, std::max(1, max_contacts_ * history_size_), "wall/gran/corotating:history");
  memory->grow(contact_kept_, nmax, max_contacts_, "wall/gran/corotating:kept");
}

void FixWallGranCorotating::copy_arrays(int i, int j, int)
{
  contact_count_[j] = contact_count_[i];
  std::copy(contact_key_[i], contact_key_[i] + max_contacts_, contact_key_[j]);
  std::copy(contact_kept_[i], contact_kept_[i] + max_contacts_, contact_kept_[j]);
  std::copy(contact_history_[i], contact_history_[i] + max_contacts_ * history_size_, contact_history_[j]);
}

void FixWallGranCorotating::set_arrays(int i)
{
  contact_count_[i] = 0;
  std::fill(contact_key_[i], contact_key_[i] + max_contacts_, -1);
  std::fill(contact_kept_[i], contact_kept_[i] + max_contacts_, 0);
  std::fill(contact_history_[i], contact_history_[i] + max_contacts_ * history_size_, 0.0);
}

// packed: count, then (key, history values) per contact
int FixWallGranCorotating::pack_exchange(int i, double *buf)
{
  int m = 0;
  buf[m++] = contact_count_[i];
  for (int k = 0; k < max_contacts_; ++k)
    if (contact_key_[i][k] >= 0) {
      buf[m++] = contact_key_[i][k];
      for (int h = 0; h < history_size_; ++h) buf[m++] = contact_history_[i][k * history_size_ + h];
    }
  return m;
}

int FixWallGranCorotating::unpack_exchange(int nlocal, double *buf)
{
  set_arrays(nlocal);
  int m = 0;
  const int count = static_cast<int>(buf[m++]);
  for (int k = 0; k < count; ++k) {
    contact_key_[nlocal][k] = static_cast<int>(buf[m++]);
    for (int h = 0; h < history_size_; ++h) contact_history_[nlocal][k * history_size_ + h] = buf[m++];
  }
  contact_count_[nlocal] = count;
  return m;
}

int FixWallGranCorotating::pack_restart(int i, double *buf)
{
  const int m = pack_exchange(i, buf + 1);
  buf[0] = m + 1;
  return m + 1;
}

void FixWallGranCorotating::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; ++i) m += static_cast<int>(extra[nlocal][m]);
  const int count = static_cast<int>(extra[nlocal][m + 1]);
  if (reset_restart_contacts_) {  // restart_contacts reset: the particle starts without wall contacts
    set_arrays(nlocal);
    contact_count_[nlocal] = 0;
    return;
  }
  if (count > max_contacts_)
    error->one(FLERR,
               (std::string("fix ") + id + " wall/gran/corotating: the restart file holds " + std::to_string(count) +
                " screw contacts for a particle, more than max_contacts = " + std::to_string(max_contacts_))
                   .c_str());
  unpack_exchange(nlocal, &extra[nlocal][m + 1]);
}

int FixWallGranCorotating::size_restart(int nlocal) { return 2 + contact_count_[nlocal] * (1 + history_size_); }

int FixWallGranCorotating::maxsize_restart() { return 2 + max_contacts_ * (1 + history_size_); }

// global: the elapsed time (the screws' phase) and the history layout
void FixWallGranCorotating::write_restart(FILE *fp)
{
  double list[4] = {0.0, 0.0, static_cast<double>(history_size_), static_cast<double>(screws_.size())};
  clock_.save(update, &list[0], &list[1]);
  if (comm->me == 0) {
    int size = static_cast<int>(sizeof list);
    fwrite(&size, sizeof(int), 1, fp);
    fwrite(list, sizeof(double), 4, fp);
  }
}

void FixWallGranCorotating::restart(char *buf)
{
  const double *list = reinterpret_cast<const double *>(buf);
  if (static_cast<size_t>(list[3]) != screws_.size() ||
      (static_cast<int>(list[2]) != history_size_ && !reset_restart_contacts_))
    fail("the restart file was written with " + number(list[3]) + " corotating meshes and " + number(list[2]) +
         " history values per contact; this input has " + std::to_string(screws_.size()) + " and " +
         std::to_string(history_size_) +
         " (another wall model: 'restart_contacts reset' starts every particle-wall contact afresh)");
  if (comm->me == 0 && reset_restart_contacts_)
    error->message(FLERR, (std::string("fix ") + id +
                           " wall/gran/corotating: restart_contacts reset: every "
                           "particle-wall contact of the restart file starts afresh")
                              .c_str());
  clock_.load(list[0], list[1]);
}

double FixWallGranCorotating::memory_usage()
{
  double bytes =
      static_cast<double>(atom->nmax) * max_contacts_ * (sizeof(int) + sizeof(char) + history_size_ * sizeof(double));
  for (const Screw &s : screws_)
    bytes += s.triangles.size() * sizeof(tmesh::Triangle) + s.tree.memory_bytes() +
             s.coplanar.items.size() * sizeof(int) + s.coplanar.offsets.size() * sizeof(std::int64_t);
  return bytes;
}
