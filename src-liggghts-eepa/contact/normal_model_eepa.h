// LIGGGHTS adapter for the EEPA normal contact law (physics/eepa_law.h).
//
//   pair_style gran model eepa tangential history rolling_friction cdt
//
// This file only connects the law to LIGGGHTS: per-type-pair parameters, the per-contact history,
// the dashpot and the forces. The law, its sources and every modelling choice: docs/model.md.
#ifdef NORMAL_MODEL
// clang-format off
NORMAL_MODEL(EEPA,eepa,20)
// clang-format on
#else
#ifndef TSG_NORMAL_MODEL_EEPA_H
#define TSG_NORMAL_MODEL_EEPA_H

#include <cmath>
#include <stdexcept>
#include <string>

#include "eepa_properties.h"
#include "force.h"

#include "eepa_law.h"
#include "history_normal_model.h"
#include "normal_force.h"

namespace LIGGGHTS {
namespace ContactModels {

template <>
class NormalModel<EEPA> : public HistoryNormalModel {
public:
  NormalModel(LAMMPS *lmp, IContactHistorySetup *hsetup, class ContactModelBase *) : HistoryNormalModel(lmp, hsetup)
  {
    // Scalars: flag "0" keeps LIGGGHTS from negating them for the partner atom on exchange.
    max_overlap_offset_ = hsetup->add_history_value("eepa_max_overlap", "0");
    plastic_overlap_offset_ = hsetup->add_history_value("eepa_plastic_overlap", "0");
    add_last_touch_step(hsetup, "eepa_last_touch_step");
  }

  void connectToProperties(PropertyRegistry &registry) override
  {
    connect_stiffness_and_damping(registry, "model eepa");
    eepa_properties_.connect(registry, "model eepa");
  }

  // Used by heat conduction to scale the contact area: the loading-branch exponent.
  double stressStrainExponent() override { return eepa_properties_.slope_exponent_for_heat(); }

  void surfacesIntersect(SurfacesIntersectData &sidata, ForceData &i_forces, ForceData &j_forces) override
  {
    if (sidata.contact_flags) *sidata.contact_flags |= CONTACT_NORMAL_MODEL;
    const int itype = sidata.itype;
    const int jtype = sidata.jtype;
    const tsg::eepa::Parameters law =
        eepa_properties_.parameters(Yeff_[itype][jtype], effective_radius(sidata), itype, jtype);

    // A contact apart in between starts virgin (docs/model.md, "A contact that re-forms starts virgin").
    double *history = sidata.contact_history;
    const tsg::eepa::History previous =
        touched_last_step(history) ? tsg::eepa::History{history[max_overlap_offset_], history[plastic_overlap_offset_]}
                                   : tsg::eepa::History{};
    const tsg::eepa::State state =
        tsg::eepa::evaluate(law, previous, sidata.deltan, eepa_properties_.plastic_root(itype, jtype));
    if (sidata.computeflag && sidata.shearupdate) {
      history[max_overlap_offset_] = state.history.max_overlap;
      history[plastic_overlap_offset_] = state.history.plastic_overlap;
      mark_touched(history);
    }

    // dashpot with the active branch's tangent stiffness; LIGGGHTS' vn is -dδ/dt
    const double beta = betaeff_[itype][jtype];
    const double gamman = tsg::eepa::damping_coefficient(beta, state.stiffness, sidata.meff);
    const double damping = -gamman * sidata.vn;
    const double normal_force = state.force + damping;

    // Tangential spring: ζ_tm times the normal tangent stiffness, Hertz-Mindlin dashpot on it.
    const double multiplier = eepa_properties_.tangential_multiplier(itype, jtype);
    const double kt = multiplier * state.stiffness;
    sidata.kt = kt / force->nktv2p;
    sidata.gammat = tangential_damping_ ? std::sqrt(multiplier) * gamman : 0.0;  // same β on k_t
    sidata.gamman = gamman;
    // Friction and CDT rolling resistance see the adhesion-corrected load (Thakur 2014):
    // tangential history uses |Fn|, CDT rolling uses kn·δ.
    sidata.Fn = state.coulomb_load + damping;
    sidata.kn = state.coulomb_load / sidata.deltan;

    tsg::apply_normal_force(sidata, i_forces, j_forces, normal_force);
  }

private:
  int max_overlap_offset_ = -1;
  int plastic_overlap_offset_ = -1;
  tsg::EepaProperties eepa_properties_;
};

}  // namespace ContactModels
}  // namespace LIGGGHTS

#endif
#endif
