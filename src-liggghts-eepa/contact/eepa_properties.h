// EEPA material parameters in LIGGGHTS: read per type pair from `fix property/global` and
// validated here, the one place they enter the code. Names and units (seed paper symbols):
//
//   plasticityRatio                 λp   [-]     in [0, 1)    k2 = k1/(1 - λp)
//   pullOffForce                    f0   [N]     <= 0         constant attraction from first touch
//   surfaceEnergy                   Δγ   [J/m²]  >= 0         stress-history-dependent pull-off
//   slopeExponent                   n    [-]     >= 1         loading/unloading branch exponent
//   tensionExponent                 X    [-]     >= 1         adhesive branch exponent
//   tangentialStiffnessMultiplier   ζ_tm [-]     > 0          k_t = ζ_tm · dF/dδ
//
// The loading stiffness is derived from youngsModulus/poissonsRatio (Yeff = E*):
//   k1 = (4/3) E* R*^(2-n)        (Hertz for n = 1.5; equal to the Hertz force at δ = R* otherwise)
#ifndef TSG_EEPA_PROPERTIES_H
#define TSG_EEPA_PROPERTIES_H

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "error.h"
#include "global_properties.h"
#include "lammps.h"
#include "property_registry.h"

#include "eepa_law.h"
#include "numbers.h"

namespace tsg {

class EepaProperties {
public:
  static constexpr char kPlasticityRatio[] = "plasticityRatio";
  static constexpr char kPullOffForce[] = "pullOffForce";
  static constexpr char kSurfaceEnergy[] = "surfaceEnergy";
  static constexpr char kSlopeExponent[] = "slopeExponent";
  static constexpr char kTensionExponent[] = "tensionExponent";
  static constexpr char kTangentialMultiplier[] = "tangentialStiffnessMultiplier";

  void connect(::PropertyRegistry &registry, const char *caller)
  {
    registry.registerProperty(kPlasticityRatio, &create<kPlasticityRatio>);
    registry.registerProperty(kPullOffForce, &create<kPullOffForce>);
    registry.registerProperty(kSurfaceEnergy, &create<kSurfaceEnergy>);
    registry.registerProperty(kSlopeExponent, &create<kSlopeExponent>);
    registry.registerProperty(kTensionExponent, &create<kTensionExponent>);
    registry.registerProperty(kTangentialMultiplier, &create<kTangentialMultiplier>);
    registry.connect(kPlasticityRatio, plasticity_ratio_, caller);
    registry.connect(kPullOffForce, pull_off_force_, caller);
    registry.connect(kSurfaceEnergy, surface_energy_, caller);
    registry.connect(kSlopeExponent, slope_exponent_, caller);
    registry.connect(kTensionExponent, tension_exponent_, caller);
    registry.connect(kTangentialMultiplier, tangential_multiplier_, caller);
    validate_all(registry.getLAMMPS(), registry.max_type());
    const int ntypes = registry.max_type();
    plastic_root_.assign(ntypes + 1, std::vector<double>(ntypes + 1, 0.0));
    for (int i = 1; i <= ntypes; ++i)
      for (int j = 1; j <= ntypes; ++j)
        plastic_root_[i][j] = tsg::eepa::plastic_root(plasticity_ratio_[i][j], slope_exponent_[i][j]);
  }

  // Law parameters of one contact: Yeff = E* of the type pair, reff = R*.
  tsg::eepa::Parameters parameters(double yeff, double reff, int itype, int jtype) const
  {
    const double n = slope_exponent_[itype][jtype];
    const double radius_factor = n == 1.5 ? std::sqrt(reff) : std::pow(reff, 2.0 - n);
    return {4.0 / 3.0 * yeff * radius_factor, plasticity_ratio_[itype][jtype], n,   tension_exponent_[itype][jtype],
            pull_off_force_[itype][jtype],    surface_energy_[itype][jtype],   reff};
  }

  // λp^(1/n) of the type pair, computed once at set-up (tsg::eepa::plastic_root)
  double plastic_root(int itype, int jtype) const { return plastic_root_[itype][jtype]; }

  double tangential_multiplier(int itype, int jtype) const { return tangential_multiplier_[itype][jtype]; }

  // LIGGGHTS asks one exponent of the whole model (heat conduction only): that of type pair 1-1.
  double slope_exponent_for_heat() const { return slope_exponent_ ? slope_exponent_[1][1] : 1.5; }

private:
  template <const char *Name>
  static ::MatrixProperty *create(::PropertyRegistry &registry, const char *caller, bool)
  {
    return MODEL_PARAMS::createPerTypePairProperty(registry, Name, caller);
  }

  // Every type pair goes through the law's own validation; its parameter names are mapped to
  // the property names a user writes in the input script.
  void validate_all(LAMMPS_NS::LAMMPS *lmp, int ntypes) const
  {
    for (int i = 1; i <= ntypes; ++i)
      for (int j = 1; j <= ntypes; ++j) {
        std::string problem;
        const double multiplier = tangential_multiplier_[i][j];
        if (!(multiplier > 0 && std::isfinite(multiplier))) {
          problem = std::string(kTangentialMultiplier) + " = " + tsg::number(multiplier, tsg::NumberKind::parameter) +
                    " is outside the allowed range (0, inf)";  // formatted as the law formats the others
        } else {
          try {
            // k1 and R* are placeholders: they are derived, not user input
            tsg::eepa::Parameters p = parameters(1.0, 1.0, i, j);
            tsg::eepa::validate(p);
          } catch (const std::invalid_argument &e) {
            problem = rename(e.what());
          }
        }
        if (!problem.empty()) {
          const std::string message =
              "model eepa, atom types " + std::to_string(i) + " " + std::to_string(j) + ": " + problem;
          lmp->error->all(FLERR, message.c_str());
        }
      }
  }

  static std::string rename(std::string message)
  {
    const char *law_names[] = {"plasticity_ratio", "pull_off_force", "surface_energy", "slope_exponent",
                               "tension_exponent"};
    const char *property_names[] = {kPlasticityRatio, kPullOffForce, kSurfaceEnergy, kSlopeExponent, kTensionExponent};
    for (int k = 0; k < 5; ++k)
      if (message.compare(0, std::string(law_names[k]).size() + 1, std::string(law_names[k]) + " ") == 0)
        return std::string(property_names[k]) + message.substr(std::string(law_names[k]).size());
    return message;
  }

  double **plasticity_ratio_ = nullptr;
  double **pull_off_force_ = nullptr;
  double **surface_energy_ = nullptr;
  double **slope_exponent_ = nullptr;
  double **tension_exponent_ = nullptr;
  double **tangential_multiplier_ = nullptr;
  std::vector<std::vector<double>> plastic_root_;  // λp^(1/n) per type pair, cached
};

}  // namespace tsg

#endif
