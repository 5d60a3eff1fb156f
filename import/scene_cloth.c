/* scene_cloth.c: a cloth of a scene: its grid or mesh, its pins and
 * scripts (selections of vertices and their motions). */
#include "import/scene_internal.h"

#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------- motions */

/* A motion of a frame whose initial pose is (pos, rot). */
int cs_sl_convert_motion(loader *L, const cs_raw_motion *rm, const char *path, const double pos[3],
                         const double rot[4], cs_motion *m)
{
    char p[PATH_LEN];
    int rc;
    memset(m, 0, sizeof *m);
    m->kind = CS_MOTION_STATIC;
    memcpy(m->position, pos, sizeof m->position);
    memcpy(m->rotation, rot, sizeof m->rotation);
    if (!rm)
        return CS_OK;
    bool constant = rm->velocity || rm->angular_velocity;
    if (constant && rm->keys)
        return cs_sl_fail(L, path, false,
                          "expected either velocity/angular_velocity or keys (got both)");
    if (constant) {
        m->kind = CS_MOTION_CONSTANT;
        if ((rc = cs_sl_vec(L, CS_SKEY(motion, velocity), rm->velocity, path, NULL, m->velocity)))
            return rc;
        return cs_sl_vec(L, CS_SKEY(motion, angular_velocity), rm->angular_velocity, path, NULL,
                         m->angular_velocity);
    }
    if (!rm->keys)
        return CS_OK;
    cs_keyframe *keys = calloc(rm->keys_count, sizeof *keys);
    if (!keys)
        return CS_ERR_NOMEM;
    m->kind = CS_MOTION_KEYFRAMES;
    m->keys = keys; /* owned by the scene from here on */
    m->nkeys = (int)rm->keys_count;
    for (unsigned k = 0; k < rm->keys_count; k++) {
        const cs_raw_key *rk = &rm->keys[k];
        double t[3], deg[3], q[4];
        if (k > 0 && !(rk->time > rm->keys[k - 1].time)) {
            snprintf(p, sizeof p, "%s.keys[%u].time", path, k);
            return cs_sl_fail(L, p, true, "must be greater than the previous key's time %g",
                              rm->keys[k - 1].time);
        }
        snprintf(p, sizeof p, "%s.keys[%u]", path, k);
        if ((rc = cs_sl_vec(L, CS_SKEY(key, translate), rk->translate, p, NULL, t)) ||
            (rc = cs_sl_vec(L, CS_SKEY(key, rotate), rk->rotate, p, NULL, deg)))
            return rc;
        keys[k].time = rk->time;
        for (int i = 0; i < 3; i++)
            keys[k].position[i] = pos[i] + t[i];
        cs_quat_from_euler_degrees(deg, q);
        cs_quat_multiply(q, rot, keys[k].rotation);
    }
    return CS_OK;
}

/* ---------------------------------------------------------- selections */

/* The vertices a selection names, ascending, each once. grid_res is NULL
 * for a cloth that is not a grid. */
static int select_vertices(loader *L, const cs_raw_selection *sel, const char *path,
                           const cs_trimesh *mesh, const int *grid_res, int **out, int *nout)
{
    char p[PATH_LEN];
    int forms = !!sel->vertices + !!sel->box + !!sel->grid_points;
    *out = NULL;
    *nout = 0;
    if (forms != 1)
        return cs_sl_fail(L, path, false,
                          "expected exactly one of vertices, box or grid_points (got %d)", forms);
    unsigned char *mark = calloc((size_t)mesh->nv, 1);
    if (!mark)
        return CS_ERR_NOMEM;
    int rc = CS_OK;
    const char *form = "vertices";
    if (sel->vertices) {
        for (unsigned i = 0; i < sel->vertices_count && !rc; i++) {
            int v = sel->vertices[i];
            snprintf(p, sizeof p, "%s.vertices[%u]", path, i);
            if (v < 0 || v >= mesh->nv)
                rc = cs_sl_fail(L, p, true, "must be a vertex index in [0, %d]", mesh->nv - 1);
            else
                mark[v] = 1;
        }
    } else if (sel->box) {
        form = "box";
        for (int k = 0; k < 3 && !rc; k++)
            if (sel->box->min[k] > sel->box->max[k]) {
                snprintf(p, sizeof p, "%s.box.max[%d]", path, k);
                rc = cs_sl_fail(L, p, true, "must be >= min[%d] = %g", k, sel->box->min[k]);
            }
        for (int v = 0; v < mesh->nv && !rc; v++) {
            const double *x = mesh->x + 3 * v;
            bool inside = true;
            for (int k = 0; k < 3; k++)
                inside = inside && x[k] >= sel->box->min[k] && x[k] <= sel->box->max[k];
            mark[v] = inside;
        }
    } else {
        form = "grid_points";
        if (!grid_res) {
            snprintf(p, sizeof p, "%s.grid_points", path);
            rc =
                cs_sl_fail(L, p, false, "only a grid cloth has grid points (this cloth is a mesh)");
        }
        for (unsigned i = 0; i < sel->grid_points_count && !rc; i++) {
            const int *ij = sel->grid_points[i];
            for (int k = 0; k < 2 && !rc; k++)
                if (ij[k] < 0 || ij[k] > grid_res[k]) {
                    snprintf(p, sizeof p, "%s.grid_points[%u][%d]", path, i, k);
                    rc = cs_sl_fail(L, p, true, "must be in [0, %d]", grid_res[k]);
                }
            /* The grid's vertex numbering (sim.h), guarded all the same. */
            long v = (long)ij[1] * (grid_res[0] + 1) + ij[0];
            if (!rc && v < mesh->nv)
                mark[v] = 1;
        }
    }
    int n = 0;
    for (int v = 0; v < mesh->nv && !rc; v++)
        n += mark[v];
    if (!rc && n == 0) {
        snprintf(p, sizeof p, "%s.%s", path, form);
        rc = cs_sl_fail(L, p, false, "selects no vertex");
    }
    if (!rc) {
        *out = malloc((size_t)n * sizeof **out);
        if (!*out)
            rc = CS_ERR_NOMEM;
        for (int v = 0; v < mesh->nv && *out; v++)
            if (mark[v])
                (*out)[(*nout)++] = v;
    }
    free(mark);
    return rc;
}

static void centroid(const cs_trimesh *mesh, const int *v, int n, double c[3])
{
    c[0] = c[1] = c[2] = 0;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            c[k] += mesh->x[3 * v[i] + k] / n;
}

/* Pins (merged into one static script) and scripts of cloth ci. */
static int convert_scripts(loader *L, const cs_raw_cloth *rc, const char *base, const int *grid_res,
                           cs_cloth_def *cd)
{
    const cs_trimesh *mesh = cd->mesh;
    char p[PATH_LEN];
    int err = CS_OK;
    int nscripts = (rc->pins_count > 0) + (int)rc->scripts_count;
    if (nscripts == 0)
        return CS_OK;
    cs_vertex_script *scripts = calloc((size_t)nscripts, sizeof *scripts);
    /* Who holds each vertex: 0 nobody, -(p+1) pin p, s+1 script s. */
    int *holder = calloc((size_t)mesh->nv, sizeof *holder);
    if (!scripts || !holder) {
        free(scripts);
        free(holder);
        return CS_ERR_NOMEM;
    }
    cd->scripts = scripts;
    cd->nscripts = nscripts;
    for (int i = 0; i < nscripts; i++)
        scripts[i].motion.kind = CS_MOTION_STATIC, scripts[i].motion.rotation[0] = 1;

    int ns = 0;
    if (rc->pins_count > 0) {
        int npinned = 0;
        for (unsigned k = 0; k < rc->pins_count && !err; k++) {
            int *v, n;
            snprintf(p, sizeof p, "%s.pins[%u]", base, k);
            if ((err = select_vertices(L, &rc->pins[k], p, mesh, grid_res, &v, &n)))
                break;
            for (int i = 0; i < n; i++)
                if (holder[v[i]] == 0)
                    holder[v[i]] = -(int)k - 1, npinned++;
            free(v);
        }
        int *all = err ? NULL : malloc((size_t)npinned * sizeof *all);
        if (!err && !all)
            err = CS_ERR_NOMEM;
        if (!err) {
            int n = 0;
            for (int v = 0; v < mesh->nv; v++)
                if (holder[v] < 0)
                    all[n++] = v;
            scripts[0].vertices = all;
            scripts[0].nvertices = n;
            centroid(mesh, all, n, scripts[0].motion.position);
            ns = 1;
        }
    }
    for (unsigned s = 0; s < rc->scripts_count && !err; s++, ns++) {
        const cs_raw_script *rs = &rc->scripts[s];
        cs_vertex_script *vs = &scripts[ns];
        int *v, n;
        double pivot[3];
        snprintf(p, sizeof p, "%s.scripts[%u].select", base, s);
        if ((err = select_vertices(L, rs->select, p, mesh, grid_res, &v, &n)))
            break;
        vs->vertices = v;
        vs->nvertices = n;
        for (int i = 0; i < n && !err; i++) {
            int h = holder[v[i]];
            if (h < 0)
                err = cs_sl_fail(
                    L, p, false,
                    "must not select a pinned vertex (got vertex %d, pinned by %s.pins[%d])", v[i],
                    base, -h - 1);
            else if (h > 0)
                err = cs_sl_fail(L, p, false,
                                 "must not select a vertex of another script "
                                 "(got vertex %d, also in %s.scripts[%d])",
                                 v[i], base, h - 1);
            else
                holder[v[i]] = (int)s + 1;
        }
        if (err)
            break;
        centroid(mesh, v, n, pivot);
        snprintf(p, sizeof p, "%s.scripts[%u]", base, s);
        if ((err = cs_sl_vec(L, CS_SKEY(script, pivot), rs->pivot, p, pivot, pivot)))
            break;
        snprintf(p, sizeof p, "%s.scripts[%u].motion", base, s);
        err = cs_sl_convert_motion(L, rs->motion, p, pivot, (const double[4]){1, 0, 0, 0},
                                   &vs->motion);
        snprintf(p, sizeof p, "%s.scripts[%u]", base, s);
        if (!err)
            err = cs_sl_num(L, CS_SKEY(script, release), rs->release, p, &vs->release_time);
    }
    free(holder);
    return err;
}

/* --------------------------------------------------------------- cloths */

static int convert_grid(loader *L, const cs_raw_grid *g, const char *base, int res[2],
                        cs_trimesh **mesh)
{
    char p[PATH_LEN], gp[PATH_LEN];
    double size[2], center[3], deg[3], q[4];
    int rc;
    snprintf(gp, sizeof gp, "%s.grid", base);
    if ((rc = cs_sl_vec(L, CS_SKEY(grid, size), g->size, gp, NULL, size)))
        return rc;
    for (int k = 0; k < 2; k++)
        if ((rc = cs_sl_int(L, CS_SKEY(grid, resolution), g->resolution ? &g->resolution[k] : NULL,
                            gp, k, &res[k])))
            return rc;
    /* Counts stay ints, and 3 * count indexes the arrays. */
    if ((int64_t)res[0] * res[1] > INT_MAX / 6 ||
        (int64_t)(res[0] + 1) * (res[1] + 1) > INT_MAX / 3) {
        snprintf(p, sizeof p, "%s.grid.resolution", base);
        return cs_sl_fail(L, p, false, "must give at most %d quads (got %d x %d)", INT_MAX / 6,
                          res[0], res[1]);
    }
    /* Refused before the tessellation and the simulation allocate it (a
     * 5000 x 5000 grid used to take 13.8 GB before anything said no). */
    double particles = (double)(res[0] + 1) * (res[1] + 1), all = L->particles + particles;
    char why[160];
    if (!cs_memory_fits(cs_sim_estimate_bytes(all, L->self_collision, false), why, sizeof why)) {
        snprintf(p, sizeof p, "%s.grid.resolution", base);
        return cs_sl_fail(L, p, false, "%d x %d quads (%.3g particles%s) to simulate%s: %s", res[0],
                          res[1], particles, all > particles ? " with the cloths before" : "",
                          L->self_collision ? " with self-collision" : "", why);
    }
    if ((rc = cs_sl_vec(L, CS_SKEY(grid, center), g->center, gp, NULL, center)) ||
        (rc = cs_sl_vec(L, CS_SKEY(grid, rotation), g->rotation, gp, NULL, deg)))
        return rc;
    cs_quat_from_euler_degrees(deg, q);
    *mesh = cs_trimesh_create_grid(size, res, q, center);
    L->particles = all;
    return *mesh ? CS_OK : CS_ERR_NOMEM;
}

static const char *cloth_name(const cs_scene *s, int j)
{
    return s->def.cloths[j].name;
}

int cs_sl_convert_cloth(loader *L, const cs_raw_cloth *rc, int ci, cs_scene *s)
{
    cs_cloth_def *cd = (cs_cloth_def *)&s->def.cloths[ci];
    char base[48], p[PATH_LEN];
    int err, res[2];
    cs_trimesh *mesh = NULL;

    snprintf(base, sizeof base, "cloths[%d]", ci);
    char *name = NULL;
    err = cs_sl_entry_name(L, rc->name, "cloths", "cloth", ci, cloth_name, s, &name);
    cd->name = name;
    if (err)
        return err;
    if ((err =
             cs_sl_vec(L, CS_SKEY(cloth, color), rc->color, base, NULL, s->cloth_colors + 3 * ci)))
        return err;

    if (!rc->grid == !rc->mesh)
        return cs_sl_fail(L, base, false, "expected exactly one of grid or mesh (got %s)",
                          rc->grid ? "both" : "neither");
    cs_mesh_report report;
    char *file = NULL;
    err = rc->grid ? convert_grid(L, rc->grid, base, res, &mesh)
                   : cs_sl_convert_mesh(L, rc->mesh, base, &mesh, &report, &file);
    cd->mesh = mesh;
    if (!err && file) {
        char who[128];
        snprintf(who, sizeof who, "%s '%.60s'", base, cd->name);
        if (!cs_sl_note_mesh(s, who, file, &report, false))
            err = CS_ERR_NOMEM;
    }
    free(file);
    if (err)
        return err;

    snprintf(p, sizeof p, "%s.material", base);
    if ((err = cs_sl_convert_keys(L, CS_SEC_material, rc->material, p, &cd->material)) ||
        (err = cs_sl_vec(L, CS_SKEY(cloth, velocity), rc->velocity, base, NULL, cd->velocity)))
        return err;
    return convert_scripts(L, rc, base, rc->grid ? res : NULL, cd);
}
