/* motion.c: rigid motions over time (static, constant velocity, keyframes)
 * and the quaternion arithmetic they need. */
#include <math.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"

void cs_quat_normalize(double q[4])
{
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(n > 0.0)) {
        q[0] = 1.0;
        q[1] = q[2] = q[3] = 0.0;
        return;
    }
    for (int i = 0; i < 4; i++)
        q[i] /= n;
}

void cs_quat_multiply(const double a[4], const double b[4], double out[4])
{
    double r[4] = {
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    };
    memcpy(out, r, sizeof r);
}

void cs_quat_to_matrix(const double q[4], double R[9])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z);
    R[1] = 2 * (x * y - w * z);
    R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z);
    R[4] = 1 - 2 * (x * x + z * z);
    R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y);
    R[7] = 2 * (y * z + w * x);
    R[8] = 1 - 2 * (x * x + y * y);
}

void cs_quat_from_rotation_vector(const double w[3], double t, double out[4])
{
    double angle = cs_norm(w) * t;
    if (angle == 0.0) {
        out[0] = 1.0;
        out[1] = out[2] = out[3] = 0.0;
        return;
    }
    double s = sin(0.5 * angle) / cs_norm(w);
    out[0] = cos(0.5 * angle);
    out[1] = w[0] * s;
    out[2] = w[1] * s;
    out[3] = w[2] * s;
}

void cs_quat_to_rotation_vector(const double q_in[4], double w[3])
{
    double q[4] = {q_in[0], q_in[1], q_in[2], q_in[3]};
    if (q[0] < 0) /* the shorter way round */
        for (int i = 0; i < 4; i++)
            q[i] = -q[i];
    double s = sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (s < 1e-300) {
        w[0] = w[1] = w[2] = 0.0;
        return;
    }
    double angle = 2.0 * atan2(s, q[0]);
    for (int i = 0; i < 3; i++)
        w[i] = q[i + 1] / s * angle;
}

void cs_quat_slerp(const double a[4], const double b_in[4], double s, double out[4])
{
    /* a * exp(s * log(a^-1 b)): constant angular velocity between keys */
    double ainv[4] = {a[0], -a[1], -a[2], -a[3]};
    double rel[4], w[3], step[4];
    cs_quat_multiply(ainv, b_in, rel);
    cs_quat_to_rotation_vector(rel, w);
    cs_quat_from_rotation_vector(w, s, step);
    cs_quat_multiply(a, step, out);
    cs_quat_normalize(out);
}

void cs_quat_from_euler_degrees(const double degrees[3], double out[4])
{
    double h[3];
    for (int i = 0; i < 3; i++)
        h[i] = degrees[i] * M_PI / 360.0; /* half angles in radians */
    double qx[4] = {cos(h[0]), sin(h[0]), 0, 0};
    double qy[4] = {cos(h[1]), 0, sin(h[1]), 0};
    double qz[4] = {cos(h[2]), 0, 0, sin(h[2])};
    double zy[4];
    cs_quat_multiply(qz, qy, zy);
    cs_quat_multiply(zy, qx, out);
}

void cs_quat_from_y_to(const double n[3], double out[4])
{
    double w = 1.0 + n[1];
    if (w < 1e-12) { /* n = -y: half a turn about x */
        out[0] = 0, out[1] = 1, out[2] = 0, out[3] = 0;
        return;
    }
    double v[4] = {w, n[2], 0.0, -n[0]}; /* (1 + y.n, y x n) */
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[3] * v[3]);
    for (int i = 0; i < 4; i++)
        out[i] = v[i] / len;
}

void cs_quat_rotate(const double q[4], const double v[3], double out[3])
{
    double R[9];
    cs_quat_to_matrix(q, R);
    cs_mat_apply(R, v, out);
}

cs_motion cs_motion_static(void)
{
    cs_motion m;
    memset(&m, 0, sizeof m);
    m.kind = CS_MOTION_STATIC;
    m.rotation[0] = 1.0;
    return m;
}

void cs_motion_pose(const cs_motion *m, double t, double R[9], double c[3],
                    double velocity[3], double omega[3])
{
    double q[4] = {m->rotation[0], m->rotation[1], m->rotation[2], m->rotation[3]};
    double pos[3] = {m->position[0], m->position[1], m->position[2]};
    double vel[3] = {0, 0, 0}, w[3] = {0, 0, 0};

    if (m->kind == CS_MOTION_CONSTANT) {
        double dq[4];
        cs_quat_from_rotation_vector(m->angular_velocity, t, dq);
        cs_quat_multiply(dq, m->rotation, q); /* world-axis rotation applied after R(0) */
        for (int i = 0; i < 3; i++) {
            pos[i] += m->velocity[i] * t;
            vel[i] = m->velocity[i];
            w[i] = m->angular_velocity[i];
        }
    } else if (m->kind == CS_MOTION_KEYFRAMES && m->nkeys > 0) {
        const cs_keyframe *k = m->keys;
        int n = m->nkeys;
        if (n == 1 || t <= k[0].time) {
            memcpy(pos, k[0].position, sizeof pos);
            memcpy(q, k[0].rotation, sizeof q);
        } else if (t >= k[n - 1].time) {
            memcpy(pos, k[n - 1].position, sizeof pos);
            memcpy(q, k[n - 1].rotation, sizeof q);
        } else {
            int i = 0;
            while (i + 1 < n && k[i + 1].time <= t)
                i++;
            double span = k[i + 1].time - k[i].time;
            double s = (t - k[i].time) / span;
            for (int d = 0; d < 3; d++) {
                pos[d] = k[i].position[d] + s * (k[i + 1].position[d] - k[i].position[d]);
                vel[d] = (k[i + 1].position[d] - k[i].position[d]) / span;
            }
            cs_quat_slerp(k[i].rotation, k[i + 1].rotation, s, q);
            /* world angular velocity: rotation vector of q1 q0^-1 over the span */
            double q0inv[4] = {k[i].rotation[0], -k[i].rotation[1], -k[i].rotation[2],
                               -k[i].rotation[3]};
            double rel[4];
            cs_quat_multiply(k[i + 1].rotation, q0inv, rel);
            cs_quat_to_rotation_vector(rel, w);
            for (int d = 0; d < 3; d++)
                w[d] /= span;
        }
    }
    cs_quat_normalize(q);
    if (R)
        cs_quat_to_matrix(q, R);
    if (c)
        memcpy(c, pos, sizeof pos);
    if (velocity)
        memcpy(velocity, vel, sizeof vel);
    if (omega)
        memcpy(omega, w, sizeof w);
}

/* The fastest point within r of the centre: |dc/dt| + |omega| r */
static double motion_speed(const cs_motion *m, double t, double r)
{
    double c[3], vel[3], w[3];
    cs_motion_pose(m, t, NULL, c, vel, w);
    return cs_norm(vel) + cs_norm(w) * r;
}

double cs_motion_max_speed(const cs_motion *m, double t0, double t1, double r)
{
    if (m->kind != CS_MOTION_KEYFRAMES)
        return motion_speed(m, 0.0, r); /* static or constant: the same at every time */
    /* keys are linear in position and slerped in rotation, so a segment's
     * speed is the same at every time in it: its midpoint's */
    double fastest = 0;
    for (int k = 0; k + 1 < m->nkeys && m->keys[k].time < t1; k++)
        if (m->keys[k + 1].time > t0)
            fastest = fmax(fastest,
                           motion_speed(m, 0.5 * (m->keys[k].time + m->keys[k + 1].time), r));
    return fastest;
}
