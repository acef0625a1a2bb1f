// fix wall/gran/corotating: fix wall/gran whose screw meshes turn rigidly about their own axes
// without ever being moved. Contacts with a screw are found in the screw's own frame, where the mesh
// is at rest, with a static triangle tree and per-particle candidate lists; the contact geometry is
// rotated back to the lab frame and evaluated by the same granular wall model as fix wall/gran,
// with the surface velocity ω × r of the turning screw. The per-step cost therefore follows the
// particles near a screw, not its triangle count. Meshes named after `fixed` (the barrel) use the
// same static look-up without turning; the other meshes are handled exactly as by fix wall/gran.
//
//   fix ID group wall/gran/corotating <fix wall/gran arguments> &
//       corotate <mesh fix ID> origin x y z axis ax ay az period T [corotate ...] &
//       [fixed <mesh fix ID> ...] [max_contacts K (64)] [list_skin s] [screw_dump N prefix]
//       [restart_contacts keep|reset (keep)]
//
// Output vector, 7 values per corotating or fixed mesh s (in the order given): force on the screw (N, 3),
// torque on it about its origin (N m, 3), and its angle θ = ω t (rad, not wrapped).
// screw_dump writes each screw in its current pose every N steps as legacy VTK,
// <prefix>_<mesh ID>_<step>.vtk (rank 0); N = 0 writes none.
// What it reports of its contacts with the corotating and fixed meshes (tsg::WallContactSource;
// meshes left to fix wall/gran are not reported): the deepest contact per mesh since the last
// take_deepest() (every step counted) and each particle's meshes in contact, read by fix
// check/contact's guards; this step's contacts per particle (deepest δ/R, meshes touched, meshes
// whose surface its centre has crossed) and the screws' power on the particles, read by fix
// squeeze/ledger.
// Restart files keep each particle's screw contacts and their history; restart_contacts reset starts
// them all afresh instead (needed when the wall model, and so the history layout, changes).
// When deleted (end of input or unfix) the fix reports the time spent in its own contact handling
// per step (slowest rank) and how many candidate lists were built.
//
// The code, by concern: fix_wall_gran_corotating.cpp (the LIGGGHTS adapter), corotating_arguments.cpp,
// corotating_geometry.cpp (triangles, candidate lists), corotating_contacts.cpp (the contact engine),
// corotating_history.cpp (per-particle contact history), corotating_output.cpp (screw dumps, cost).
// Design: docs/geometry.md, "Screws turned without moving meshes"; measurements: docs/performance.md.
#ifdef FIX_CLASS

// clang-format off
FixStyle(wall/gran/corotating,FixWallGranCorotating)
// clang-format on

#else

#ifndef TSG_FIX_WALL_GRAN_COROTATING_H
#define TSG_FIX_WALL_GRAN_COROTATING_H

#include <string>
#include <vector>

#include "fix_wall_gran.h"
#include "neighbor.h"

#include "numbers.h"
#include "restart_clock.h"
#include "rigid_rotation.h"
#include "triangle_contact.h"
#include "triangle_lookup.h"
#include "wall_contact_source.h"

namespace LAMMPS_NS {

class FixWallGranCorotating : public FixWallGran, public tsg::WallContactSource {
public:
  FixWallGranCorotating(class LAMMPS *, int, char **);
  ~FixWallGranCorotating() override;

  void post_create() override;
  void init() override;
  void setup(int vflag) override;
  int setmask() override;
  void pre_neighbor() override;
  void post_force(int vflag) override;
  void end_of_step() override;
  int modify_param(int narg, char **arg) override;
  double compute_vector(int n) override;

  int wall_count() const override { return n_meshes(); }
  std::string wall_name(int wall) const override;
  const double *step_overlap_ratio() const override { return step_overlap_.data(); }
  const unsigned *step_walls_touched() const override { return step_touched_.data(); }
  const unsigned *step_walls_crossed() const override { return step_crossed_.data(); }
  double step_power() const override { return step_power_; }
  // the corotate and fixed meshes; the others go through the stock path of fix wall/gran
  bool reports_wall(int wall) const override { return screw_of_wall(wall) != nullptr; }
  DeepestContact take_deepest(int wall) override;
  unsigned walls_in_contact(int i) const override;

  void grow_arrays(int nmax) override;
  void copy_arrays(int i, int j, int delflag) override;
  void set_arrays(int i) override;
  int pack_exchange(int i, double *buf) override;
  int unpack_exchange(int nlocal, double *buf) override;
  int pack_restart(int i, double *buf) override;
  void unpack_restart(int nlocal, int nth) override;
  int size_restart(int nlocal) override;
  int maxsize_restart() override;
  void write_restart(FILE *fp) override;
  void restart(char *buf) override;
  double memory_usage() override;

private:
  static constexpr int kLoadValues = 6;  // force on a screw (3) and torque about its origin (3)
  // numbers in the set-up and restart messages: 6 significant digits (numbers.h)
  static std::string number(double v) { return tsg::number(v, tsg::NumberKind::setup); }

  // A screw triangle near one image of a particle, found with the reach plus the list skin;
  // reused until the particle has moved beyond its margin in the lab or in a screw's frame.
  // Its bounding sphere and plane are copied here (single precision, read with kFilterSlack): the
  // per-step reach tests then read the list in order instead of two arrays of the whole mesh.
  // Slack of the reach tests on a candidate, m: far above the rounding of its single-precision copies
  // (float coordinates of a machine of 0.1 m: 1e-8 m), far below a particle's radius, so that no
  // triangle within reach is ever skipped; survivors are tested in double precision.
  static constexpr double kFilterSlack = 1e-7;
  struct Candidate {
    int screw;
    int triangle;
    signed char image[3];  // periodic image: x + image · box length
    float sphere[4];       // centre (screw frame), radius
    float plane[4];        // unit normal, normal · node 0
  };
  struct Screw {
    std::string mesh_id;
    bool turning = true;                            // false: a 'fixed' mesh (ω = 0, no axis check)
    int list_index = -1;                            // position in FixMesh_list_
    tsg::rotation::RigidRotation motion;            // axis through origin, angular speed
    std::vector<tsg::trimesh::Triangle> triangles;  // in the screw's own frame (as given), sorted by mesh id
    tsg::trimesh::TriangleTree tree;
    tsg::trimesh::CompressedLists coplanar;
    double precision = 0.0;                         // the mesh's precision (fix mesh/surface)
    int key_offset = 0;                             // contact keys of this screw: key_offset + triangle index
    double load[kLoadValues] = {0, 0, 0, 0, 0, 0};  // force on the screw and torque about its origin, this rank
    double angle = 0.0;                             // θ at the last force evaluation
    DeepestContact deepest;                         // since the last take_deepest() (WallContactSource)
  };

  const Screw *screw_of_wall(int wall) const;
  // corotating_arguments.cpp
  static int wall_gran_arguments(int narg, char **arg);
  void parse_corotate(int narg, char **arg, int first);
  void add_mesh(Screw screw);
  void set_screw_dump(const char *every, const char *prefix);
  [[noreturn]] void fail(const std::string &message);
  // corotating_geometry.cpp
  void gather_triangles(Screw &screw);
  void check_shares_axis(const Screw &screw);
  void build_candidates(int i, const std::vector<tsg::rotation::Mat3> &poses);
  void follow_lists_to_new_indices(const std::vector<tsg::rotation::Mat3> &poses);
  // corotating_contacts.cpp
  void corotating_contacts();
  double *handle_contact(int i, const Screw &screw, int tri, bool face, bool &accepted);
  void mark_all_contacts();
  void clean_up_contacts();
  // corotating_output.cpp
  void write_screw_dumps();
  void report_cost();

  std::vector<Screw> screws_;
  // candidate lists per owned particle, valid until the particle has moved beyond its margin from
  // where its list was built (lab frame or a screw's frame; build_candidates says how far); they
  // follow their particle to its new local index after re-neighbouring. All lists share one pool,
  // laid out in particle order at each re-neighbouring so that the step reads it in sequence; a list
  // rebuilt longer than its place between re-neighbourings goes to the pool's end.
  struct CandidateSpan {
    size_t begin = 0;
    unsigned count = 0, capacity = 0;
  };
  std::vector<Candidate> candidate_pool_;
  std::vector<CandidateSpan> candidate_spans_;
  std::vector<Candidate> candidate_scratch_;  // the list being built
  // per particle: lab position and squared margin, then body position and squared margin per screw
  std::vector<double> built_at_;
  size_t built_stride() const { return 4 + 4 * screws_.size(); }
  std::vector<tagint> list_owner_;  // atom ID of each list (local indices change at re-neighbouring)
  bool reindex_lists_ = false;
  // cost report when the fix is deleted: time in its own contact handling, list builds
  double contact_seconds_ = 0.0;
  bigint timed_steps_ = 0, list_builds_ = 0;
  std::vector<class FixMeshSurface *> all_meshes_, static_meshes_;
  bool triangles_gathered_ = false;

  // the angle comes from the time elapsed since the fix was created (as fix move/mesh's), kept
  // across a restart
  tsg::RestartClock clock_;

  // contact history with screw triangles, per particle: up to max_contacts_ slots of
  // (key, dnum values); keys < 0 are free slots
  // per-particle capacity for contacts with the named meshes: a particle pressed into a finely
  // meshed curved surface touches many triangles at once (each one a contact, as in fix wall/gran)
  int max_contacts_ = 64;
  bool reset_restart_contacts_ = false;  // restart_contacts reset
  int most_contacts_ = 0;                // largest number of contacts of one particle seen (reported)
  // candidate lists hold triangles within reach + list skin; default half the neighbour skin (the
  // lists are rebuilt when a particle near a screw moves a list skin in its frame, where the screw's
  // turning moves every particle: docs/performance.md has the measured trade-off)
  double list_skin_ = 0.0;
  double list_skin() const { return list_skin_ > 0.0 ? list_skin_ : 0.5 * neighbor->skin; }
  int dump_every_ = 0;
  std::string dump_prefix_;
  std::vector<int> extensive_;
  int history_size_ = 0;
  int *contact_count_ = nullptr;
  int **contact_key_ = nullptr;
  double **contact_history_ = nullptr;
  char **contact_kept_ = nullptr;

  std::vector<double> load_all_;
  bigint load_step_ = -1;

  // this step's contacts per local particle and the screws' power (WallContactSource)
  std::vector<double> step_overlap_;
  std::vector<unsigned> step_touched_, step_crossed_;
  double step_power_ = 0.0;
};

}  // namespace LAMMPS_NS

#endif
#endif
