/* body.c: collision bodies as signed distances in a moving rigid frame.
 * Analytic shapes live here; grid bodies (level sets from meshes) enter
 * through cs_body_def.phi_fn with the same interface. */
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"

cs_body_def cs_default_body_def(void)
{
    cs_body_def b;
    memset(&b, 0, sizeof b);
    b.shape = CS_BODY_PLANE;
    b.radius = 1.0;
    b.half_extents[0] = b.half_extents[1] = b.half_extents[2] = 0.5;
    b.half_height = 0.5;
    b.friction = 0.3;
    b.motion = cs_motion_static();
    return b;
}

static double sign_of(double a) { return a < 0 ? -1.0 : 1.0; }

static double phi_plane(const double p[3], double g[3])
{
    g[0] = 0;
    g[1] = 1;
    g[2] = 0;
    return p[1];
}

static double phi_sphere(double r, const double p[3], double g[3])
{
    double n = cs_norm(p);
    if (n > 0) {
        for (int i = 0; i < 3; i++)
            g[i] = p[i] / n;
    } else { /* the centre: any direction is a steepest one */
        g[0] = 0;
        g[1] = 1;
        g[2] = 0;
    }
    return n - r;
}

static double phi_box(const double h[3], const double p[3], double g[3])
{
    double q[3], outside[3];
    int axis = 0;
    for (int i = 0; i < 3; i++) {
        q[i] = fabs(p[i]) - h[i];
        outside[i] = q[i] > 0 ? q[i] : 0;
        if (q[i] > q[axis])
            axis = i;
    }
    double d = cs_norm(outside);
    if (d > 0) {
        for (int i = 0; i < 3; i++)
            g[i] = outside[i] / d * sign_of(p[i]);
        return d;
    }
    g[0] = g[1] = g[2] = 0;
    g[axis] = sign_of(p[axis]);
    return q[axis];
}

static double phi_cylinder(double r, double hh, const double p[3], double g[3])
{
    double rho = sqrt(p[0] * p[0] + p[2] * p[2]);
    double radial[3] = {0, 0, 1}; /* any horizontal direction on the axis */
    if (rho > 0) {
        radial[0] = p[0] / rho;
        radial[2] = p[2] / rho;
    }
    double dr = rho - r, dy = fabs(p[1]) - hh;
    if (dr > 0 && dy > 0) { /* nearest to the rim */
        double d = sqrt(dr * dr + dy * dy);
        for (int i = 0; i < 3; i++)
            g[i] = (radial[i] * dr) / d;
        g[1] = sign_of(p[1]) * dy / d;
        return d;
    }
    if (dr > dy) {
        memcpy(g, radial, 3 * sizeof *g);
        return dr;
    }
    g[0] = g[2] = 0;
    g[1] = sign_of(p[1]);
    return dy;
}

void cs_body_def_pose(const cs_body_def *b, double t, cs_body_pose *pose)
{
    cs_motion_pose(&b->motion, t, pose->R, pose->c, pose->velocity, pose->omega);
    static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    pose->unrotated = true;
    for (int k = 0; k < 9; k++)
        pose->unrotated = pose->unrotated && pose->R[k] == I[k];
}

double cs_body_posed_phi(const cs_body_def *b, const cs_body_pose *pose, const double x[3],
                         double grad[3])
{
    /* Most bodies never turn (the ground, a resting ball): the identity's
     * products give the same numbers but for the sign of a zero, which
     * none of the callers' tests tells apart (the same state hashes), and
     * are a large part of this function's time in B.4 */
    double p[3], g[3];
    cs_sub(x, pose->c, p);
    if (!pose->unrotated)
        cs_mat_apply_transpose(pose->R, p, p); /* in place: it reads a first */
    double phi;
    if (b->phi_fn) {
        phi = b->phi_fn(b->phi_data, p, g);
    } else {
        switch (b->shape) {
        case CS_BODY_SPHERE: phi = phi_sphere(b->radius, p, g); break;
        case CS_BODY_BOX: phi = phi_box(b->half_extents, p, g); break;
        case CS_BODY_CYLINDER: phi = phi_cylinder(b->radius, b->half_height, p, g); break;
        case CS_BODY_PLANE:
        default: phi = phi_plane(p, g); break;
        }
    }
    if (pose->unrotated)
        memcpy(grad, g, sizeof g);
    else
        cs_mat_apply(pose->R, g, grad);
    return phi;
}

double cs_body_def_phi(const cs_body_def *b, double t, const double x[3], double grad[3])
{
    cs_body_pose pose;
    cs_body_def_pose(b, t, &pose);
    return cs_body_posed_phi(b, &pose, x, grad);
}

void cs_body_posed_velocity(const cs_body_pose *pose, const double x[3], double v[3])
{
    double r[3], wr[3];
    cs_sub(x, pose->c, r);
    cs_cross(pose->omega, r, wr);
    for (int i = 0; i < 3; i++)
        v[i] = pose->velocity[i] + wr[i];
}

void cs_body_def_velocity(const cs_body_def *b, double t, const double x[3], double v[3])
{
    cs_body_pose pose;
    cs_body_def_pose(b, t, &pose);
    cs_body_posed_velocity(&pose, x, v);
}

/* Piecewise linear between the keys, constant outside them (the keys are
 * sorted, at most CS_BODY_MAX_FRICTION_KEYS and >= 0: cs_sim_create's
 * check). */
double cs_body_def_friction(const cs_body_def *b, double t)
{
    int n = b->nfriction_keys;
    if (n <= 0)
        return b->friction;
    const cs_friction_key *k = b->friction_keys;
    if (t <= k[0].time)
        return k[0].friction;
    if (t >= k[n - 1].time)
        return k[n - 1].friction;
    int i = 0;
    while (k[i + 1].time <= t)
        i++;
    return k[i].friction +
           (t - k[i].time) / (k[i + 1].time - k[i].time) * (k[i + 1].friction - k[i].friction);
}
