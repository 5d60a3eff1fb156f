/* grid_cloth.h: a small jittered grid cloth for the simulation core's
 * tests (test_sim_core.c, test_sim_step.c). Include after cmocka.h and
 * sim/internal.h. */
#ifndef CS_TESTS_GRID_CLOTH_H
#define CS_TESTS_GRID_CLOTH_H

#include <string.h>

static inline double frand(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return ((*seed >> 8) & 0xffff) / 65535.0 * 2.0 - 1.0;
}

/* A small jittered grid cloth definition; the mesh is returned for freeing. */
static inline cs_sim_def grid_def(cs_cloth_def *cloth, cs_trimesh **mesh, int res, unsigned seed)
{
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 1, 0};
    int r[2] = {res, res};
    *mesh = cs_trimesh_create_grid(size, r, q, c);
    for (int k = 0; k < 3 * (*mesh)->nv; k++)
        (*mesh)->x[k] += 0.01 * frand(&seed);
    memset(cloth, 0, sizeof *cloth);
    cloth->name = "grid";
    cloth->mesh = *mesh;
    cloth->material = cs_default_cloth_material();
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = cloth;
    return def;
}

#endif
