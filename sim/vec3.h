/* vec3.h: small inline vector and quaternion helpers private to sim/.
 * Vectors are double[3]; quaternions double[4] as (w, x, y, z). */
#ifndef CS_VEC3_H
#define CS_VEC3_H

#include <math.h>

static inline double cs_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double cs_norm(const double a[3]) { return sqrt(cs_dot(a, a)); }

static inline void cs_sub(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

static inline void cs_cross(const double a[3], const double b[3], double out[3])
{
    double r[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    out[0] = r[0];
    out[1] = r[1];
    out[2] = r[2];
}

/* out += s * a */
static inline void cs_axpy(double s, const double a[3], double out[3])
{
    out[0] += s * a[0];
    out[1] += s * a[1];
    out[2] += s * a[2];
}

/* out = R a, R row-major 3x3 */
static inline void cs_mat_apply(const double R[9], const double a[3], double out[3])
{
    double r[3] = {R[0] * a[0] + R[1] * a[1] + R[2] * a[2],
                   R[3] * a[0] + R[4] * a[1] + R[5] * a[2],
                   R[6] * a[0] + R[7] * a[1] + R[8] * a[2]};
    out[0] = r[0];
    out[1] = r[1];
    out[2] = r[2];
}

/* out = R^T a */
static inline void cs_mat_apply_transpose(const double R[9], const double a[3], double out[3])
{
    double r[3] = {R[0] * a[0] + R[3] * a[1] + R[6] * a[2],
                   R[1] * a[0] + R[4] * a[1] + R[7] * a[2],
                   R[2] * a[0] + R[5] * a[1] + R[8] * a[2]};
    out[0] = r[0];
    out[1] = r[1];
    out[2] = r[2];
}

void cs_quat_normalize(double q[4]);
void cs_quat_to_matrix(const double q[4], double R[9]);
/* Rotation by angle |w| * t about axis w (exponential map). */
void cs_quat_from_rotation_vector(const double w[3], double t, double out[4]);
/* Rotation vector (axis * angle, angle in [0, pi]) of a unit quaternion. */
void cs_quat_to_rotation_vector(const double q[4], double w[3]);
void cs_quat_slerp(const double a[4], const double b[4], double s, double out[4]);

#endif
