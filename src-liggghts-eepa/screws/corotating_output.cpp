// fix wall/gran/corotating: the screw dumps (legacy VTK) and the cost report (fix_wall_gran_corotating.h).
#include "fix_wall_gran_corotating.h"

#include <mpi.h>

#include <filesystem>

#include "comm.h"
#include "error.h"
#include "update.h"

using namespace LAMMPS_NS;
namespace rot = ::tsg::rotation;
namespace tmesh = ::tsg::trimesh;

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
