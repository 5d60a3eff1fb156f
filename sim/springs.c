/* springs.c: edge and bending springs, their forces and damping operator. */
#include <stdlib.h>
#include <string.h>

#include "sim/springs.h"
#include "sim/vec3.h"

static int reserve(cs_springs *s, int extra)
{
    if (s->n + extra <= s->capacity)
        return 0;
    int cap = s->capacity ? s->capacity : 64;
    while (cap < s->n + extra)
        cap *= 2;
    int *ends = realloc(s->ends, sizeof *ends * 2 * (size_t)cap);
    if (ends)
        s->ends = ends;
    double **arrays[3] = {&s->rest_length, &s->stiffness, &s->damping};
    int ok = ends != NULL;
    for (int k = 0; k < 3 && ok; k++) {
        double *a = realloc(*arrays[k], sizeof *a * (size_t)cap);
        if (a)
            *arrays[k] = a;
        ok = a != NULL;
    }
    double *dir = ok ? realloc(s->direction, sizeof *dir * 3 * (size_t)cap) : NULL;
    if (!dir)
        return -1;
    s->direction = dir;
    s->capacity = cap;
    return 0;
}

static void push(cs_springs *s, int i, int j, const double *x, const double *mass,
                 double E, double xi)
{
    double u[3];
    cs_sub(x + 3 * j, x + 3 * i, u);
    double L0 = cs_norm(u);
    if (!(L0 > 1e-12)) { /* coincident vertices: no direction, no spring */
        s->skipped++;
        return;
    }
    double m_reduced = mass[i] * mass[j] / (mass[i] + mass[j]);
    int k = s->n++;
    s->ends[2 * k] = i;
    s->ends[2 * k + 1] = j;
    s->rest_length[k] = L0;
    s->stiffness[k] = E;
    s->damping[k] = xi * 2.0 * sqrt(E * m_reduced / L0);
    memcpy(s->direction + 3 * k, u, sizeof u);
}

/* An undirected mesh edge with the triangle it came from. */
typedef struct edge_ref {
    int a, b;      /* a < b, local vertex indices */
    int opposite;  /* the triangle's third vertex */
} edge_ref;

static int edge_cmp(const void *pa, const void *pb)
{
    const edge_ref *p = pa, *q = pb;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return (p->opposite > q->opposite) - (p->opposite < q->opposite);
}

int cs_springs_add_mesh(cs_springs *s, int offset, int nv, int nt, const int *tri,
                        const double *x, const double *mass,
                        double edge_E, double edge_xi, double bend_E, double bend_xi)
{
    (void)nv;
    edge_ref *edges = malloc(sizeof *edges * 3 * (size_t)(nt > 0 ? nt : 1));
    if (!edges)
        return -1;
    int ne = 0;
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3], c = tri[3 * t + (k + 2) % 3];
            edges[ne].a = a < b ? a : b;
            edges[ne].b = a < b ? b : a;
            edges[ne].opposite = c;
            ne++;
        }
    qsort(edges, (size_t)ne, sizeof *edges, edge_cmp);

    /* Edge springs first (one per distinct edge), then bending springs. */
    for (int pass = 0; pass < 2; pass++) {
        for (int i = 0; i < ne;) {
            int j = i;
            while (j < ne && edges[j].a == edges[i].a && edges[j].b == edges[i].b)
                j++;
            if (pass == 0) {
                if (reserve(s, 1)) {
                    free(edges);
                    return -1;
                }
                push(s, offset + edges[i].a, offset + edges[i].b, x, mass, edge_E, edge_xi);
            } else {
                /* every pair of triangles on this edge (more than one pair
                 * only where the mesh is non-manifold) */
                for (int p = i; p < j; p++)
                    for (int q = p + 1; q < j; q++) {
                        if (edges[p].opposite == edges[q].opposite)
                            continue; /* duplicate triangle */
                        if (reserve(s, 1)) {
                            free(edges);
                            return -1;
                        }
                        push(s, offset + edges[p].opposite, offset + edges[q].opposite, x,
                             mass, bend_E, bend_xi);
                    }
            }
            i = j;
        }
        if (pass == 0)
            s->nedge = s->n;
    }
    free(edges);
    return 0;
}

void cs_springs_free(cs_springs *s)
{
    free(s->ends);
    free(s->rest_length);
    free(s->stiffness);
    free(s->damping);
    free(s->direction);
    memset(s, 0, sizeof *s);
}

void cs_springs_add_elastic(const cs_springs *s, const double *x, double *f)
{
    for (int k = 0; k < s->n; k++) {
        int i = s->ends[2 * k], j = s->ends[2 * k + 1];
        double u[3];
        cs_sub(x + 3 * j, x + 3 * i, u);
        double l = cs_norm(u);
        if (!(l > 0))
            continue; /* coincident: no direction to push along */
        double mag = s->stiffness[k] * (l / s->rest_length[k] - 1.0) / l;
        cs_axpy(mag, u, f + 3 * i);
        cs_axpy(-mag, u, f + 3 * j);
    }
}

void cs_springs_prepare(cs_springs *s, const double *x)
{
    for (int k = 0; k < s->n; k++) {
        int i = s->ends[2 * k], j = s->ends[2 * k + 1];
        double *u = s->direction + 3 * k;
        cs_sub(x + 3 * j, x + 3 * i, u);
        double l = cs_norm(u);
        if (l > 0) {
            for (int d = 0; d < 3; d++)
                u[d] /= l;
        } else {
            u[0] = u[1] = u[2] = 0;
        }
    }
}

void cs_springs_add_damping(const cs_springs *s, const double *v, double *out)
{
    for (int k = 0; k < s->n; k++) {
        int i = s->ends[2 * k], j = s->ends[2 * k + 1];
        const double *u = s->direction + 3 * k;
        double rel[3];
        cs_sub(v + 3 * j, v + 3 * i, rel);
        double mag = s->damping[k] * cs_dot(rel, u);
        cs_axpy(mag, u, out + 3 * i);
        cs_axpy(-mag, u, out + 3 * j);
    }
}

void cs_springs_add_damping_diagonal(const cs_springs *s, double *diag)
{
    for (int k = 0; k < s->n; k++) {
        int i = s->ends[2 * k], j = s->ends[2 * k + 1];
        const double *u = s->direction + 3 * k;
        for (int d = 0; d < 3; d++) {
            double a = s->damping[k] * u[d] * u[d];
            diag[3 * i + d] += a;
            diag[3 * j + d] += a;
        }
    }
}

double cs_springs_stiffness_bound(const cs_springs *s, const double *mass,
                                  const unsigned char *is_free, int nparticles)
{
    double *sum = calloc((size_t)nparticles + 1, sizeof *sum);
    if (!sum)
        return 0;
    for (int k = 0; k < s->n; k++) {
        double kk = s->stiffness[k] / s->rest_length[k];
        sum[s->ends[2 * k]] += kk;
        sum[s->ends[2 * k + 1]] += kk;
    }
    double bound = 0;
    for (int i = 0; i < nparticles; i++)
        if (is_free[i] && 2.0 * sum[i] / mass[i] > bound)
            bound = 2.0 * sum[i] / mass[i];
    free(sum);
    return bound;
}

void cs_springs_keep_touching(cs_springs *s, const int *owner, int rank)
{
    int kept = 0, kept_edge = 0;
    for (int k = 0; k < s->n; k++) {
        int i = s->ends[2 * k], j = s->ends[2 * k + 1];
        if (owner[i] != rank && owner[j] != rank)
            continue;
        s->ends[2 * kept] = i;
        s->ends[2 * kept + 1] = j;
        s->rest_length[kept] = s->rest_length[k];
        s->stiffness[kept] = s->stiffness[k];
        s->damping[kept] = s->damping[k];
        kept_edge += k < s->nedge;
        kept++;
    }
    s->n = kept;
    s->nedge = kept_edge;
}
