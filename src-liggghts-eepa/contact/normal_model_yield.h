// LIGGGHTS adapter for Hertz contact with a limiting contact pressure (physics/yield_law.h): the
// squeeze treatment of docs/stability.md.
//
//   fix walls all wall/gran/corotating model yield tangential history rolling_friction cdt ...
//   fix m5 all property/global yieldPressure peratomtypepair N p_11 ... (Pa, > 0)
//
// Below the yield pressure the force, the dashpot (restitution through betaeff) and Mindlin's
// tangential stiffness 8 G* a are those of model hertz; beyond it the pressure stays at p_y, and
// the work done beyond yield is dissipated (Thornton & Ning 1998). The per-contact history is
// the law's: largest overlap and force, plastic overlap, unloading radius.
#ifdef NORMAL_MODEL
// clang-format off
NORMAL_MODEL(YIELD,yield,21)
// clang-format on
#else
#ifndef TSG_NORMAL_MODEL_YIELD_H
#define TSG_NORMAL_MODEL_YIELD_H

#include <cmath>
#include <stdexcept>
#include <string>

#include "error.h"
#include "force.h"
#include "global_properties.h"

#include "history_normal_model.h"
#include "normal_force.h"
#include "yield_law.h"

namespace LIGGGHTS {
namespace ContactModels {

template <>
class NormalModel<YIELD> : public HistoryNormalModel {
public:
  static constexpr char kYieldPressure[] = "yieldPressure";  // p_y, Pa, > 0

  NormalModel(LAMMPS *lmp, IContactHistorySetup *hsetup, class ContactModelBase *) : HistoryNormalModel(lmp, hsetup)
  {
    // scalars: flag "0" keeps LIGGGHTS from negating them for the partner atom on exchange
    max_overlap_offset_ = hsetup->add_history_value("yield_max_overlap", "0");
    max_force_offset_ = hsetup->add_history_value("yield_max_force", "0");
    plastic_overlap_offset_ = hsetup->add_history_value("yield_plastic_overlap", "0");
    unload_radius_offset_ = hsetup->add_history_value("yield_unload_radius", "0");
    add_last_touch_step(hsetup, "yield_last_touch_step");
  }

  void connectToProperties(PropertyRegistry &registry) override
  {
    connect_stiffness_and_damping(registry, "model yield");
    registry.registerProperty("Geff", &MODEL_PARAMS::createGeff, "model yield");
    registry.registerProperty(kYieldPressure, &create_yield_pressure, "model yield");
    registry.connect("Geff", Geff_, "model yield");
    registry.connect(kYieldPressure, yield_pressure_, "model yield");
    const int ntypes = registry.max_type();
    for (int i = 1; i <= ntypes; ++i)
      for (int j = 1; j <= ntypes; ++j) {
        const double p = yield_pressure_[i][j];
        if (!(p > 0 && std::isfinite(p))) {
          const std::string message = "model yield, atom types " + std::to_string(i) + " " + std::to_string(j) + ": " +
                                      kYieldPressure + " = " + std::to_string(p) +
                                      " is outside the allowed range (0, inf) Pa (the limiting contact pressure p_y)";
          registry.getLAMMPS()->error->all(FLERR, message.c_str());
        }
      }
  }

  double stressStrainExponent() override { return 1.5; }

  void surfacesIntersect(SurfacesIntersectData &sidata, ForceData &i_forces, ForceData &j_forces) override
  {
    if (sidata.contact_flags) *sidata.contact_flags |= CONTACT_NORMAL_MODEL;
    const int itype = sidata.itype;
    const int jtype = sidata.jtype;
    const tsg::yield::Parameters law{Yeff_[itype][jtype], effective_radius(sidata), yield_pressure_[itype][jtype]};

    // a contact apart in between starts virgin
    double *history = sidata.contact_history;
    tsg::yield::History previous;
    if (touched_last_step(history)) {
      previous.max_overlap = history[max_overlap_offset_];
      previous.max_force = history[max_force_offset_];
      previous.plastic_overlap = history[plastic_overlap_offset_];
      previous.unload_radius = history[unload_radius_offset_];
    }
    const tsg::yield::State state = tsg::yield::evaluate(law, previous, sidata.deltan);
    if (sidata.computeflag && sidata.shearupdate) {
      history[max_overlap_offset_] = state.history.max_overlap;
      history[max_force_offset_] = state.history.max_force;
      history[plastic_overlap_offset_] = state.history.plastic_overlap;
      history[unload_radius_offset_] = state.history.unload_radius;
      mark_touched(history);
    }

    // model hertz's dashpot and tangential stiffness, on the active branch's contact radius
    constexpr double kSqrtFiveOverSix = 0.91287092917527685576;
    const double normal_stiffness = state.stiffness;  // 2 E* a
    const double tangential_stiffness = 8.0 * Geff_[itype][jtype] * state.contact_radius;
    const double beta = betaeff_[itype][jtype];
    const double gamman = -2.0 * kSqrtFiveOverSix * beta * std::sqrt(normal_stiffness * sidata.meff);
    const double gammat =
        tangential_damping_ ? -2.0 * kSqrtFiveOverSix * beta * std::sqrt(tangential_stiffness * sidata.meff) : 0.0;
    const double normal_force = state.force - gamman * sidata.vn;

    sidata.Fn = normal_force;
    sidata.kn = sidata.deltan > 0 ? state.force / sidata.deltan / force->nktv2p : 0.0;  // CDT rolling: kn·δ
    sidata.kt = tangential_stiffness / force->nktv2p;
    sidata.gamman = gamman;
    sidata.gammat = gammat;

    tsg::apply_normal_force(sidata, i_forces, j_forces, normal_force);
  }

private:
  static ::MatrixProperty *create_yield_pressure(::PropertyRegistry &registry, const char *caller, bool)
  {
    return MODEL_PARAMS::createPerTypePairProperty(registry, kYieldPressure, caller);
  }

  double **Geff_ = nullptr;
  double **yield_pressure_ = nullptr;
  int max_overlap_offset_ = -1;
  int max_force_offset_ = -1;
  int plastic_overlap_offset_ = -1;
  int unload_radius_offset_ = -1;
};

}  // namespace ContactModels
}  // namespace LIGGGHTS

#endif
#endif
