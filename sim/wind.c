/* wind.c: the wind field of Section 8 (a uniform wind, a ground boost and
 * divergence-free gusts) and the vertex normals and areas its drag acts on. */
#include <math.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"

/* Area-weighted vertex normals and a third of the adjacent area. */
void cs_wind_geometry(cs_sim *sim, const double *x)
{
    memset(sim->wind_normal, 0, sizeof(double) * 3 * (size_t)sim->n);
    memset(sim->wind_area, 0, sizeof(double) * (size_t)sim->n);
    for (int c = 0; c < sim->ncloths; c++) {
        const cs_trimesh *m = sim->cloths[c].mesh;
        int off = sim->cloths[c].offset;
        for (int t = 0; t < m->nt; t++) {
            int a = off + m->tri[3 * t], b = off + m->tri[3 * t + 1], cc = off + m->tri[3 * t + 2];
            double e1[3], e2[3], cr[3];
            cs_sub(x + 3 * b, x + 3 * a, e1);
            cs_sub(x + 3 * cc, x + 3 * a, e2);
            cs_cross(e1, e2, cr); /* |cr| = twice the area */
            int v[3] = {a, b, cc};
            for (int k = 0; k < 3; k++) {
                cs_axpy(1.0, cr, sim->wind_normal + 3 * v[k]);
                sim->wind_area[v[k]] += cs_norm(cr) / 6.0;
            }
        }
    }
    for (int i = 0; i < sim->n; i++) {
        double *nrm = sim->wind_normal + 3 * i, l = cs_norm(nrm);
        if (l > 0)
            for (int d = 0; d < 3; d++)
                nrm[d] /= l;
    }
}

/* The ABC flow's phases advance at these multiples of 2 pi / gust_period:
 * ratios far from simple fractions, so the pattern never repeats exactly. */
static const double GUST_RATE[3] = {1.0, 0.6180339887498949, 0.4142135623730951};

void cs_wind_at(const cs_wind_def *w, const double p[3], double t, double out[3])
{
    double f = 1 - p[1] / w->ground_height;
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    for (int d = 0; d < 3; d++)
        out[d] = w->velocity[d] + f * w->ground_boost[d];
    if (!(w->gust > 0))
        return;
    /* u = A (sin(kz + a_z) + cos(ky + a_y), sin(kx + a_x) + cos(kz + a_z),
     *        sin(ky + a_y) + cos(kx + a_x)): each component depends only on
     * the other two coordinates, so div u = 0; each is the sum of two
     * unit-amplitude waves, so its RMS over space is A. */
    double k = 2 * M_PI / w->gust_length, s = 2 * M_PI * t / w->gust_period, arg[3];
    for (int d = 0; d < 3; d++)
        arg[d] = k * p[d] + GUST_RATE[d] * s;
    out[0] += w->gust * (sin(arg[2]) + cos(arg[1]));
    out[1] += w->gust * (sin(arg[0]) + cos(arg[2]));
    out[2] += w->gust * (sin(arg[1]) + cos(arg[0]));
}

double cs_wind_max_speed(const cs_wind_def *w)
{
    /* each gust component is at most 2 A */
    return cs_norm(w->velocity) + cs_norm(w->ground_boost) + 2 * sqrt(3.0) * w->gust;
}
