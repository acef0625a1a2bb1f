// The normal force of a contact on its surfaces, as LIGGGHTS' normal models apply it: against a wall,
// scaled by the contact's area ratio and on the particle only; between particles, +F on i and -F on j
// along the contact normal. Shared by our normal models (normal_model_eepa.h, normal_model_yield.h).
#ifndef TSG_NORMAL_FORCE_H
#define TSG_NORMAL_FORCE_H

namespace tsg {

// Intersect: LIGGGHTS::ContactModels::SurfacesIntersectData; Forces: its ForceData.
template <class Intersect, class Forces>
inline void apply_normal_force(const Intersect &sidata, Forces &i_forces, Forces &j_forces, double normal_force)
{
  const double fn = sidata.is_wall ? normal_force * sidata.area_ratio : normal_force;
  i_forces.delta_F[0] += fn * sidata.en[0];
  i_forces.delta_F[1] += fn * sidata.en[1];
  i_forces.delta_F[2] += fn * sidata.en[2];
  if (!sidata.is_wall) {
    j_forces.delta_F[0] -= fn * sidata.en[0];
    j_forces.delta_F[1] -= fn * sidata.en[1];
    j_forces.delta_F[2] -= fn * sidata.en[2];
  }
}

}  // namespace tsg

#endif
