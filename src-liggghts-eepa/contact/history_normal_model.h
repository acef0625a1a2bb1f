// What our normal models with a per-contact history (normal_model_eepa.h, normal_model_yield.h)
// share as LIGGGHTS normal models: the tangential_damping setting, the step of a contact's last
// evaluation (a contact not evaluated on the previous step has been apart in between and starts
// virgin), the effective radius, and the hooks of the interface that neither needs.
// contact_models.h comes before the guard: it includes our normal models, which include this header
// and need the class below, so included on its own this header must let them define it.
#include "contact_models.h"

#ifndef TSG_HISTORY_NORMAL_MODEL_H
#define TSG_HISTORY_NORMAL_MODEL_H

#include "global_properties.h"
#include "normal_model_base.h"
#include "update.h"

namespace LIGGGHTS {
namespace ContactModels {

class HistoryNormalModel : public NormalModelBase {
public:
  void registerSettings(Settings &settings) override
  {
    settings.registerOnOff("tangential_damping", tangential_damping_, true);
  }

  void postSettings(IContactHistorySetup *, ContactModelBase *) override {}

  // Apart but within contact_distance_factor: not a contact, so the pair's history need not
  // survive a neighbour rebuild (the reset itself happens on the next touch).
  void surfacesClose(SurfacesCloseData &scdata, ForceData &, ForceData &) override
  {
    if (scdata.contact_flags) *scdata.contact_flags &= ~CONTACT_NORMAL_MODEL;
  }

  void beginPass(SurfacesIntersectData &, ForceData &, ForceData &) override {}
  void endPass(SurfacesIntersectData &, ForceData &, ForceData &) override {}

protected:
  HistoryNormalModel(LAMMPS *lmp, IContactHistorySetup *hsetup) : NormalModelBase(lmp, hsetup, nullptr) {}

  // The derived constructor adds its history values in its own order (restart files keep that
  // order), the step of the last evaluation among them: this registers that one.
  void add_last_touch_step(IContactHistorySetup *hsetup, const char *name)
  {
    last_touch_step_offset_ = hsetup->add_history_value(name, "0");  // "0": not negated on exchange
  }

  // LIGGGHTS calls surfacesIntersect only while the surfaces overlap and keeps a pair's history
  // until the next neighbour rebuild (with contact_distance_factor > 1 even across rebuilds), so a
  // separation shows as a contact not evaluated on the previous step.
  bool touched_last_step(const double *history) const
  {
    return history[last_touch_step_offset_] >= static_cast<double>(update->ntimestep) - 1;
  }
  void mark_touched(double *history) const
  {
    history[last_touch_step_offset_] = static_cast<double>(update->ntimestep);
  }

  // Young's modulus and the damping factor β per type pair (Yeff, betaeff): every model of ours uses both.
  void connect_stiffness_and_damping(PropertyRegistry &registry, const char *caller)
  {
    registry.registerProperty("Yeff", &MODEL_PARAMS::createYeff, caller);
    registry.registerProperty("betaeff", &MODEL_PARAMS::createBetaEff, caller);
    registry.connect("Yeff", Yeff_, caller);
    registry.connect("betaeff", betaeff_, caller);
  }

  static double effective_radius(const SurfacesIntersectData &sidata)
  {
    return sidata.is_wall ? sidata.radi : sidata.radi * sidata.radj / (sidata.radi + sidata.radj);
  }

  bool tangential_damping_ = true;
  double **Yeff_ = nullptr;
  double **betaeff_ = nullptr;

private:
  int last_touch_step_offset_ = -1;
};

}  // namespace ContactModels
}  // namespace LIGGGHTS

#endif
