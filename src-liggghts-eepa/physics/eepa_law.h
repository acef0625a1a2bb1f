// EEPA — Edinburgh Elasto-Plastic Adhesion normal contact law, dependency-free.
//
// Sources: Thakur, Morrissey, Sun, Chen, Ooi, Granular Matter 16:383-400 (2014) ("Thakur 2014");
// Morrissey, PhD thesis, University of Edinburgh (2013) ("Morrissey 2013"); the seed paper
// (Section 2.1, Table 4). Every equation, and every choice made where the sources are silent, is
// derived in docs/model.md. Sign convention: overlap δ > 0 in contact, force > 0 repels.
#ifndef TSG_EEPA_LAW_H
#define TSG_EEPA_LAW_H

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "numbers.h"

namespace tsg::eepa {

// One contact pair, SI units.
struct Parameters {
  double k1;                // loading stiffness, N/m^n (n = 1.5: (4/3) E* sqrt(R*))
  double plasticity_ratio;  // λp in [0, 1): k2 = k1 / (1 - λp)
  double slope_exponent;    // n >= 1
  double tension_exponent;  // X >= 1, exponent of the adhesive branch
  double pull_off_force;    // f0 <= 0, N, constant and signed (negative attracts)
  double surface_energy;    // Δγ >= 0, J/m^2
  double effective_radius;  // R* > 0, m
};

// Per-contact history. max_overlap: largest overlap ever reached (δmax); it fixes the pull-off
// force. plastic_overlap: intercept δp of the current k2 line, f = f0 + k2 (δ^n - δp^n). Both
// start at zero on first touch.
struct History {
  double max_overlap = 0;
  double plastic_overlap = 0;
};

enum class Branch { Separated, Loading, Unloading, Adhesive };

// Result of one evaluation.
struct State {
  double force;         // hysteretic normal force including f0, N, positive repels
  double stiffness;     // tangent stiffness of the contact, N/m, >= 0 (see evaluate)
  double coulomb_load;  // normal load seen by the Coulomb limit, N, >= 0
  Branch branch;
  History history;  // updated history
};

// Largest adhesive pull of a contact with a given history: the adhesive branch reaches
// f0 - force at overlap.
struct PullOff {
  double force;    // f_min >= 0, N
  double overlap;  // δ_min, m
};

namespace detail {

constexpr double kPi = 3.14159265358979323846;

// f_min is capped at this fraction of k2 δp^n, the tension of the unloading line at δ = 0
// (docs/model.md, "Choice: pull-off cap").
constexpr double kMaxPullOffFraction = 0.5;

// x^e; the Hertzian exponent takes the sqrt path, several times faster than std::pow.
inline double power(double x, double e) { return e == 1.5 ? x * std::sqrt(x) : std::pow(x, e); }

// x^(1/e); the Hertzian exponent takes the cube-root path (x^(2/3) = cbrt(x^2)).
inline double root(double x, double e) { return e == 1.5 ? std::cbrt(x * x) : std::pow(x, 1 / e); }

inline void require(bool in_range, const char *name, double value, const char *range)
{
  if (!in_range)
    throw std::invalid_argument(std::string(name) + " = " + tsg::number(value, tsg::NumberKind::parameter) +
                                " is outside the allowed range " + range);
}

// The adhesive branch of a contact: f_min and δ_min^n (see pull_off).
struct AdhesiveBranch {
  double f_min;
  double min_n;
};

// Adhesive branch below the virgin unloading line of plastic overlap δp (plastic_n = δp^n).
inline AdhesiveBranch adhesive_branch(const Parameters &p, double k2, double plastic, double plastic_n)
{
  if (!(p.surface_energy > 0 && plastic_n > 0)) return {0, plastic_n};
  const double contact_radius = std::sqrt(2 * p.effective_radius * plastic);
  const double jkr = 1.5 * kPi * p.surface_energy * contact_radius;
  const double f_min = std::min(jkr, kMaxPullOffFraction * k2 * plastic_n);
  return {f_min, plastic_n - f_min / k2};
}

// Adhesive branch of a contact whose largest overlap was max_overlap.
// plastic_root = λp^(1/n): δp/δmax of the virgin unloading line.
inline AdhesiveBranch adhesive_branch_after(const Parameters &p, double k2, double max_overlap, double plastic_root)
{
  const double plastic_n = p.plasticity_ratio * power(max_overlap, p.slope_exponent);
  if (!(p.surface_energy > 0 && plastic_n > 0)) return {0, plastic_n};
  const double plastic = plastic_root * max_overlap;
  return adhesive_branch(p, k2, plastic, plastic_n);
}

// Magnitude of the adhesive branch at δ (overlap_n = δ^n): Thakur's kadh δ^X with
// kadh = f_min/δ_min^X, evaluated as f_min (δ^n/δ_min^n)^(X/n) so that X = 20 neither
// overflows nor underflows; capped at f_min for δ >= δ_min, where the monomial grows unbounded.
inline double adhesion(const Parameters &p, const AdhesiveBranch &branch, double overlap_n)
{
  if (!(branch.f_min > 0)) return 0;
  if (overlap_n >= branch.min_n) return branch.f_min;
  return branch.f_min * std::pow(overlap_n / branch.min_n, p.tension_exponent / p.slope_exponent);
}

}  // namespace detail

// Throws std::invalid_argument naming the parameter, its value and the allowed range.
inline void validate(const Parameters &p)
{
  constexpr double inf = std::numeric_limits<double>::infinity();
  detail::require(p.k1 > 0 && p.k1 < inf, "k1", p.k1, "(0, inf)");
  detail::require(p.plasticity_ratio >= 0 && p.plasticity_ratio < 1, "plasticity_ratio", p.plasticity_ratio, "[0, 1)");
  detail::require(p.slope_exponent >= 1 && p.slope_exponent < inf, "slope_exponent", p.slope_exponent, "[1, inf)");
  detail::require(p.tension_exponent >= 1 && p.tension_exponent < inf, "tension_exponent", p.tension_exponent,
                  "[1, inf)");
  detail::require(p.pull_off_force <= 0 && p.pull_off_force > -inf, "pull_off_force", p.pull_off_force, "(-inf, 0]");
  detail::require(p.surface_energy >= 0 && p.surface_energy < inf, "surface_energy", p.surface_energy, "[0, inf)");
  detail::require(p.effective_radius > 0 && p.effective_radius < inf, "effective_radius", p.effective_radius,
                  "(0, inf)");
}

// λp^(1/n): the plastic overlap per unit overlap of an unloading line leaving the k1 branch.
inline double plastic_root(double plasticity_ratio, double slope_exponent)
{
  return std::pow(plasticity_ratio, 1 / slope_exponent);
}

// Pull-off of a contact whose largest overlap was max_overlap (Thakur 2014; Morrissey 2013):
//   δp^n   = λp δmax^n                     plastic overlap of the virgin unloading line
//   a      = sqrt(2 R* δp)                 contact radius at δp (small-overlap geometric circle)
//   f_min  = min(1.5 π Δγ a, k2 δp^n / 2)  JKR-type pull-off, capped (docs: "Pull-off cap")
//   δ_min^n = δp^n - f_min / k2            where the unloading line reaches f0 - f_min
// Without surface energy (or plastic overlap) f_min = 0 and δ_min = δp.
inline PullOff pull_off(const Parameters &p, double max_overlap)
{
  const double k2 = p.k1 / (1 - p.plasticity_ratio);
  const detail::AdhesiveBranch branch =
      detail::adhesive_branch_after(p, k2, max_overlap, plastic_root(p.plasticity_ratio, p.slope_exponent));
  return {branch.f_min, detail::root(branch.min_n, p.slope_exponent)};
}

// One evaluation of the law at overlap δ, given the history of the previous evaluation.
// Branches (Thakur 2014), compared by overlap, never by force:
//   Loading    λp δ^n >= δp^n (δ at or past where the k2 line meets k1, δmax on a plain cycle):
//              f = f0 + k1 δ^n;              δp^n <- λp δ^n, δmax <- max(δmax, δ)
//   Unloading  k2 (δ^n - δp^n) >= -f_adh(δ): f = f0 + k2 (δ^n - δp^n); history unchanged
//   Adhesive   otherwise:                    f = f0 - f_adh(δ), f_adh = kadh δ^X (pull_off);
//              δp^n <- δ^n + f_adh(δ)/k2, the k2 line through the current point, so that a
//              reload leaves the branch continuously and rejoins k1 at (δp^n/λp)^(1/n).
// stiffness: n k1 δ^(n-1) on Loading, n k2 δ^(n-1) on Unloading and Adhesive (the adhesive
// branch's own slope is negative; n k2 δ^(n-1) is what a reload meets).
// coulomb_load: |f - f0 + f_adh(δ)| (Thakur 2014), zero on the adhesive branch.
// δ <= 0 (or NaN): Separated, all zero, history reset.
// plastic_root = plastic_root(λp, n), passed in so that a caller evaluating many contacts of one
// type pair computes the root once (the overload below computes it per call).
inline State evaluate(const Parameters &p, const History &previous, double overlap, double plastic_root)
{
  if (!(overlap > 0)) return {0, 0, 0, Branch::Separated, History{}};
  const double n = p.slope_exponent;
  const double f0 = p.pull_off_force;
  const double lambda = p.plasticity_ratio;
  const double k2 = p.k1 / (1 - lambda);
  const double overlap_n = detail::power(overlap, n);
  const double slope = n * overlap_n / overlap;  // d(δ^n)/dδ
  const double plastic_n = detail::power(previous.plastic_overlap, n);

  if (lambda * overlap_n >= plastic_n) {
    const double plastic_per_overlap = plastic_root;  // δp/δ of a line leaving k1
    const double max_overlap = std::max(previous.max_overlap, overlap);
    const History history{max_overlap, plastic_per_overlap * overlap};
    const detail::AdhesiveBranch adhesive =
        detail::adhesive_branch(p, k2, plastic_per_overlap * max_overlap, lambda * detail::power(max_overlap, n));
    const double elastic = p.k1 * overlap_n;
    const double pull = detail::adhesion(p, adhesive, overlap_n);
    return {f0 + elastic, p.k1 * slope, elastic + pull, Branch::Loading, history};
  }

  const double line = k2 * (overlap_n - plastic_n);
  const double pull =
      detail::adhesion(p, detail::adhesive_branch_after(p, k2, previous.max_overlap, plastic_root), overlap_n);
  if (line >= -pull) return {f0 + line, k2 * slope, line + pull, Branch::Unloading, previous};
  const History history{previous.max_overlap, detail::root(overlap_n + pull / k2, n)};
  return {f0 - pull, k2 * slope, 0, Branch::Adhesive, history};
}

inline State evaluate(const Parameters &p, const History &previous, double overlap)
{
  return evaluate(p, previous, overlap, plastic_root(p.plasticity_ratio, p.slope_exponent));
}

// Undamped, non-adhesive restitution of a two-body impact (docs/model.md, "Restitution of the
// undamped, non-adhesive law"):
//   e^2 = [1 - (n+1) λp + n λp^(1+1/n)] / (1 - λp)
// the work returned on the k2 line over the work done on the k1 line.
inline double undamped_restitution(double plasticity_ratio, double slope_exponent)
{
  detail::require(plasticity_ratio >= 0 && plasticity_ratio < 1, "plasticity_ratio", plasticity_ratio, "[0, 1)");
  detail::require(slope_exponent >= 1 && slope_exponent < std::numeric_limits<double>::infinity(), "slope_exponent",
                  slope_exponent, "[1, inf)");
  const double n = slope_exponent;
  const double lambda = plasticity_ratio;
  const double e2 = (1 - (n + 1) * lambda + n * std::pow(lambda, 1 + 1 / n)) / (1 - lambda);
  return std::sqrt(std::max(0.0, e2));
}

// Damping ratio of the Hertz-Mindlin dashpot for a target restitution e (Tsuji et al. 1992;
// LIGGGHTS/EDEM Hertz-Mindlin): β = ln e / sqrt(ln^2 e + π^2), β in (-1, 0].
inline double damping_ratio_from_restitution(double e)
{
  detail::require(e > 0 && e <= 1, "restitution", e, "(0, 1]");
  const double log_e = std::log(e);
  return log_e / std::sqrt(log_e * log_e + detail::kPi * detail::kPi);
}

// Hertz-Mindlin dashpot with the branch tangent stiffness S (State::stiffness):
//   F_d = -2 sqrt(5/6) β sqrt(S m*) v_n
// normal_velocity v_n = dδ/dt, positive while approaching (LIGGGHTS' sidata.vn is -dδ/dt).
// The coefficient −2 sqrt(5/6) β sqrt(S m*) (>= 0) is damping_coefficient, F_d = coefficient · v_n.
inline double damping_coefficient(double beta, double stiffness, double reduced_mass)
{
  constexpr double sqrt_five_sixths = 0.91287092917527685576;
  return -2 * sqrt_five_sixths * beta * std::sqrt(stiffness * reduced_mass);
}

inline double damping_force(double beta, double stiffness, double reduced_mass, double normal_velocity)
{
  return damping_coefficient(beta, stiffness, reduced_mass) * normal_velocity;
}

}  // namespace tsg::eepa

#endif
