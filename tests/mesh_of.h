/* mesh_of.h: a triangle mesh from literal vertices and triangles, for the
 * tests that build tiny scenes by hand. */
#ifndef CS_TESTS_MESH_OF_H
#define CS_TESTS_MESH_OF_H

#include <string.h>

#include "sim/sim.h"

static cs_trimesh *mesh_of(int nv, const double *x, int nt, const int *tri)
{
    cs_trimesh *m = cs_trimesh_create(nv, nt);
    assert_non_null(m);
    memcpy(m->x, x, sizeof *x * 3 * (size_t)nv);
    if (nt > 0)
        memcpy(m->tri, tri, sizeof *tri * 3 * (size_t)nt);
    return m;
}

#endif
