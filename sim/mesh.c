/* mesh.c: triangle meshes and the generated rectangle grid. */
#include <math.h>
#include <stdlib.h>

#include "sim/internal.h"
#include "sim/sim.h"
#include "sim/vec3.h"

cs_trimesh *cs_trimesh_create(int nv, int nt)
{
    if (nv < 0 || nt < 0)
        return NULL;
    cs_trimesh *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->nv = nv;
    m->nt = nt;
    m->x = calloc((size_t)nv * 3 + 1, sizeof *m->x);
    m->tri = calloc((size_t)nt * 3 + 1, sizeof *m->tri);
    if (!m->x || !m->tri) {
        cs_trimesh_destroy(m);
        return NULL;
    }
    return m;
}

void cs_trimesh_destroy(cs_trimesh *m)
{
    if (!m)
        return;
    free(m->x);
    free(m->tri);
    free(m);
}

double cs_trimesh_mean_edge(const cs_trimesh *m)
{
    double sum = 0;
    for (int t = 0; t < m->nt; t++)
        for (int k = 0; k < 3; k++) {
            double d[3];
            cs_sub(m->x + 3 * m->tri[3 * t + k], m->x + 3 * m->tri[3 * t + (k + 1) % 3], d);
            sum += cs_norm(d);
        }
    return m->nt > 0 ? sum / (3.0 * m->nt) : 0;
}

cs_trimesh *cs_trimesh_create_grid(const double size[2], const int res[2],
                                   const double rotate[4], const double center[3])
{
    if (res[0] < 1 || res[1] < 1 || !(size[0] > 0) || !(size[1] > 0))
        return NULL;
    int nx = res[0] + 1, nz = res[1] + 1;
    cs_trimesh *m = cs_trimesh_create(nx * nz, 2 * res[0] * res[1]);
    if (!m)
        return NULL;
    double q[4] = {rotate[0], rotate[1], rotate[2], rotate[3]}, R[9];
    cs_quat_normalize(q);
    cs_quat_to_matrix(q, R);
    for (int j = 0; j < nz; j++)
        for (int i = 0; i < nx; i++) {
            double p[3] = {((double)i / res[0] - 0.5) * size[0], 0.0,
                           ((double)j / res[1] - 0.5) * size[1]};
            double *out = m->x + 3 * (j * nx + i);
            cs_mat_apply(R, p, out);
            for (int d = 0; d < 3; d++)
                out[d] += center[d];
        }
    /* Alternate the diagonal so the mesh has no preferred shear direction;
     * every triangle is wound so its normal is the local +y. */
    int *t = m->tri;
    for (int j = 0; j < res[1]; j++)
        for (int i = 0; i < res[0]; i++) {
            int v00 = j * nx + i, v10 = v00 + 1, v01 = v00 + nx, v11 = v01 + 1;
            if ((i + j) % 2 == 0) {
                int a[6] = {v00, v01, v11, v00, v11, v10};
                for (int k = 0; k < 6; k++)
                    *t++ = a[k];
            } else {
                int a[6] = {v00, v01, v10, v10, v01, v11};
                for (int k = 0; k < 6; k++)
                    *t++ = a[k];
            }
        }
    return m;
}

static int cmp_int2(const void *a, const void *b)
{
    const int *p = a, *q = b;
    if (p[0] != q[0])
        return p[0] < q[0] ? -1 : 1;
    return (p[1] > q[1]) - (p[1] < q[1]);
}

int cs_sort_unique_pairs(int *pairs, int n)
{
    qsort(pairs, (size_t)n, 2 * sizeof *pairs, cmp_int2);
    int u = 0;
    for (int k = 0; k < n; k++)
        if (u == 0 || pairs[2 * k] != pairs[2 * (u - 1)] ||
            pairs[2 * k + 1] != pairs[2 * (u - 1) + 1]) {
            pairs[2 * u] = pairs[2 * k];
            pairs[2 * u + 1] = pairs[2 * k + 1];
            u++;
        }
    return u;
}
