// Signed crossings of an axial plane between two positions, dependency-free.
//
// A particle moving from unwrapped coordinate u0 to u1 crosses the plane x = X (and, on a periodic
// axis of period L, every image X + kL)
//   open:     [u1 >= X] - [u0 >= X]                      (+1 towards +x, -1 towards -x, 0)
//   periodic: floor((u1 - X)/L) - floor((u0 - X)/L)      (any number of images in one step)
// A particle sitting exactly on the plane counts as downstream of it, so touching and leaving the
// plane in the same direction is one crossing, never two.
#ifndef TSG_PLANE_CROSSING_H
#define TSG_PLANE_CROSSING_H

#include <cmath>

namespace tsg::flow {

inline long net_crossings(double u0, double u1, double plane, double period)
{
  if (period > 0)
    return static_cast<long>(std::floor((u1 - plane) / period)) - static_cast<long>(std::floor((u0 - plane) / period));
  return static_cast<long>(u1 >= plane) - static_cast<long>(u0 >= plane);
}

// kg/s -> kg/h
constexpr double kSecondsPerHour = 3600.0;

}  // namespace tsg::flow

#endif
