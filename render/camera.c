/* camera.c: the pinhole camera both engines share, automatic framing and
 * turntable orbits. */
#include <math.h>
#include <string.h>

#include "render/internal.h"

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    double r[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    memcpy(out, r, sizeof r);
}

static double normalize3(double a[3])
{
    double n = sqrt(dot3(a, a));
    if (n > 0)
        for (int i = 0; i < 3; i++)
            a[i] /= n;
    return n;
}

static bool finite3(const double a[3])
{
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

int cs_render_camera_check(const cs_render_camera *c, char *err, size_t errlen)
{
    if (!c) {
        cs_render_error(err, errlen, "no camera given");
        return CS_ERR_BAD_INPUT;
    }
    if (!finite3(c->position) || !finite3(c->target) || !finite3(c->up) ||
        !isfinite(c->fov_degrees)) {
        cs_render_error(err, errlen, "the camera has a non-finite position, target, up or fov");
        return CS_ERR_BAD_INPUT;
    }
    if (!(c->fov_degrees > 0 && c->fov_degrees < 180)) {
        cs_render_error(err, errlen, "camera fov must be in (0, 180) degrees (got %g)",
                        c->fov_degrees);
        return CS_ERR_BAD_INPUT;
    }
    double f[3], s[3];
    for (int i = 0; i < 3; i++)
        f[i] = c->target[i] - c->position[i];
    double len = normalize3(f);
    double scale = fmax(sqrt(dot3(c->position, c->position)), 1.0);
    if (!(len > 1e-12 * scale)) {
        cs_render_error(err, errlen, "the camera target is at its position (%g, %g, %g)",
                        c->position[0], c->position[1], c->position[2]);
        return CS_ERR_BAD_INPUT;
    }
    double up[3] = {c->up[0], c->up[1], c->up[2]};
    if (!(normalize3(up) > 0)) {
        cs_render_error(err, errlen, "the camera's up direction is zero");
        return CS_ERR_BAD_INPUT;
    }
    cross3(f, up, s);
    if (!(sqrt(dot3(s, s)) > 1e-6)) {
        cs_render_error(err, errlen, "the camera's up direction is along its view direction");
        return CS_ERR_BAD_INPUT;
    }
    return CS_OK;
}

void cs_camera_basis_make(const cs_render_camera *c, int width, int height, cs_camera_basis *b)
{
    memcpy(b->eye, c->position, sizeof b->eye);
    for (int i = 0; i < 3; i++)
        b->forward[i] = c->target[i] - c->position[i];
    normalize3(b->forward);
    double up[3] = {c->up[0], c->up[1], c->up[2]};
    cross3(b->forward, up, b->right);
    normalize3(b->right);
    cross3(b->right, b->forward, b->up);
    b->tan_half = tan(0.5 * c->fov_degrees * M_PI / 180.0);
    b->aspect = (double)width / (double)height;
}

bool cs_render_camera_project(const cs_render_camera *c, int width, int height,
                              const double p[3], double pixel[2])
{
    if (cs_render_camera_check(c, NULL, 0) != CS_OK || width < 1 || height < 1)
        return false;
    cs_camera_basis b;
    cs_camera_basis_make(c, width, height, &b);
    double d[3];
    for (int i = 0; i < 3; i++)
        d[i] = p[i] - b.eye[i];
    double z = dot3(d, b.forward);
    if (!(z > 0))
        return false;
    double sx = dot3(d, b.right) / z / (b.tan_half * b.aspect);
    double sy = dot3(d, b.up) / z / b.tan_half;
    pixel[0] = 0.5 * (sx + 1.0) * width;
    pixel[1] = 0.5 * (1.0 - sy) * height;
    return true;
}

void cs_render_camera_ray(const cs_render_camera *c, int width, int height, double px, double py,
                          double dir[3])
{
    cs_camera_basis b;
    cs_camera_basis_make(c, width, height, &b);
    double sx = (2.0 * px / width - 1.0) * b.tan_half * b.aspect;
    double sy = (1.0 - 2.0 * py / height) * b.tan_half;
    for (int i = 0; i < 3; i++)
        dir[i] = b.forward[i] + sx * b.right[i] + sy * b.up[i];
    normalize3(dir);
}

bool cs_render_bounds(int nmeshes, const cs_render_mesh *meshes, double lo[3], double hi[3])
{
    bool any = false;
    for (int i = 0; i < 3; i++) {
        lo[i] = INFINITY;
        hi[i] = -INFINITY;
    }
    for (int m = 0; m < nmeshes; m++) {
        if (meshes[m].backdrop || !meshes[m].x)
            continue;
        for (int v = 0; v < meshes[m].nv; v++) {
            const double *p = meshes[m].x + 3 * (size_t)v;
            if (!finite3(p))
                continue;
            for (int i = 0; i < 3; i++) {
                lo[i] = fmin(lo[i], p[i]);
                hi[i] = fmax(hi[i], p[i]);
            }
            any = true;
        }
    }
    return any;
}

cs_render_camera cs_render_camera_frame(const double lo[3], const double hi[3], double aspect)
{
    cs_render_camera c;
    memset(&c, 0, sizeof c);
    c.fov_degrees = 40.0;
    c.up[1] = 1.0;
    double radius = 0;
    for (int i = 0; i < 3; i++) {
        c.target[i] = 0.5 * (lo[i] + hi[i]);
        radius += 0.25 * (hi[i] - lo[i]) * (hi[i] - lo[i]);
    }
    radius = sqrt(radius);
    if (!(radius > 1e-9))
        radius = 0.5;   /* a single point: look at it from a metre or so */
    /* The sphere fits when its angular radius is the smaller half-angle. */
    double half_v = 0.5 * c.fov_degrees * M_PI / 180.0;
    double half_h = atan(tan(half_v) * (aspect > 0 ? aspect : 1.0));
    double half = fmin(half_v, half_h);
    double dist = 1.05 * radius / sin(half);
    double dir[3] = {0.55, 0.45, 0.70};
    normalize3(dir);
    for (int i = 0; i < 3; i++)
        c.position[i] = c.target[i] + dist * dir[i];
    return c;
}

/* Rodrigues' rotation of v about the unit axis k. */
static void rotate3(const double v[3], const double k[3], double cs, double sn, double out[3])
{
    double kxv[3];
    cross3(k, v, kxv);
    double kv = dot3(k, v);
    for (int i = 0; i < 3; i++)
        out[i] = v[i] * cs + kxv[i] * sn + k[i] * kv * (1 - cs);
}

cs_render_camera cs_render_camera_orbit(const cs_render_camera *c, const double centre[3],
                                        const double axis[3], double angle)
{
    cs_render_camera out = *c;
    double k[3] = {axis[0], axis[1], axis[2]};
    if (!(normalize3(k) > 0))
        return out;
    double cs = cos(angle), sn = sin(angle);
    double p[3], t[3];
    for (int i = 0; i < 3; i++) {
        p[i] = c->position[i] - centre[i];
        t[i] = c->target[i] - centre[i];
    }
    rotate3(p, k, cs, sn, out.position);
    rotate3(t, k, cs, sn, out.target);
    rotate3(c->up, k, cs, sn, out.up);
    for (int i = 0; i < 3; i++) {
        out.position[i] += centre[i];
        out.target[i] += centre[i];
    }
    return out;
}
