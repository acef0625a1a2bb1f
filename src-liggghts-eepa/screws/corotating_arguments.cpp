// fix wall/gran/corotating: its keywords after the fix wall/gran arguments (fix_wall_gran_corotating.h).
#include "fix_wall_gran_corotating.h"

#include <cmath>
#include <cstring>

#include "error.h"
#include "fix_mesh_surface.h"

#include "numbers.h"

using namespace LAMMPS_NS;
namespace rot = ::tsg::rotation;

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
