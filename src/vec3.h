/*
 * vec3.h — static inline helpers for struct wetdem_vec3 (internal).
 * Plain Cartesian algebra in SI units; no frame rotations.
 */
#ifndef WETDEM_VEC3_H
#define WETDEM_VEC3_H

#include <math.h>

#include "wetdem.h"

static inline struct wetdem_vec3 vec3(double x, double y, double z)
{
    return (struct wetdem_vec3){x, y, z};
}
static inline struct wetdem_vec3 vec3_add(struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    return vec3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline struct wetdem_vec3 vec3_sub(struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    return vec3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline struct wetdem_vec3 vec3_scale(struct wetdem_vec3 a, double s)
{
    return vec3(a.x * s, a.y * s, a.z * s);
}
/* a + s b */
static inline struct wetdem_vec3 vec3_axpy(struct wetdem_vec3 a, double s, struct wetdem_vec3 b)
{
    return vec3(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}
static inline double vec3_dot(struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline struct wetdem_vec3 vec3_cross(struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double vec3_norm(struct wetdem_vec3 a)
{
    return sqrt(vec3_dot(a, a));
}
static inline struct wetdem_vec3 vec3_neg(struct wetdem_vec3 a)
{
    return vec3(-a.x, -a.y, -a.z);
}
/* Component of a perpendicular to the unit vector n. */
static inline struct wetdem_vec3 vec3_reject(struct wetdem_vec3 a, struct wetdem_vec3 n)
{
    return vec3_axpy(a, -vec3_dot(a, n), n);
}
/* A vector perpendicular to the unit vector n, of length at least 0.43 (x or, where n lies
 * near x, y with n's part taken out): a tangent direction for probing a contact. */
static inline struct wetdem_vec3 vec3_some_perpendicular(struct wetdem_vec3 n)
{
    return vec3_reject(fabs(n.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0), n);
}
static inline int vec3_is_finite(struct wetdem_vec3 a)
{
    return isfinite(a.x) && isfinite(a.y) && isfinite(a.z);
}

#endif
