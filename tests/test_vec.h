/*
 * test_vec.h — small vector helpers for tests that use only the public header (wetdem.h).
 * They repeat the shape of the library's internal src/vec3.h on purpose: a test that checked
 * the library's vector algebra with that same algebra could not catch an error in it (a wrong
 * sign in a cross product would cancel), so the tests carry their own.
 */
#ifndef WETDEM_TEST_VEC_H
#define WETDEM_TEST_VEC_H

#include <math.h>

#include "wetdem.h"

static inline struct wetdem_vec3 v3(double x, double y, double z)
{
    return (struct wetdem_vec3){x, y, z};
}
static inline struct wetdem_vec3 add(struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    return v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline struct wetdem_vec3 sub(struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    return v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline struct wetdem_vec3 scale(struct wetdem_vec3 a, double s)
{
    return v3(a.x * s, a.y * s, a.z * s);
}
static inline double dot(struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline double norm(struct wetdem_vec3 a)
{
    return sqrt(dot(a, a));
}
static inline struct wetdem_vec3 cross(struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline struct wetdem_vec3 unit(struct wetdem_vec3 a)
{
    return scale(a, 1.0 / norm(a));
}

#endif
