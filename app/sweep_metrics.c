/* sweep_metrics.c: a sweep run's counters and its error against the
 * reference (see sweep_metrics.h for the metrics). */
#include "app/sweep_metrics.h"

#include "app/run.h"
#include "common/util.h"
#include "sim/sim.h"

#include <cJSON.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ tightness */

bool cs_sweep_key_matches(const char *pattern, const char *key)
{
    for (; *pattern; pattern++) {
        if (*pattern == '*') {
            if (*key < '0' || *key > '9')
                return false;
            while (*key >= '0' && *key <= '9')
                key++;
        } else if (*key++ != *pattern) {
            return false;
        }
    }
    return *key == '\0';
}

double cs_sweep_measure(const char *value)
{
    double m = 1;
    int numbers = 0;
    for (const char *p = value; *p;) {
        if (strchr("[], \t", *p)) {
            p++;
            continue;
        }
        char *end;
        double v = strtod(p, &end);
        if (end == p || !(v > 0))
            return NAN;
        m *= v;
        numbers++;
        p = end;
    }
    return numbers ? m : NAN;
}

/* ---------------------------------------------------------------- counters */

static double num(const cJSON *obj, const char *key, double missing)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    return cJSON_IsNumber(v) ? v->valuedouble : missing;
}

int cs_sweep_read_counts(const char *dir, cs_sweep_counts *c, char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    c->intersections = -1;
    c->penetration = -1;
    char path[4096];
    snprintf(path, sizeof path, "%s/summary.json", dir);
    size_t len;
    char *text = cs_file_read_all(path, &len);
    if (!text) {
        snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
        return -1;
    }
    cJSON *root = cJSON_Parse(text);
    free(text);
    const cJSON *status = cJSON_GetObjectItemCaseSensitive(root, "status");
    const cJSON *frames = cJSON_GetObjectItemCaseSensitive(root, "frames");
    if (!cJSON_IsString(status) || !cJSON_IsArray(frames)) {
        snprintf(err, errlen, "%s: not the final summary of a 'clothsim run'", path);
        cJSON_Delete(root);
        return -1;
    }
    snprintf(c->status, sizeof c->status, "%s", status->valuestring);
    c->frames_written = (int)num(root, "frames_written", 0);
    c->seconds = malloc(((size_t)cJSON_GetArraySize(frames) + 1) * sizeof *c->seconds);
    if (!c->seconds) {
        snprintf(err, errlen, "out of memory");
        cJSON_Delete(root);
        return -1;
    }
    const cJSON *f;
    cJSON_ArrayForEach(f, frames) {
        c->seconds[c->nseconds++] = num(f, "seconds", NAN);
        c->steps += (long)num(f, "steps", 0);
        c->cg_iterations += (long)num(f, "cg_iterations", 0);
        c->collisions += (long)num(f, "collisions", 0);
        c->impact_zones += (long)num(f, "impact_zones", 0);
        long pairs = (long)num(f, "intersections", -1);
        if (pairs > c->intersections)
            c->intersections = pairs;
        double pen = num(f, "body_penetration_max", -1);
        if (pen > c->penetration)
            c->penetration = pen;
    }
    cJSON_Delete(root);
    return 0;
}

void cs_sweep_counts_free(cs_sweep_counts *c)
{
    free(c->seconds);
    c->seconds = NULL;
    c->nseconds = 0;
}

/* ---------------------------------------------------------------- analytic */

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

int cs_sweep_analytic_init(const cs_sim_def *def, cs_sweep_analytic *an, char *err,
                           size_t errlen)
{
    memset(an, 0, sizeof *an);
    const cs_body_def *plane = NULL;
    int nplanes = 0;
    for (int b = 0; b < def->nbodies; b++)
        if (def->bodies[b].shape == CS_BODY_PLANE && !def->bodies[b].phi_fn)
            plane = &def->bodies[b], nplanes++;
    if (nplanes != 1 || !def->bodies_enabled) {
        snprintf(err, errlen, "--analytic incline needs the scene to have one plane body "
                              "(it has %d) and body collisions on", nplanes);
        return -1;
    }
    if (plane->nfriction_keys > 0) {
        snprintf(err, errlen, "--analytic incline needs a constant friction (body %s has a "
                              "schedule)", plane->name ? plane->name : "0");
        return -1;
    }
    double origin[3] = {0, 0, 0}, n[3];
    cs_body_def_phi(plane, 0, origin, n); /* a plane's gradient: its normal */
    double g = sqrt(dot3(def->gravity, def->gravity)), gn = dot3(def->gravity, n);
    if (!(g > 0) || !(gn < 0) || def->ncloths < 1 || !(def->fps > 0)) {
        snprintf(err, errlen, "--analytic incline needs a cloth, frames per second, and "
                              "gravity pressing the cloth onto the plane");
        return -1;
    }
    const double *v = def->cloths[0].velocity;
    for (int c = 1; c < def->ncloths; c++)
        if (memcmp(def->cloths[c].velocity, v, sizeof def->cloths[c].velocity) != 0) {
            snprintf(err, errlen, "--analytic incline needs every cloth to start at the same "
                                  "velocity (a rigid body)");
            return -1;
        }
    double gt[3], vt[3], vn = dot3(v, n);
    for (int k = 0; k < 3; k++) {
        gt[k] = def->gravity[k] - gn * n[k];
        vt[k] = v[k] - vn * n[k];
    }
    double gtl = sqrt(dot3(gt, gt)), vtl = sqrt(dot3(vt, vt));
    /* downhill; on a level plane the way the cloth starts to slide */
    const double *dir = gtl > 1e-12 * g ? gt : vtl > 0 ? vt : NULL;
    double len = gtl > 1e-12 * g ? gtl : vtl;
    if (dir) {
        for (int k = 0; k < 3; k++)
            an->down[k] = dir[k] / len;
    } else { /* level and at rest: it stays; any direction in the plane */
        double e[3] = {fabs(n[0]) < 0.9 ? 1 : 0, fabs(n[0]) < 0.9 ? 0 : 1, 0};
        double en = dot3(e, n), l = 0;
        for (int k = 0; k < 3; k++)
            an->down[k] = e[k] - en * n[k], l += an->down[k] * an->down[k];
        for (int k = 0; k < 3; k++)
            an->down[k] /= sqrt(l);
    }
    an->motion = (cs_incline){g, gtl > 1e-12 * g ? gtl / g : 0, -gn / g, plane->friction,
                              dot3(vt, an->down)};
    an->fps = def->fps;
    return 0;
}

/* ----------------------------------------------------------------- surface */

/* A frame's cloths as one surface. */
typedef struct surface {
    int ncloths;
    int *cloth_nv;   /* per cloth its vertex count */
    int nv, nt;
    double *x;       /* 3 per vertex */
    int *tri;        /* 3 per triangle, into x */
} surface;

static void surface_free(surface *s)
{
    free(s->cloth_nv);
    free(s->x);
    free(s->tri);
    memset(s, 0, sizeof *s);
}

/* Reads frame of the run in dir as one surface. Returns an exit status. */
static int surface_read(const cs_frame_layout *l, const char *dir, int frame, surface *s,
                        char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    char frames_dir[4096];
    snprintf(frames_dir, sizeof frames_dir, "%s/frames", dir);
    int n = l->ncloths;
    cs_trimesh **m = calloc(n > 0 ? (size_t)n : 1, sizeof *m);
    if (!m) {
        snprintf(err, errlen, "out of memory");
        return CS_EXIT_OUTPUT;
    }
    int status = cs_frame_read(l, frames_dir, frame, m, err, errlen);
    for (int c = 0; status == CS_EXIT_OK && c < n; c++) {
        s->nv += m[c]->nv;
        s->nt += m[c]->nt;
    }
    if (status == CS_EXIT_OK) {
        s->ncloths = n;
        s->cloth_nv = calloc(n > 0 ? (size_t)n : 1, sizeof *s->cloth_nv);
        s->x = malloc((size_t)(s->nv > 0 ? s->nv : 1) * 3 * sizeof *s->x);
        s->tri = malloc((size_t)(s->nt > 0 ? s->nt : 1) * 3 * sizeof *s->tri);
        if (!s->cloth_nv || !s->x || !s->tri) {
            snprintf(err, errlen, "out of memory");
            status = CS_EXIT_OUTPUT;
        }
    }
    for (int c = 0, v0 = 0, t0 = 0; status == CS_EXIT_OK && c < n; c++) {
        s->cloth_nv[c] = m[c]->nv;
        memcpy(s->x + 3 * (size_t)v0, m[c]->x, 3 * (size_t)m[c]->nv * sizeof *s->x);
        for (int k = 0; k < 3 * m[c]->nt; k++)
            s->tri[3 * (size_t)t0 + k] = m[c]->tri[k] + v0;
        v0 += m[c]->nv;
        t0 += m[c]->nt;
    }
    for (int c = 0; c < n; c++)
        cs_trimesh_destroy(m[c]);
    free(m);
    if (status != CS_EXIT_OK)
        surface_free(s);
    return status;
}

static bool same_vertices(const surface *a, const surface *b)
{
    if (a->ncloths != b->ncloths)
        return false;
    for (int c = 0; c < a->ncloths; c++)
        if (a->cloth_nv[c] != b->cloth_nv[c])
            return false;
    return true;
}

static double dist3(const double *a, const double *b)
{
    double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

/* Area-weighted centroid (the centre of mass at uniform density); the mean
 * vertex when the surface has no area. */
static void centroid(const surface *s, double out[3])
{
    double sum[3] = {0, 0, 0}, area = 0;
    for (int t = 0; t < s->nt; t++) {
        const double *a = s->x + 3 * s->tri[3 * t], *b = s->x + 3 * s->tri[3 * t + 1],
                     *c = s->x + 3 * s->tri[3 * t + 2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        double w = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            sum[k] += w * (a[k] + b[k] + c[k]) / 3.0;
        area += w;
    }
    if (area > 0) {
        for (int k = 0; k < 3; k++)
            out[k] = sum[k] / area;
        return;
    }
    for (int k = 0; k < 3; k++) {
        out[k] = 0;
        for (int v = 0; v < s->nv; v++)
            out[k] += s->x[3 * v + k] / s->nv;
    }
}

static void bounds(const surface *s, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = DBL_MAX;
        hi[k] = -DBL_MAX;
    }
    for (int v = 0; v < s->nv; v++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], s->x[3 * v + k]);
            hi[k] = fmax(hi[k], s->x[3 * v + k]);
        }
}

/* ------------------------------------------------------ point to triangles */

/* Squared distance from p to triangle abc (Ericson, Real-Time Collision
 * Detection, 5.1.5). */
static double point_triangle_dist2(const double *p, const double *a, const double *b,
                                   const double *c)
{
    double ab[3], ac[3], ap[3], q[3];
    for (int k = 0; k < 3; k++) {
        ab[k] = b[k] - a[k];
        ac[k] = c[k] - a[k];
        ap[k] = p[k] - a[k];
    }
#define DOT(u, v) ((u)[0] * (v)[0] + (u)[1] * (v)[1] + (u)[2] * (v)[2])
    double d1 = DOT(ab, ap), d2 = DOT(ac, ap);
    double v = 0, w = 0;
    if (d1 <= 0 && d2 <= 0) {
        v = w = 0; /* a */
    } else {
        double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
        double d3 = DOT(ab, bp), d4 = DOT(ac, bp);
        double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
        double d5 = DOT(ab, cp), d6 = DOT(ac, cp);
        double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d3 >= 0 && d4 <= d3) {
            v = 1; /* b */
        } else if (d6 >= 0 && d5 <= d6) {
            w = 1; /* c */
        } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
            v = d1 / (d1 - d3); /* edge ab */
        } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
            w = d2 / (d2 - d6); /* edge ac */
        } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
            w = (d4 - d3) / ((d4 - d3) + (d5 - d6)); /* edge bc */
            v = 1 - w;
        } else {
            double denom = va + vb + vc;
            v = denom != 0 ? vb / denom : 0;
            w = denom != 0 ? vc / denom : 0;
        }
    }
#undef DOT
    for (int k = 0; k < 3; k++)
        q[k] = a[k] + v * ab[k] + w * ac[k];
    double d = dist3(p, q);
    return d * d;
}

/* A uniform grid of a surface's triangles: each triangle listed in every
 * cell its bounding box touches (CSR: cell c holds items[start[c]..start[c+1])). */
typedef struct tri_grid {
    const surface *s;
    double lo[3], h;
    int dim[3];
    int *start, *items;
} tri_grid;

static long cell_index(const tri_grid *g, int i, int j, int k)
{
    return ((long)k * g->dim[1] + j) * g->dim[0] + i;
}

static int clamp_cell(const tri_grid *g, int axis, double x)
{
    double f = floor((x - g->lo[axis]) / g->h);
    if (!(f >= 0))
        return 0;
    return f >= g->dim[axis] ? g->dim[axis] - 1 : (int)f;
}

/* Calls fn for each cell of triangle t's bounding box (both passes of the build). */
static void tri_cells(const tri_grid *g, int t, int lo[3], int hi[3])
{
    for (int k = 0; k < 3; k++) {
        double a = g->s->x[3 * g->s->tri[3 * t] + k], b = g->s->x[3 * g->s->tri[3 * t + 1] + k],
               c = g->s->x[3 * g->s->tri[3 * t + 2] + k];
        lo[k] = clamp_cell(g, k, fmin(a, fmin(b, c)));
        hi[k] = clamp_cell(g, k, fmax(a, fmax(b, c)));
    }
}

static void grid_free(tri_grid *g)
{
    free(g->start);
    free(g->items);
}

/* Cells about the size of a triangle, but no more cells than about 2 per
 * triangle (a crumpled cloth fills a volume). Returns 0, or -1 when memory
 * runs out. */
static int grid_build(tri_grid *g, const surface *s)
{
    memset(g, 0, sizeof *g);
    g->s = s;
    double lo[3], hi[3], edge = 0;
    bounds(s, lo, hi);
    for (int t = 0; t < s->nt; t++)
        edge += dist3(s->x + 3 * s->tri[3 * t], s->x + 3 * s->tri[3 * t + 1]);
    edge = s->nt > 0 ? edge / s->nt : 1;
    double ext[3], vol = 1;
    for (int k = 0; k < 3; k++) {
        ext[k] = s->nv > 0 ? hi[k] - lo[k] : 0;
        vol *= ext[k] + edge;
        g->lo[k] = s->nv > 0 ? lo[k] : 0;
    }
    g->h = fmax(edge, cbrt(vol / (2.0 * (s->nt > 0 ? s->nt : 1))));
    if (!(g->h > 0))
        g->h = 1;
    long ncells = 1;
    for (int k = 0; k < 3; k++) {
        g->dim[k] = (int)fmin(ext[k] / g->h, 1 << 20) + 1;
        ncells *= g->dim[k];
    }
    g->start = calloc((size_t)ncells + 1, sizeof *g->start);
    if (!g->start)
        return -1;
    int lo_c[3], hi_c[3];
    for (int pass = 0; pass < 2; pass++) {
        for (int t = 0; t < s->nt; t++) {
            tri_cells(g, t, lo_c, hi_c);
            for (int k = lo_c[2]; k <= hi_c[2]; k++)
                for (int j = lo_c[1]; j <= hi_c[1]; j++)
                    for (int i = lo_c[0]; i <= hi_c[0]; i++) {
                        long c = cell_index(g, i, j, k);
                        if (pass == 0)
                            g->start[c + 1]++;
                        else
                            g->items[g->start[c]++] = t;
                    }
        }
        if (pass == 0) {
            for (long c = 0; c < ncells; c++)
                g->start[c + 1] += g->start[c];
            g->items = malloc((size_t)(g->start[ncells] > 0 ? g->start[ncells] : 1) *
                              sizeof *g->items);
            if (!g->items)
                return -1;
        } else { /* start[c] advanced to start[c + 1]: shift back */
            for (long c = ncells; c > 0; c--)
                g->start[c] = g->start[c - 1];
            g->start[0] = 0;
        }
    }
    return 0;
}

/* Distance from p to the nearest triangle of the grid: rings of cells
 * around p's (clamped) cell until no unvisited cell can be nearer (a cell
 * r rings out is at least (r - 1) h away). */
static double grid_distance(const tri_grid *g, const double *p)
{
    const surface *s = g->s;
    if (s->nt == 0)
        return NAN;
    int c0[3];
    for (int k = 0; k < 3; k++)
        c0[k] = clamp_cell(g, k, p[k]);
    int rmax = g->dim[0];
    if (g->dim[1] > rmax)
        rmax = g->dim[1];
    if (g->dim[2] > rmax)
        rmax = g->dim[2];
    double best = INFINITY;
    for (int r = 0; r <= rmax; r++) {
        if (r > 0 && sqrt(best) <= (r - 1) * g->h)
            break;
        for (int k = c0[2] - r; k <= c0[2] + r; k++)
            for (int j = c0[1] - r; j <= c0[1] + r; j++)
                for (int i = c0[0] - r; i <= c0[0] + r; i++) {
                    if (i < 0 || j < 0 || k < 0 || i >= g->dim[0] || j >= g->dim[1] ||
                        k >= g->dim[2])
                        continue;
                    if (abs(i - c0[0]) != r && abs(j - c0[1]) != r && abs(k - c0[2]) != r)
                        continue; /* inside: an earlier ring */
                    long c = cell_index(g, i, j, k);
                    for (int n = g->start[c]; n < g->start[c + 1]; n++) {
                        const int *t = s->tri + 3 * g->items[n];
                        double d2 = point_triangle_dist2(p, s->x + 3 * t[0], s->x + 3 * t[1],
                                                         s->x + 3 * t[2]);
                        if (d2 < best)
                            best = d2;
                    }
                }
    }
    return sqrt(best);
}

/* The largest distance from a vertex of a to the triangles of b's grid. */
static double one_sided(const surface *a, const tri_grid *b)
{
    double worst = 0;
    for (int v = 0; v < a->nv; v++) {
        double d = grid_distance(b, a->x + 3 * v);
        if (!(d <= worst)) /* NaN too */
            worst = d;
    }
    return worst;
}

/* ----------------------------------------------------------------- compare */

double cs_sweep_error_headline(const cs_sweep_error *e)
{
    return !isnan(e->analytic) ? e->analytic : isnan(e->vertex_max) ? e->hausdorff
                                                                     : e->vertex_max;
}

static int frame_error(const surface *a, const surface *ref, cs_sweep_error *e)
{
    e->vertex_rms = e->vertex_max = NAN;
    if (same_vertices(a, ref)) {
        double sum = 0, worst = 0;
        for (int v = 0; v < a->nv; v++) {
            double d = dist3(a->x + 3 * v, ref->x + 3 * v);
            sum += d * d;
            worst = fmax(worst, d);
        }
        e->vertex_rms = a->nv > 0 ? sqrt(sum / a->nv) : 0;
        e->vertex_max = worst;
    }
    double ca[3], cr[3], la[3], ha[3], lr[3], hr[3];
    centroid(a, ca);
    centroid(ref, cr);
    e->com = dist3(ca, cr);
    bounds(a, la, ha);
    bounds(ref, lr, hr);
    e->bbox = 0;
    for (int k = 0; k < 3; k++)
        e->bbox = fmax(e->bbox, fmax(fabs(la[k] - lr[k]), fabs(ha[k] - hr[k])));
    tri_grid ga, gr;
    int rc = grid_build(&ga, a) == 0 && grid_build(&gr, ref) == 0 ? 0 : -1;
    if (rc == 0)
        e->hausdorff = fmax(one_sided(a, &gr), one_sided(ref, &ga));
    grid_free(&ga);
    grid_free(&gr);
    return rc;
}

/* The larger, NaN only when both are. */
static double worse(double a, double b)
{
    return isnan(a) ? b : isnan(b) ? a : fmax(a, b);
}

static void csv_num(FILE *out, double v, const char *sep)
{
    if (isnan(v))
        fprintf(out, "%s", sep);
    else
        fprintf(out, "%.9g%s", v, sep);
}

/* The run's centre of mass at frame f against the analytic body's, which
 * starts at the run's frame 0 (c0): the error, and the distances travelled
 * downhill by both. */
static void analytic_frame(const cs_sweep_analytic *an, const double c0[3], const surface *a,
                           int f, double *error, double *travel, double *exact)
{
    double c[3], v, d[3];
    centroid(a, c);
    cs_incline_motion(&an->motion, f / an->fps, exact, &v);
    for (int k = 0; k < 3; k++)
        d[k] = c[k] - (c0[k] + *exact * an->down[k]);
    *error = sqrt(dot3(d, d));
    for (int k = 0; k < 3; k++)
        d[k] = c[k] - c0[k];
    *travel = dot3(d, an->down);
}

int cs_sweep_compare(const cs_frame_layout *layout, const char *dir, const char *ref_dir,
                     int frames, const cs_sweep_analytic *an, FILE *per_frame, double *travel,
                     cs_sweep_error *overall, char *err, size_t errlen)
{
    overall->vertex_rms = overall->vertex_max = overall->com = overall->bbox =
        overall->hausdorff = overall->analytic = NAN;
    if (per_frame)
        fprintf(per_frame, "frame,vertex_rms_m,vertex_max_m,com_m,bbox_m,hausdorff_m%s\n",
                an ? ",analytic_m,travel_m,travel_analytic_m" : "");
    double c0[3] = {0, 0, 0};
    for (int f = 0; f < frames; f++) {
        surface a, ref;
        int status = surface_read(layout, dir, f, &a, err, errlen);
        if (status != CS_EXIT_OK)
            return status;
        if ((status = surface_read(layout, ref_dir, f, &ref, err, errlen)) != CS_EXIT_OK) {
            surface_free(&a);
            return status;
        }
        cs_sweep_error e;
        int rc = frame_error(&a, &ref, &e);
        double moved = NAN, exact = NAN;
        e.analytic = NAN;
        if (an && f == 0)
            centroid(&a, c0);
        if (an)
            analytic_frame(an, c0, &a, f, &e.analytic, &moved, &exact);
        if (travel)
            travel[f] = moved;
        surface_free(&a);
        surface_free(&ref);
        if (rc != 0) {
            snprintf(err, errlen, "out of memory");
            return CS_EXIT_OUTPUT;
        }
        overall->vertex_rms = worse(overall->vertex_rms, e.vertex_rms);
        overall->vertex_max = worse(overall->vertex_max, e.vertex_max);
        overall->com = worse(overall->com, e.com);
        overall->bbox = worse(overall->bbox, e.bbox);
        overall->hausdorff = worse(overall->hausdorff, e.hausdorff);
        overall->analytic = worse(overall->analytic, e.analytic);
        if (per_frame) {
            fprintf(per_frame, "%d,", f);
            csv_num(per_frame, e.vertex_rms, ",");
            csv_num(per_frame, e.vertex_max, ",");
            csv_num(per_frame, e.com, ",");
            csv_num(per_frame, e.bbox, ",");
            csv_num(per_frame, e.hausdorff, an ? "," : "\n");
            if (an) {
                csv_num(per_frame, e.analytic, ",");
                csv_num(per_frame, moved, ",");
                csv_num(per_frame, exact, "\n");
            }
        }
    }
    return CS_EXIT_OK;
}
