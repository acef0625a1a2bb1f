// Critical time-step estimates for DEM contacts, dependency-free. SI units.
// Derivations and the seed-paper check are in docs/model.md, "Time step".
#ifndef TSG_CONTACT_TIMESTEP_H
#define TSG_CONTACT_TIMESTEP_H

#include <cmath>

namespace tsg::timestep {

// Rayleigh time of a sphere of radius R (pass the smallest radius in the system):
//   T_R = π R sqrt(ρ/G) / (0.1631 ν + 0.8766)
// the time a Rayleigh surface wave, speed (0.1631 ν + 0.8766) sqrt(G/ρ), takes to cross half the
// sphere's circumference (Li, Xu, Thornton, Powder Technol. 160:219 (2005); EDEM guidance).
// DEM practice, and the seed paper, use a fraction (10-20 %) of it.
inline double rayleigh_time(double radius, double density, double shear_modulus, double poisson_ratio)
{
  constexpr double pi = 3.14159265358979323846;
  return pi * radius * std::sqrt(density / shear_modulus) / (0.1631 * poisson_ratio + 0.8766);
}

// Duration of an undamped elastic impact with f = k1 δ^n at approach speed v (n = 1.5: Hertz):
//   δmax = ((n+1) m* v^2 / (2 k1))^(1/(n+1))                        energy balance
//   t_c  = 2 (δmax/v) ∫0^1 dx / sqrt(1 - x^(n+1)) = (2/(n+1)) B(1/(n+1), 1/2) δmax / v
// n = 1 gives π sqrt(m*/k1); n = 1.5 gives Johnson's 2.943 δmax/v (Contact Mechanics, 1985,
// Ch. 11), i.e. t_c ∝ v^(-1/5).
inline double hertz_collision_time(double k1, double slope_exponent, double reduced_mass, double impact_speed)
{
  const double n = slope_exponent;
  const double max_overlap = std::pow((n + 1) * reduced_mass * impact_speed * impact_speed / (2 * k1), 1 / (n + 1));
  const double a = 1 / (n + 1);
  const double beta_function = std::tgamma(a) * std::tgamma(0.5) / std::tgamma(a + 0.5);
  return 2 * a * beta_function * max_overlap / impact_speed;
}

// Stability limit of velocity Verlet (central difference) for one contact of tangent stiffness
// S and reduced mass m*: dt < 2 sqrt(m*/S) = 2/ω (O'Sullivan & Bray, Eng. Comput. 21:278 (2004)).
inline double verlet_stable_step(double stiffness, double reduced_mass)
{
  return 2 * std::sqrt(reduced_mass / stiffness);
}

// Factor by which EEPA's stiffer unloading branch, k2 = k1/(1 - λp), shortens a step that scales
// with sqrt(m/k_eff) at a given overlap (verlet_stable_step on the branch tangent stiffness; the
// Rayleigh time, taken as the k1-branch estimate): sqrt(k1/k2) = sqrt(1 - λp).
// λp = 0.8 (seed) gives 1/sqrt(5) = 0.447.
inline double eepa_step_factor(double plasticity_ratio) { return std::sqrt(1 - plasticity_ratio); }

}  // namespace tsg::timestep

#endif
