/* scene_mesh.c: meshes in a scene (a file through assimp, or inline), mesh
 * bodies, and the level-set policy they share with `clothsim levelset`:
 * which mesh the grid is made of (holes closed for the sign), its voxel
 * size and interior; then the grids themselves, from the cache or made. */
#include "import/scene_internal.h"

#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <yaml.h>

char *cs_sl_scene_relative(const char *file, const char *path)
{
    if (path[0] == '/')
        return cs_sl_strdup(path);
    char *dir = cs_sl_scene_dir(file);
    if (!dir)
        return NULL;
    size_t n = strlen(dir) + strlen(path) + 2;
    char *out = malloc(n);
    if (out)
        snprintf(out, n, "%s/%s", dir, path);
    free(dir);
    return out;
}

/* ------------------------------------------------ level-set policy */

cs_trimesh *cs_mesh_body_sign_mesh(cs_trimesh *mesh, const cs_mesh_report *rep, bool close_holes,
                                   int *holes_closed, cs_mesh_report *closed)
{
    *closed = *rep;
    *holes_closed = 0;
    if (rep->closed || !close_holes)
        return mesh;
    /* a copy with the holes closed; mesh stays as read */
    cs_trimesh *sign = cs_trimesh_create(mesh->nv, mesh->nt);
    if (!sign)
        return NULL;
    memcpy(sign->x, mesh->x, 3 * (size_t)mesh->nv * sizeof *sign->x);
    memcpy(sign->tri, mesh->tri, 3 * (size_t)mesh->nt * sizeof *sign->tri);
    *holes_closed = cs_mesh_close_holes(&sign);
    if (*holes_closed < 0) {
        cs_trimesh_destroy(sign);
        return NULL;
    }
    cs_mesh_analyse(sign, closed);
    return sign;
}

/* The narrow band (voxels) a grid needs so that collisions, which see
 * phi - offset, read true distances for band voxels beyond the offset
 * surface. Beyond its band a grid reads the band's width, so a band
 * narrower than the offset would put every point past it inside the
 * collision surface, and B.4 would move such a particle onto it in one
 * step. The 1e-9 keeps an offset of a whole number of voxels from rounding
 * up. */
static double grid_band(double band, double offset, double voxel)
{
    return offset > 0 && voxel > 0 ? band + ceil(offset / voxel - 1e-9) : band;
}

bool cs_mesh_body_grid(const cs_mesh_report *mesh, double *voxel, double cloth_edge, double offset,
                       double *band, cs_interior_mode interior, bool *fill, char *why,
                       size_t len)
{
    if (!(*voxel > 0))
        *voxel = cs_levelset_default_voxel(mesh, cloth_edge, *band, interior == CS_INTERIOR_FILL);
    *band = grid_band(*band, offset, *voxel);
    *fill = interior == CS_INTERIOR_AUTO ? cs_levelset_auto_fill(mesh, *voxel)
                                         : interior == CS_INTERIOR_FILL;
    return cs_levelset_voxel_ok(mesh, *voxel, *band, *fill, why, len);
}

/* mesh.scale: one number (uniform) or three, each > 0. Read from the
 * document: the schema cannot say "a number or a list". */
int cs_sl_read_scale(loader *L, const char *path, double out[3])
{
    const cs_key_range *range = &CS_SKEY(mesh, scale)->range;
    char bound[64], want[192], one[96];
    cs_key_range_text(range, bound, sizeof bound);
    snprintf(want, sizeof want, "expected a number %s or a list of 3 numbers %s", bound, bound);
    snprintf(one, sizeof one, "expected a number %s", bound);
    cs_spath p;
    cs_sloc loc;
    out[0] = out[1] = out[2] = 1;
    if (!cs_spath_parse(&p, path))
        return CS_OK;
    cs_sdoc_locate(&L->doc, &p, false, &loc);
    if (loc.matched != p.n || !loc.node)
        return CS_OK;
    const yaml_node_t *n = yaml_document_get_node(&L->doc.doc, loc.node);
    if (!n)
        return CS_OK;
    int items = 1;
    const yaml_node_item_t *item = NULL;
    if (n->type == YAML_SEQUENCE_NODE) {
        item = n->data.sequence.items.start;
        items = (int)(n->data.sequence.items.top - item);
        if (items != 3)
            return cs_sl_fail(L, path, false, "%s (got a list of %d)", want, items);
    } else if (n->type != YAML_SCALAR_NODE) {
        return cs_sl_fail(L, path, true, "%s", want);
    }
    for (int k = 0; k < items; k++) {
        const yaml_node_t *e = item ? yaml_document_get_node(&L->doc.doc, item[k]) : n;
        char ep[PATH_LEN + 8];
        snprintf(ep, sizeof ep, item ? "%s[%d]" : "%s", path, k);
        if (!e || e->type != YAML_SCALAR_NODE)
            return cs_sl_fail(L, ep, true, "%s", item ? one : want);
        const char *text = (const char *)e->data.scalar.value;
        char *end;
        double v = strtod(text, &end);
        if (!*text || isspace((unsigned char)*text) || *end || !isfinite(v))
            return cs_sl_fail(L, ep, true, "%s", item ? one : want);
        if (!cs_key_in_range(range, v)) {
            return cs_sl_fail(L, ep, true, "must be %s", bound);
        }
        for (int d = item ? k : 0; d < (item ? k + 1 : 3); d++)
            out[d] = v;
    }
    return CS_OK;
}

/* The placement keys of a mesh block. */
static int convert_placement(loader *L, const cs_raw_mesh *m, const char *mp, cs_mesh_placement *pl)
{
    char p[PATH_LEN];
    double deg[3];
    int rc;
    *pl = cs_default_mesh_placement();
    snprintf(p, sizeof p, "%s.scale", mp);
    if ((rc = cs_sl_read_scale(L, p, pl->scale)))
        return rc;
    if ((rc = cs_sl_vec(L, CS_SKEY(mesh, rotation), m->rotation, mp, NULL, deg)))
        return rc;
    cs_quat_from_euler_degrees(deg, pl->rotation);
    return cs_sl_vec(L, CS_SKEY(mesh, translate), m->translate, mp, NULL, pl->translate);
}

/* A mesh file through assimp; *file gets the path as opened. */
static int convert_mesh_file(loader *L, const cs_raw_mesh *m, const char *mp, cs_trimesh **mesh,
                             cs_mesh_report *rep, char **file)
{
    char p[PATH_LEN + 32], why[768];
    cs_mesh_placement pl;
    int rc;
    if (m->triangles) {
        snprintf(p, sizeof p, "%s.triangles", mp);
        return cs_sl_fail(L, p, false, "is only used with vertices (remove it or the file)");
    }
    if ((rc = convert_placement(L, m, mp, &pl)))
        return rc;
    pl.node = m->node;
    if (m->units && *m->units > 0 &&
        !cs_mesh_units_from_name(cs_scene_enum_name(CS_SKEY(mesh, units), *m->units),
                                 &pl.unit_scale))
        pl.unit_scale = 0;
    snprintf(p, sizeof p, "%s.file", mp);
    if (!*m->file)
        return cs_sl_fail(L, p, false, "must not be empty");
    if (!(*file = cs_sl_scene_relative(L->file, m->file)))
        return CS_ERR_NOMEM;
    rc = cs_mesh_import(*file, &pl, mesh, rep, why, sizeof why);
    if (rc == CS_ERR_BAD_INPUT) {
        /* a node that is not there is the node key's fault */
        if (m->node && rep->format[0] && rep->instances == 0)
            snprintf(p, sizeof p, "%s.node", mp);
        return cs_sl_fail(L, p, false, "%s", why);
    }
    return rc;
}

int cs_sl_convert_mesh(loader *L, const cs_raw_mesh *m, const char *base, cs_trimesh **mesh,
                       cs_mesh_report *rep, char **file)
{
    char p[PATH_LEN + 64], mp[PATH_LEN];
    int rc;
    snprintf(mp, sizeof mp, "%s.mesh", base);
    memset(rep, 0, sizeof *rep);
    *file = NULL;
    if (!m->file == !m->vertices)
        return cs_sl_fail(L, mp, false, "expected exactly one of file or vertices (got %s)",
                          m->file ? "both" : "neither");
    if (m->file)
        return convert_mesh_file(L, m, mp, mesh, rep, file);
    if (m->node || m->units) {
        snprintf(p, sizeof p, "%s.%s", mp, m->node ? "node" : "units");
        return cs_sl_fail(L, p, false, "is only used with file (remove it)");
    }
    int nv = (int)m->vertices_count, nt = (int)m->triangles_count;
    if (m->vertices_count > INT_MAX / 3 || m->triangles_count > INT_MAX / 3)
        return cs_sl_fail(L, mp, false, "is too large");
    for (int f = 0; f < nt; f++) {
        const int *c = m->triangles[f];
        for (int k = 0; k < 3; k++)
            if (c[k] < 0 || c[k] >= nv) {
                snprintf(p, sizeof p, "%s.triangles[%d][%d]", mp, f, k);
                return cs_sl_fail(L, p, true, "must be a vertex index in [0, %d]", nv - 1);
            }
        if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
            snprintf(p, sizeof p, "%s.triangles[%d]", mp, f);
            return cs_sl_fail(L, p, false, "must name three distinct vertices (got [%d, %d, %d])",
                              c[0], c[1], c[2]);
        }
    }
    cs_mesh_placement pl;
    if ((rc = convert_placement(L, m, mp, &pl)))
        return rc;
    *mesh = cs_trimesh_create(nv, nt);
    if (!*mesh)
        return CS_ERR_NOMEM;
    for (int v = 0; v < nv; v++) {
        double sc[3], r[3];
        for (int k = 0; k < 3; k++)
            sc[k] = pl.scale[k] * m->vertices[v][k];
        cs_quat_rotate(pl.rotation, sc, r);
        for (int k = 0; k < 3; k++)
            (*mesh)->x[3 * v + k] = r[k] + pl.translate[k];
    }
    for (int f = 0; f < nt; f++)
        for (int k = 0; k < 3; k++)
            (*mesh)->tri[3 * f + k] = m->triangles[f][k];
    snprintf(rep->format, sizeof rep->format, "inline");
    rep->unit_scale = 1;
    cs_mesh_analyse(*mesh, rep);
    return CS_OK;
}

/* One line on what import did with a mesh file, and a warning for what the
 * cloth or body will feel. */
bool cs_sl_note_mesh(cs_scene *s, const char *who, const char *file, const cs_mesh_report *r,
                     bool body)
{
    char fixes[256] = "";
    size_t used = 0;
    if (r->degenerate_triangles)
        used +=
            (size_t)snprintf(fixes + used, sizeof fixes - used, "; dropped %d zero-area triangle%s",
                             r->degenerate_triangles, r->degenerate_triangles == 1 ? "" : "s");
    if (r->duplicate_triangles && used < sizeof fixes)
        used +=
            (size_t)snprintf(fixes + used, sizeof fixes - used, "; dropped %d duplicate triangle%s",
                             r->duplicate_triangles, r->duplicate_triangles == 1 ? "" : "s");
    if (r->unreferenced_vertices && used < sizeof fixes)
        snprintf(fixes + used, sizeof fixes - used, "; dropped %d unused vertices",
                 r->unreferenced_vertices);
    if (!cs_sl_note(s, "%s: %s (%s, %s): %d triangles, %d vertices, %d part%s, %s%s", who,
                    cs_sl_base_name(file), r->format, r->units, r->triangles, r->vertices, r->parts,
                    r->parts == 1 ? "" : "s", r->closed ? "closed" : "open", fixes))
        return false;
    if (r->size_warning[0] && !cs_sl_note(s, "warning: %s: %s", who, r->size_warning))
        return false;
    if (r->nonmanifold_edges &&
        !cs_sl_note(s, "warning: %s: %d non-manifold edge%s (more than two triangles on an edge)%s",
                    who, r->nonmanifold_edges, r->nonmanifold_edges == 1 ? "" : "s",
                    body ? "" : "; bending springs join every pair of triangles across them"))
        return false;
    if (r->inconsistent_edges &&
        !cs_sl_note(s,
                    "warning: %s: %d edge%s where neighbouring triangles disagree on "
                    "orientation",
                    who, r->inconsistent_edges, r->inconsistent_edges == 1 ? "" : "s"))
        return false;
    return true;
}

/* The mesh of a mesh body, in the body's local frame, and its grid
 * settings; the grid itself is made once the whole scene is known
 * (finish_mesh_bodies, build_levelsets). */
int cs_sl_convert_mesh_body(loader *L, const cs_raw_body *rb, int bi, cs_scene *s)
{
    cs_scene_mesh_body *mb = &s->mesh_bodies[bi];
    char base[48], p[PATH_LEN];
    int err;
    snprintf(base, sizeof base, "bodies[%d]", bi);
    if ((err = cs_sl_convert_mesh(L, rb->mesh, base, &mb->mesh, &mb->report, &mb->file)))
        return err;
    if (!mb->file && !(mb->file = cs_sl_strdup("(inline)")))
        return CS_ERR_NOMEM;
    if (mb->mesh->nt == 0) {
        snprintf(p, sizeof p, "%s.mesh", base);
        return cs_sl_fail(L, p, false, "must have triangles for a body");
    }
    /* a band is a few voxels: beyond 1000 the default voxel size coarsens
     * to nothing and the message would blame the voxel size */
    if ((err = cs_sl_num(L, CS_SKEY(body, voxel_size), rb->voxel_size, base, &mb->voxel_size)) ||
        (err = cs_sl_num(L, CS_SKEY(body, band), rb->band, base, &mb->band)))
        return err;
    mb->close_holes = rb->close_holes ? *rb->close_holes : CS_SKEY(body, close_holes)->def(0) != 0;
    mb->interior =
        (cs_interior_mode)(rb->interior ? *rb->interior : (int)CS_SKEY(body, interior)->def(0));
    return CS_OK;
}

/* The median edge length over all cloths: what the default voxel size
 * follows (0 if there are no edges). */
static double cloth_edge_median(const cs_sim_def *d)
{
    long total = 0;
    for (int c = 0; c < d->ncloths; c++)
        total += d->cloths[c].mesh ? 3L * d->cloths[c].mesh->nt : 0;
    if (total == 0)
        return 0;
    long stride = total / 30000 + 1, n = 0; /* a sample is plenty for a median */
    double *len = malloc(((size_t)(total / stride) + 2) * sizeof *len);
    if (!len)
        return 0;
    long k = 0;
    for (int c = 0; c < d->ncloths; c++) {
        const cs_trimesh *m = d->cloths[c].mesh;
        for (int t = 0; m && t < m->nt; t++)
            for (int e = 0; e < 3; e++, k++) {
                if (k % stride)
                    continue;
                const double *a = m->x + 3 * m->tri[3 * t + e];
                const double *b = m->x + 3 * m->tri[3 * t + (e + 1) % 3];
                len[n++] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                                (a[2] - b[2]) * (a[2] - b[2]));
            }
    }
    /* selection by sorting: n is at most 30000 */
    for (long i = 1; i < n; i++) {
        double v = len[i];
        long j = i;
        for (; j > 0 && len[j - 1] > v; j--)
            len[j] = len[j - 1];
        len[j] = v;
    }
    double median = n ? len[n / 2] : 0;
    free(len);
    return median;
}

/* Voxel sizes (given, or the default from the cloth's edge length), their
 * check against the mesh and memory, and closing the holes the sign needs
 * closed: everything about mesh bodies that can fail with a message. */
int cs_sl_finish_mesh_bodies(loader *L, cs_scene *s)
{
    double edge = -1;
    for (int b = 0; b < s->def.nbodies; b++) {
        cs_scene_mesh_body *mb = &s->mesh_bodies[b];
        if (!mb->mesh)
            continue;
        char base[48], p[PATH_LEN], who[128], why[256];
        snprintf(base, sizeof base, "bodies[%d]", b);
        snprintf(who, sizeof who, "%s '%.60s'", base, s->def.bodies[b].name);
        if (strcmp(mb->file, "(inline)") && !cs_sl_note_mesh(s, who, mb->file, &mb->report, true))
            return CS_ERR_NOMEM;
        cs_mesh_report closed;
        cs_trimesh *sign = cs_mesh_body_sign_mesh(mb->mesh, &mb->report, mb->close_holes,
                                                  &mb->holes_closed, &closed);
        if (!sign)
            return CS_ERR_NOMEM;
        mb->sign_mesh = sign;
        if (!mb->report.closed) {
            bool ok;
            if (!mb->close_holes)
                ok = cs_sl_note(s,
                                "warning: %s: the mesh is not closed (%d boundary edges) and "
                                "close_holes is false: the sign comes from OpenVDB's flood fill "
                                "from outside, which leaks in through holes wider than about a "
                                "voxel",
                                who, mb->report.boundary_edges);
            else if (closed.closed)
                ok = cs_sl_note(s,
                                "warning: %s: the mesh is not closed (%d boundary edges in %d "
                                "loop%s); closed them with fans to each loop's centre so the "
                                "level set has an inside",
                                who, mb->report.boundary_edges, mb->report.boundary_loops,
                                mb->report.boundary_loops == 1 ? "" : "s");
            else
                ok = cs_sl_note(s,
                                "warning: %s: the mesh is not closed and stays open after "
                                "closing %d loop%s (%d boundary and %d non-manifold edges "
                                "left): the sign may be wrong near them",
                                who, mb->holes_closed, mb->holes_closed == 1 ? "" : "s",
                                closed.boundary_edges, closed.nonmanifold_edges);
            if (!ok)
                return CS_ERR_NOMEM;
        }
        bool given = mb->voxel_size > 0;
        if (!given && edge < 0)
            edge = cloth_edge_median(&s->def);
        mb->grid_band = mb->band;
        if (!cs_mesh_body_grid(&closed, &mb->voxel_size, edge, s->def.bodies[b].offset,
                               &mb->grid_band, mb->interior, &mb->fill_interior, why,
                               sizeof why)) {
            snprintf(p, sizeof p, "%s%s", base, given ? ".voxel_size" : "");
            if (given)
                return cs_sl_fail(L, p, true, "%s", why);
            return cs_sl_fail(L, p, false, "the default voxel_size %.3g m %s", mb->voxel_size, why);
        }
    }
    return CS_OK;
}

/* ------------------------------------------------------------ level sets */

/* Makes (or reads from the cache) the grid of every mesh body and plugs it
 * into the body's phi. Only once the whole scene converted without error,
 * so nothing is converted for a scene that is then refused. */
int cs_sl_build_levelsets(loader *L, cs_scene *s)
{
    for (int b = 0; s->mesh_bodies && b < s->def.nbodies; b++) {
        cs_scene_mesh_body *mb = &s->mesh_bodies[b];
        if (!mb->mesh)
            continue;
        char stem[128], who[128], why[512], p[64];
        snprintf(stem, sizeof stem, "%s", cs_sl_base_name(mb->file));
        char *dot = strrchr(stem, '.');
        if (dot && dot != stem)
            *dot = '\0';
        snprintf(who, sizeof who, "bodies[%d] '%.60s'", b, s->def.bodies[b].name);
        cs_levelset_request req = {
            .voxel_size = mb->voxel_size,
            .band = mb->grid_band,
            .fill_interior = mb->fill_interior,
            .cache_dir = s->levelset_cache,
            .label = stem,
        };
        cs_levelset_result res;
        int rc = cs_levelset_build(mb->sign_mesh, &req, &res, why, sizeof why);
        if (rc != CS_OK) {
            snprintf(p, sizeof p, "bodies[%d].mesh", b);
            return rc == CS_ERR_NOMEM
                       ? rc
                       : cs_sl_fail(L, p, false, "cannot make its level set: %s", why);
        }
        mb->levelset = res.grid;
        mb->from_cache = res.from_cache;
        mb->seconds = res.seconds;
        if (res.cache_path[0] && !(mb->cache_path = cs_sl_strdup(res.cache_path)))
            return CS_ERR_NOMEM;
        cs_levelset_attach((cs_body_def *)&s->def.bodies[b], mb->levelset);
        cs_levelset_info info;
        cs_levelset_get_info(mb->levelset, &info);
        char done[1200];
        if (res.from_cache)
            snprintf(done, sizeof done, "read from the cache %s in %.2f s", res.cache_path,
                     res.seconds);
        else if (res.cache_path[0])
            snprintf(done, sizeof done, "converted in %.2f s, cached as %s", res.seconds,
                     res.cache_path);
        else
            snprintf(done, sizeof done, "converted in %.2f s (not cached)", res.seconds);
        if (!cs_sl_note(s,
                        "%s: level set %dx%dx%d voxels of %.3g m (band %g%s), %lld active, "
                        "%.1f MB; %s",
                        who, info.dim[0], info.dim[1], info.dim[2], info.voxel_size, mb->grid_band,
                        mb->fill_interior ? ", interior filled" : "", info.active_voxels,
                        info.memory_bytes / 1e6, done))
            return CS_ERR_NOMEM;
        if (res.cache_note[0] &&
            !cs_sl_note(s, "warning: %s: level-set cache: %s", who, res.cache_note))
            return CS_ERR_NOMEM;
    }
    return CS_OK;
}
