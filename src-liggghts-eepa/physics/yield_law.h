// Hertz contact with a limiting contact pressure (Thornton & Ning 1998), dependency-free: the
// squeeze treatment of docs/stability.md. A contact is Hertzian until its largest pressure reaches
// the yield pressure p_y; beyond, the pressure stays at p_y and the force grows linearly; unloading
// (and reloading up to the largest overlap reached) is Hertzian about an enlarged radius R_p, from
// the plastic overlap δ_p on. The work done beyond yield is dissipated, so a particle pressed deep
// into a wall gives back only the small elastic part of it.
//
//   δ_y = R (π p_y / (2 E*))²                      yield overlap
//   F_y = (4/3) E* √R δ_y^1.5                       yield force
//   F   = F_y + π p_y R (δ - δ_y)                   loading beyond δ_y
//   a_p = √((2 F_max + F_y) / (2 π p_y))            contact radius at the largest force
//   R_p = 4 E* a_p³ / (3 F_max)                     unloading radius (= R at F_max = F_y)
//   δ_p = δ_max - 3 F_max / (4 E* a_p)              plastic overlap
//   F   = (4/3) E* √R_p (δ - δ_p)^1.5               unloading and reloading, δ_p < δ <= δ_max
//
// Sign convention: overlap δ > 0 in contact, force > 0 repels. SI units.
#ifndef TSG_YIELD_LAW_H
#define TSG_YIELD_LAW_H

#include <cmath>
#include <stdexcept>
#include <string>

namespace tsg::yield {

constexpr double kPi = 3.14159265358979323846;

struct Parameters {
  double modulus;         // E*, Pa (> 0)
  double radius;          // R*, m (> 0)
  double yield_pressure;  // p_y, Pa (> 0; infinity: Hertz)
};

// Per contact; all zero on first touch. max_force > yield force marks a yielded contact.
struct History {
  double max_overlap = 0;
  double max_force = 0;
  double plastic_overlap = 0;
  double unload_radius = 0;  // R_p; 0 while the contact has not yielded
};

struct State {
  double force;           // N, >= 0
  double stiffness;       // tangent dF/dδ of the elastic branch through δ (2 E* a), N/m: time step, dashpot
  double contact_radius;  // a, m (Mindlin's tangential stiffness 8 G* a)
  bool yielding;          // on the plastic loading branch
  History history;
};

inline void validate(const Parameters &p)
{
  if (!(p.modulus > 0 && std::isfinite(p.modulus))) throw std::invalid_argument("modulus must be finite and > 0");
  if (!(p.radius > 0 && std::isfinite(p.radius))) throw std::invalid_argument("radius must be finite and > 0");
  if (!(p.yield_pressure > 0)) throw std::invalid_argument("yield_pressure must be > 0 (Pa)");
}

inline double yield_overlap(const Parameters &p)
{
  const double ratio = kPi * p.yield_pressure / (2 * p.modulus);
  return p.radius * ratio * ratio;
}

inline double hertz_force(double modulus, double radius, double overlap)
{
  return 4.0 / 3.0 * modulus * std::sqrt(radius) * overlap * std::sqrt(overlap);
}

inline double yield_force(const Parameters &p) { return hertz_force(p.modulus, p.radius, yield_overlap(p)); }

// Force on the loading branch (the virgin curve) at overlap δ.
inline double loading_force(const Parameters &p, double overlap)
{
  const double dy = yield_overlap(p);
  if (overlap <= dy) return hertz_force(p.modulus, p.radius, overlap);
  return yield_force(p) + kPi * p.yield_pressure * p.radius * (overlap - dy);
}

// Work done on the loading branch from first touch to δ (J): the energy a head-on impact must bring.
inline double loading_work(const Parameters &p, double overlap)
{
  const double dy = yield_overlap(p);
  if (overlap <= dy) return 0.4 * hertz_force(p.modulus, p.radius, overlap) * overlap;
  const double beyond = overlap - dy;
  return 0.4 * yield_force(p) * dy + yield_force(p) * beyond +
         0.5 * kPi * p.yield_pressure * p.radius * beyond * beyond;
}

// History after loading to δ_max on the virgin curve.
inline History loaded_to(const Parameters &p, double overlap)
{
  History h;
  h.max_overlap = overlap;
  h.max_force = loading_force(p, overlap);
  const double fy = yield_force(p);
  if (overlap <= yield_overlap(p)) {
    h.unload_radius = 0;
    h.plastic_overlap = 0;
    return h;
  }
  const double a = std::sqrt((2 * h.max_force + fy) / (2 * kPi * p.yield_pressure));
  h.unload_radius = 4 * p.modulus * a * a * a / (3 * h.max_force);
  h.plastic_overlap = overlap - 3 * h.max_force / (4 * p.modulus * a);
  return h;
}

// Elastic energy given back on unloading from the history's largest overlap to separation (J).
inline double unloading_work(const History &h) { return 0.4 * h.max_force * (h.max_overlap - h.plastic_overlap); }

// Force, stiffness and updated history at overlap δ >= 0 after `previous`.
inline State evaluate(const Parameters &p, const History &previous, double overlap)
{
  State s{0, 0, 0, false, previous};
  if (overlap >= previous.max_overlap) {  // on the virgin curve
    s.history = loaded_to(p, overlap);
    s.force = s.history.max_force;
    s.yielding = overlap > yield_overlap(p);
    s.contact_radius = s.yielding ? std::sqrt((2 * s.force + yield_force(p)) / (2 * kPi * p.yield_pressure))
                                  : std::sqrt(p.radius * overlap);
    s.stiffness = 2 * p.modulus * s.contact_radius;
    return s;
  }
  if (previous.unload_radius == 0) {  // elastic contact below its largest overlap: Hertz
    s.force = hertz_force(p.modulus, p.radius, overlap);
    s.contact_radius = std::sqrt(p.radius * overlap);
  } else {
    const double elastic = std::max(0.0, overlap - previous.plastic_overlap);
    s.force = hertz_force(p.modulus, previous.unload_radius, elastic);
    s.contact_radius = std::sqrt(previous.unload_radius * elastic);
  }
  s.stiffness = 2 * p.modulus * s.contact_radius;
  return s;
}

// Rebound speed of a sphere of mass m hitting a rigid flat wall head-on at speed v (no damping, no
// friction): the loading work fixes δ_max, the unloading work the rebound (closed form, for tests).
inline double rebound_speed(const Parameters &p, double mass, double speed)
{
  const double energy = 0.5 * mass * speed * speed;
  const double dy = yield_overlap(p), fy = yield_force(p);
  double overlap = 0;
  if (energy <= 0.4 * fy * dy) {
    overlap = std::pow(energy / (0.4 * 4.0 / 3.0 * p.modulus * std::sqrt(p.radius)), 0.4);
  } else {  // 0.4 fy dy + fy x + (π p_y R / 2) x² = energy
    const double k = kPi * p.yield_pressure * p.radius;
    const double c = 0.4 * fy * dy - energy;
    overlap = dy + (-fy + std::sqrt(fy * fy - 2 * k * c)) / k;
  }
  return std::sqrt(2 * unloading_work(loaded_to(p, overlap)) / mass);
}

}  // namespace tsg::yield

#endif
