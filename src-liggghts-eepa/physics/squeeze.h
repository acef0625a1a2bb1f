// Squeeze events of one particle, dependency-free: the state machine behind fix squeeze/ledger.
//
// A particle is squeezed while its deepest overlap δ/R — against any wall, or against another
// particle (R the smaller radius) — exceeds `start`; the event ends when both fall below `end`
// (hysteresis: a contact oscillating about one threshold is one event). After the end the particle is
// followed for `release_steps` more steps, and the largest speed it reaches is the event's release
// speed (what a pinch fires a particle with). A new squeeze during the release closes the event
// (released at its largest speed so far) and opens the next. Where: the walls touched at any time
// of the event (a bit mask) and whether other particles pressed too give its kind; the position is
// the particle's at its deepest overlap.
#ifndef TSG_SQUEEZE_H
#define TSG_SQUEEZE_H

#include <algorithm>
#include <stdexcept>
#include <string>

namespace tsg::squeeze {

struct Thresholds {
  double start = 0.1;      // δ/R that opens an event
  double end = 0.05;       // δ/R below which it closes (<= start)
  int release_steps = 50;  // steps after the end over which the release speed is taken (>= 0)
};

inline void validate(const Thresholds &t)
{
  if (!(t.start > 0 && t.start < 10))
    throw std::invalid_argument("start = " + std::to_string(t.start) + " must be in (0, 10) (δ/R)");
  if (!(t.end > 0 && t.end <= t.start))
    throw std::invalid_argument("end = " + std::to_string(t.end) + " must be in (0, start] (δ/R)");
  if (t.release_steps < 0) throw std::invalid_argument("release_steps must be >= 0");
}

// What the particle feels at one step.
struct Sample {
  double wall_ratio = 0;        // deepest δ/R against any wall (0: none)
  unsigned walls = 0;           // bit k: touches wall k (δ > 0)
  double pair_ratio = 0;        // deepest δ/R against another particle (0: none)
  bool with_particles = false;  // touches another particle (δ > 0)
  double speed = 0;             // m/s
  double position[3] = {0, 0, 0};
};

enum Phase { kFree = 0, kPressed = 1, kReleasing = 2 };

// Per particle; all zero before its first event (it fits the per-atom arrays of a LIGGGHTS fix).
struct Track {
  double phase = kFree;
  double start_time = 0;
  double start_speed = 0;
  double peak_wall = 0;
  double peak_pair = 0;
  double walls = 0;           // union of the wall bits during the event
  double with_particles = 0;  // 1: other particles pressed during the event
  double peak_position[3] = {0, 0, 0};
  double release_left = 0;  // steps of the release still to follow
  double release_speed = 0;
  double events = 0;  // events of this particle so far, this one included once opened
};

// A finished event.
struct Event {
  double start_time, end_time;  // s: opened; release taken until
  double start_speed, release_speed;
  double peak_wall, peak_pair;
  unsigned walls;
  bool with_particles;
  double position[3];
  int number;  // the particle's event count: 1 on its first squeeze
};

enum class Kind { two_walls, wall_and_particles, wall_alone, particles };

inline int wall_count(unsigned walls)
{
  int n = 0;
  for (; walls; walls &= walls - 1) ++n;
  return n;
}

inline Kind kind(const Event &e)
{
  if (wall_count(e.walls) >= 2) return Kind::two_walls;
  if (e.walls != 0) return e.with_particles ? Kind::wall_and_particles : Kind::wall_alone;
  return Kind::particles;
}

inline const char *kind_name(Kind k)
{
  switch (k) {
    case Kind::two_walls:
      return "two_walls";
    case Kind::wall_and_particles:
      return "wall_and_particles";
    case Kind::wall_alone:
      return "wall_alone";
    case Kind::particles:
      return "particles";
  }
  return "?";
}

namespace detail {
inline Event close(const Track &t, double time)
{
  Event e{};
  e.start_time = t.start_time;
  e.end_time = time;
  e.start_speed = t.start_speed;
  e.release_speed = t.release_speed;
  e.peak_wall = t.peak_wall;
  e.peak_pair = t.peak_pair;
  e.walls = static_cast<unsigned>(t.walls);
  e.with_particles = t.with_particles != 0;
  std::copy(t.peak_position, t.peak_position + 3, e.position);
  e.number = static_cast<int>(t.events);
  return e;
}

// The event of the track closes at `time`; the track is free again (its event count kept).
inline void finish(Track &t, double time, Event &finished)
{
  finished = close(t, time);
  const double events = t.events;
  t = Track{};
  t.events = events;
}

inline void open(Track &t, const Sample &s, double time)
{
  const double events = t.events + 1;
  t = Track{};
  t.events = events;
  t.phase = kPressed;
  t.start_time = time;
  t.start_speed = s.speed;
}
}  // namespace detail

// Advances the track by one step at `time`; returns true and fills `finished` when an event closes.
inline bool advance(Track &t, const Sample &s, const Thresholds &th, double time, Event &finished)
{
  const double depth = std::max(s.wall_ratio, s.pair_ratio);
  bool closed = false;
  if (t.phase == kReleasing) {
    if (depth > th.start) {  // squeezed again before the release ended: two events
      finished = detail::close(t, time);
      closed = true;
      detail::open(t, s, time);
    } else {
      t.release_speed = std::max(t.release_speed, s.speed);
      t.release_left -= 1;
      if (t.release_left <= 0) {
        detail::finish(t, time, finished);
        return true;
      }
      return false;
    }
  } else if (t.phase == kFree) {
    if (!(depth > th.start)) return false;
    detail::open(t, s, time);
  }
  // pressed
  if (s.wall_ratio > 0 || s.pair_ratio > 0) {
    t.walls = static_cast<double>(static_cast<unsigned>(t.walls) | s.walls);
    if (s.with_particles && s.pair_ratio > 0) t.with_particles = 1;
  }
  if (depth >= std::max(t.peak_wall, t.peak_pair)) std::copy(s.position, s.position + 3, t.peak_position);
  t.peak_wall = std::max(t.peak_wall, s.wall_ratio);
  t.peak_pair = std::max(t.peak_pair, s.pair_ratio);
  if (depth < th.end) {
    t.phase = kReleasing;
    t.release_speed = s.speed;
    t.release_left = th.release_steps;
    if (th.release_steps == 0) {
      detail::finish(t, time, finished);
      return true;
    }
  }
  return closed;
}

}  // namespace tsg::squeeze

#endif
