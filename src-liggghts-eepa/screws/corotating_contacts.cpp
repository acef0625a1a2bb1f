// fix wall/gran/corotating: the contact engine, each step's contacts of the particles with the screws in
// the screws' frames, their forces by the granular wall model, and the contact bookkeeping
// (fix_wall_gran_corotating.h).
#include "fix_wall_gran_corotating.h"

#include <algorithm>
#include <cmath>

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "fix_mesh_surface.h"
#include "fix_wall_gran_base.h"
#include "force.h"
#include "neighbor.h"
#include "update.h"

using namespace LAMMPS_NS;
namespace rot = ::tsg::rotation;
namespace tmesh = ::tsg::trimesh;

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
  if (reindex_lists_ || static_cast<int>(candidate_spans_.size()) != nlocal) {
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
    const CandidateSpan span = candidate_spans_[i];
    const Candidate *const first = candidate_pool_.data() + span.begin;
    for (const Candidate *it = first; it != first + span.count; ++it) {
      const Candidate &cand = *it;
      Screw &s = screws_[cand.screw];
      // three comparisons, not std::equal: on chars it becomes a memcmp call (4 % of a step, perf)
      if (cand.screw != current_screw || cand.image[0] != current_image[0] || cand.image[1] != current_image[1] ||
          cand.image[2] != current_image[2]) {
        current_screw = cand.screw;
        std::copy(cand.image, cand.image + 3, current_image);
        lab = {x[i][0] + cand.image[0] * domain->prd[0], x[i][1] + cand.image[1] * domain->prd[1],
               x[i][2] + cand.image[2] * domain->prd[2]};
        const rot::Vec3 body = s.motion.to_body(poses[cand.screw], lab);
        centre[0] = body.x, centre[1] = body.y, centre[2] = body.z;
      }
      // the list was built with reach + skin: most candidates are out of reach now (bounding sphere;
      // then plane and bound circle together, which leaves out most neighbours of the touched triangle)
      const float *sphere = cand.sphere, *plane = cand.plane;
      const double gx = centre[0] - sphere[0], gy = centre[1] - sphere[1], gz = centre[2] - sphere[2];
      const double gap2 = gx * gx + gy * gy + gz * gz;
      const double limit = reach + sphere[3] + kFilterSlack;
      if (gap2 > limit * limit) continue;
      const double height = centre[0] * plane[0] + centre[1] * plane[1] + centre[2] * plane[2] - plane[3];
      if (tmesh::out_of_reach(gap2, limit, height, sphere[3], reach, kFilterSlack)) continue;
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
