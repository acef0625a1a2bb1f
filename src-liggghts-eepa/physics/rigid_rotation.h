// Rigid rotation of a body about a fixed axis at constant angular speed, dependency-free.
//
// A screw turning at ω about the unit axis a through the point p occupies, at time t, the pose
//   x_lab = p + R(θ) (x_body − p),   θ = ω t                                   (rotation by θ about a)
// R(θ) is Rodrigues' matrix  R = cos θ I + sin θ [a]× + (1 − cos θ) a aᵀ.
// The angle is always computed from the elapsed time (never by adding increments), so the phase
// does not drift over long runs. The surface velocity of the body at a lab point c is ω a × (c − p).
#ifndef TSG_RIGID_ROTATION_H
#define TSG_RIGID_ROTATION_H

#include <cmath>

namespace tsg::rotation {

struct Vec3 {
  double x, y, z;
};

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double norm(Vec3 a) { return std::sqrt(dot(a, a)); }

// Row-major 3×3 matrix.
struct Mat3 {
  double m[3][3];
  Vec3 apply(Vec3 v) const
  {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  Vec3 apply_transpose(Vec3 v) const
  {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
  }
};

// Rodrigues' rotation matrix for the angle theta about the unit vector axis.
inline Mat3 rotation_matrix(Vec3 axis, double theta)
{
  const double c = std::cos(theta), s = std::sin(theta), k = 1.0 - c;
  const double x = axis.x, y = axis.y, z = axis.z;
  return {{{c + k * x * x, k * x * y - s * z, k * x * z + s * y},
           {k * y * x + s * z, c + k * y * y, k * y * z - s * x},
           {k * z * x - s * y, k * z * y + s * x, c + k * z * z}}};
}

// The rotating body: axis through origin, unit axis direction, angular speed omega (rad/s, sign
// gives the sense by the right-hand rule about axis).
struct RigidRotation {
  Vec3 origin;
  Vec3 axis;     // unit length
  double omega;  // rad/s

  double angle(double elapsed_time) const { return omega * elapsed_time; }

  // lab point -> body frame (the frame in which the mesh was given), for pose matrix R(θ)
  Vec3 to_body(const Mat3 &pose, Vec3 lab_point) const { return origin + pose.apply_transpose(lab_point - origin); }
  // body vector -> lab vector
  static Vec3 vector_to_lab(const Mat3 &pose, Vec3 body_vector) { return pose.apply(body_vector); }
  // surface velocity of the body at the lab point c: ω a × (c − p)
  Vec3 surface_velocity(Vec3 lab_point) const { return omega * cross(axis, lab_point - origin); }
};

}  // namespace tsg::rotation

#endif
