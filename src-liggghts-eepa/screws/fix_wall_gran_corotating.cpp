// fix wall/gran/corotating, the LIGGGHTS adapter: set-up, the per-step hooks, the output vector, what
// it reports of its contacts (tsg::WallContactSource) and its global restart data. The rest, by
// concern: corotating_arguments.cpp (the fix's keywords), corotating_geometry.cpp (the screws' triangles
// and the candidate lists), corotating_contacts.cpp (the contact engine), corotating_history.cpp (the
// per-particle contact history: migration and restart), corotating_output.cpp (screw dumps, cost
// report). See fix_wall_gran_corotating.h and docs/geometry.md, "Screws turned without moving meshes".
#include "fix_wall_gran_corotating.h"

#include <algorithm>
#include <cstring>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_mesh_surface.h"
#include "memory.h"
#include "tri_mesh.h"
#include "update.h"

using namespace LAMMPS_NS;
using namespace FixConst;

namespace tmesh = ::tsg::trimesh;

namespace {
constexpr int kOutputsPerScrew = 7;  // load values and the angle
}  // namespace

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

// fix_modify ID screw_dump N prefix: e.g. one dump at the current step before a `run 0` (the
// cases' snapshot.in). Takes effect at the next run's set-up.
int FixWallGranCorotating::modify_param(int narg, char **arg)
{
  if (narg < 1 || strcmp(arg[0], "screw_dump") != 0) return 0;
  if (narg < 3) fail("fix_modify screw_dump needs: N prefix");
  set_screw_dump(arg[1], arg[2]);
  return 3;
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

// Atoms are exchanged and reordered at re-neighbouring: the lists follow their particles after it.
void FixWallGranCorotating::pre_neighbor()
{
  FixWallGran::pre_neighbor();
  reindex_lists_ = true;
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
