/* tessellate.c: triangle meshes of the analytic bodies at a time t, for
 * drawing. The simulation never uses them (it queries phi); the renderer
 * does, so they live beside the shapes they approximate.
 *
 * Vertices are shared only where the surface is smooth (the sphere, the side
 * of a cylinder): a renderer that averages triangle normals at shared
 * vertices then shades curved parts smoothly and keeps the edges of boxes
 * and cylinder caps sharp. Triangles wind counter-clockwise seen from
 * outside, so their normals point out of the body. */
#include <stdlib.h>

#include "sim/sim.h"
#include "sim/vec3.h"

typedef struct builder {
    cs_trimesh *m;
    int nv, nt;
} builder;

static int add_vertex(builder *b, double x, double y, double z)
{
    double *p = b->m->x + 3 * b->nv;
    p[0] = x;
    p[1] = y;
    p[2] = z;
    return b->nv++;
}

static void add_triangle(builder *b, int i, int j, int k)
{
    int *t = b->m->tri + 3 * b->nt++;
    t[0] = i;
    t[1] = j;
    t[2] = k;
}

/* a, b, c, d counter-clockwise seen from outside. */
static void add_quad(builder *b, int v0, int v1, int v2, int v3)
{
    add_triangle(b, v0, v1, v2);
    add_triangle(b, v0, v2, v3);
}

/* Latitude-longitude sphere: poles on local y, `slices` around, `stacks`
 * from pole to pole. */
static void sphere(builder *b, double r, int slices, int stacks)
{
    int north = add_vertex(b, 0, r, 0);
    int first = b->nv;
    for (int i = 1; i < stacks; i++) {
        double th = M_PI * i / stacks;
        for (int j = 0; j < slices; j++) {
            double ph = 2 * M_PI * j / slices;
            add_vertex(b, r * sin(th) * cos(ph), r * cos(th), r * sin(th) * sin(ph));
        }
    }
    int south = add_vertex(b, 0, -r, 0);
    /* Going along +phi, then +theta, turns counter-clockwise about the
     * outward normal. */
    for (int j = 0; j < slices; j++) {
        int jn = (j + 1) % slices;
        add_triangle(b, north, first + jn, first + j);
        for (int i = 0; i + 2 < stacks; i++) {
            int row = first + i * slices, next = row + slices;
            add_quad(b, row + j, row + jn, next + jn, next + j);
        }
        int last = first + (stacks - 2) * slices;
        add_triangle(b, last + j, last + jn, south);
    }
}

static void box(builder *b, const double h[3])
{
    /* Per face: outward axis and sign, then tangents u, v with u x v = n. */
    static const int faces[6][4] = {
        {0, +1, 1, 2}, {0, -1, 2, 1}, {1, +1, 2, 0},
        {1, -1, 0, 2}, {2, +1, 0, 1}, {2, -1, 1, 0},
    };
    static const double corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int f = 0; f < 6; f++) {
        int n = faces[f][0], u = faces[f][2], v = faces[f][3];
        int idx[4];
        for (int k = 0; k < 4; k++) {
            double p[3];
            p[n] = faces[f][1] * h[n];
            p[u] = corners[k][0] * h[u];
            p[v] = corners[k][1] * h[v];
            idx[k] = add_vertex(b, p[0], p[1], p[2]);
        }
        add_quad(b, idx[0], idx[1], idx[2], idx[3]);
    }
}

/* Capped cylinder on local y; the caps have their own rim vertices so the
 * edge between side and cap stays sharp. */
static void cylinder(builder *b, double r, double hh, int slices)
{
    int side = b->nv;
    for (int j = 0; j < slices; j++) {
        double ph = 2 * M_PI * j / slices;
        add_vertex(b, r * cos(ph), -hh, r * sin(ph));
        add_vertex(b, r * cos(ph), hh, r * sin(ph));
    }
    for (int j = 0; j < slices; j++) {
        int jn = (j + 1) % slices;
        add_quad(b, side + 2 * j, side + 2 * j + 1, side + 2 * jn + 1, side + 2 * jn);
    }
    for (int cap = 0; cap < 2; cap++) {
        double y = cap ? hh : -hh;
        int centre = add_vertex(b, 0, y, 0);
        int rim = b->nv;
        for (int j = 0; j < slices; j++) {
            double ph = 2 * M_PI * j / slices;
            add_vertex(b, r * cos(ph), y, r * sin(ph));
        }
        for (int j = 0; j < slices; j++) {
            int jn = (j + 1) % slices;
            if (cap)
                add_triangle(b, centre, rim + jn, rim + j);
            else
                add_triangle(b, centre, rim + j, rim + jn);
        }
    }
}

cs_trimesh *cs_body_def_tessellate(const cs_body_def *body, double t, double plane_extent,
                                   int detail)
{
    if (!body || body->phi_fn)
        return NULL;
    int slices = detail < 3 ? 3 : detail;
    if (slices > 4096)
        slices = 4096;
    int stacks = slices / 2 < 2 ? 2 : slices / 2;
    int nv, nt;
    switch (body->shape) {
    case CS_BODY_PLANE:
        if (!(plane_extent > 0) || !isfinite(plane_extent))
            return NULL;
        nv = 4, nt = 2;
        break;
    case CS_BODY_SPHERE:
        if (!(body->radius > 0))
            return NULL;
        nv = 2 + (stacks - 1) * slices, nt = 2 * slices * (stacks - 1);
        break;
    case CS_BODY_BOX:
        for (int i = 0; i < 3; i++)
            if (!(body->half_extents[i] > 0))
                return NULL;
        nv = 24, nt = 12;
        break;
    case CS_BODY_CYLINDER:
        if (!(body->radius > 0) || !(body->half_height > 0))
            return NULL;
        nv = 4 * slices + 2, nt = 4 * slices;
        break;
    default:
        return NULL;
    }
    builder b = {cs_trimesh_create(nv, nt), 0, 0};
    if (!b.m)
        return NULL;
    switch (body->shape) {
    case CS_BODY_PLANE: {
        /* The order of argument evaluation is unspecified: name each corner. */
        double e = plane_extent;
        int v0 = add_vertex(&b, -e, 0, -e), v1 = add_vertex(&b, -e, 0, e);
        int v2 = add_vertex(&b, e, 0, e), v3 = add_vertex(&b, e, 0, -e);
        add_quad(&b, v0, v1, v2, v3);
        break;
    }
    case CS_BODY_SPHERE: sphere(&b, body->radius, slices, stacks); break;
    case CS_BODY_BOX: box(&b, body->half_extents); break;
    case CS_BODY_CYLINDER: cylinder(&b, body->radius, body->half_height, slices); break;
    default: break;
    }
    /* Local to world at time t: c(t) + R(t) p. */
    double R[9], c[3];
    cs_motion_pose(&body->motion, t, R, c, NULL, NULL);
    for (int i = 0; i < b.nv; i++) {
        double *p = b.m->x + 3 * i, w[3];
        cs_mat_apply(R, p, w);
        for (int d = 0; d < 3; d++)
            p[d] = c[d] + w[d];
    }
    return b.m;
}
