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

#include "contact_models.h"
#include "eepa_properties.h"
#include "force.h"
#include "global_properties.h"
#include "normal_model_base.h"
#include "update.h"

#include "eepa_law.h"
#include "normal_force.h"

namespace LIGGGHTS {
namespace ContactModels {

template <>
class NormalModel<EEPA> : public NormalModelBase {
public:
  NormalModel(LAMMPS *lmp, IContactHistorySetup *hsetup, class ContactModelBase *)
      : NormalModelBase(lmp, hsetup, nullptr)
  {
    // Scalars: flag "0" keeps LIGGGHTS from negating them for the partner atom on exchange.
    max_overlap_offset_ = hsetup->add_history_value("eepa_max_overlap", "0");
    plastic_overlap_offset_ = hsetup->add_history_value("eepa_plastic_overlap", "0");
    last_touch_step_offset_ = hsetup->add_history_value("eepa_last_touch_step", "0");
  }

  void registerSettings(Settings &settings) override
  {
    settings.registerOnOff("tangential_damping", tangential_damping_, true);
  }

  void postSettings(IContactHistorySetup *, ContactModelBase *) override {}

  void connectToProperties(PropertyRegistry &registry) override
  {
    registry.registerProperty("Yeff", &MODEL_PARAMS::createYeff, "model eepa");
    registry.registerProperty("betaeff", &MODEL_PARAMS::createBetaEff, "model eepa");
    registry.connect("Yeff", Yeff_, "model eepa");
    registry.connect("betaeff", betaeff_, "model eepa");
    eepa_properties_.connect(registry, "model eepa");
  }

  // Used by heat conduction to scale the contact area: the loading-branch exponent.
  double stressStrainExponent() override { return eepa_properties_.slope_exponent_for_heat(); }

  void surfacesIntersect(SurfacesIntersectData &sidata, ForceData &i_forces, ForceData &j_forces) override
  {
    if (sidata.contact_flags) *sidata.contact_flags |= CONTACT_NORMAL_MODEL;
    const int itype = sidata.itype;
    const int jtype = sidata.jtype;
    const double reff = sidata.is_wall ? sidata.radi : sidata.radi * sidata.radj / (sidata.radi + sidata.radj);
    const tsg::eepa::Parameters law = eepa_properties_.parameters(Yeff_[itype][jtype], reff, itype, jtype);

    // A contact starts virgin (docs/model.md, "A contact that re-forms starts virgin"). LIGGGHTS calls this function
    // only while the surfaces overlap and keeps a pair's history until the next neighbour rebuild (with
    // contact_distance_factor > 1 even across rebuilds), so a separation is detected here: a
    // contact not evaluated on the previous step has been apart in between.
    double *history = sidata.contact_history;
    const double step = static_cast<double>(update->ntimestep);
    const bool touched_last_step = history[last_touch_step_offset_] >= step - 1;
    const tsg::eepa::History previous =
        touched_last_step ? tsg::eepa::History{history[max_overlap_offset_], history[plastic_overlap_offset_]}
                          : tsg::eepa::History{};
    const tsg::eepa::State state =
        tsg::eepa::evaluate(law, previous, sidata.deltan, eepa_properties_.plastic_root(itype, jtype));
    if (sidata.computeflag && sidata.shearupdate) {
      history[max_overlap_offset_] = state.history.max_overlap;
      history[plastic_overlap_offset_] = state.history.plastic_overlap;
      history[last_touch_step_offset_] = step;
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

  // Apart but within contact_distance_factor: not a contact, so the pair's history need not
  // survive a neighbour rebuild (the reset itself happens on the next touch, above).
  void surfacesClose(SurfacesCloseData &scdata, ForceData &, ForceData &) override
  {
    if (scdata.contact_flags) *scdata.contact_flags &= ~CONTACT_NORMAL_MODEL;
  }

  void beginPass(SurfacesIntersectData &, ForceData &, ForceData &) override {}
  void endPass(SurfacesIntersectData &, ForceData &, ForceData &) override {}

private:
  double **Yeff_ = nullptr;
  double **betaeff_ = nullptr;
  bool tangential_damping_ = true;
  int max_overlap_offset_ = -1;
  int plastic_overlap_offset_ = -1;
  int last_touch_step_offset_ = -1;
  tsg::EepaProperties eepa_properties_;
};

}  // namespace ContactModels
}  // namespace LIGGGHTS

#endif
#endif
