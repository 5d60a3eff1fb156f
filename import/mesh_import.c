/* mesh_import.c: mesh files as cloths and bodies.
 *
 * assimp reads and triangulates; everything after is done here so that it
 * is the same for every format and can be counted: the node tree is walked
 * with its transforms (only the selected nodes or meshes), coordinates are
 * checked for NaN before anything could hide them (assimp's own vertex
 * joining merges all NaN vertices into one), units and the placement are
 * applied, and the mesh is repaired and analysed (mesh_repair.c).
 *
 * A mesh file must never crash or hang the command that reads it. So each of the three readers below (cs_mesh_read, cs_mesh_import,
 * cs_mesh_catalog_read) does its work in a child process with limits
 * (mesh_guard.c) and sends back plain numbers; in that child the file is
 * checked before assimp sees it (mesh_check.c), assimp reads it without
 * post-processing, its faces are checked, and only then does assimp
 * triangulate.
 *
 * What that costs: the checks next to nothing beside assimp's own read,
 * the child process a few tens of milliseconds of CPU a file
 * (CLOTHSIM_IMPORT_ISOLATION=0 reads in the process itself, to compare;
 * docs/performance.md has the numbers). PLY frames are read without
 * joining vertices (see cs_mesh_read), which more than pays for the child.
 */
#include "import/mesh_internal.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define set_err cs_mesh_set_err

/* ----------------------------------------------------------- opening */

/* Opens with assimp (in the guard's child); on failure says why, the
 * system's reason first (assimp only says "Unable to open file"). The
 * file is pre-checked, read without post-processing, its faces checked,
 * and then post-processed with flags; join_unindexed adds the joining of
 * identical vertices for formats that list them per corner (not PLY or
 * glTF, which keep the writer's numbering). */
static int open_scene(const char *path, unsigned flags, bool join_unindexed,
                      const struct aiScene **out, char *err, size_t errlen)
{
    *out = NULL;
    if (!path || !*path) {
        set_err(err, errlen, "no mesh file given");
        return CS_ERR_BAD_INPUT;
    }
    if (access(path, R_OK) != 0) {
        set_err(err, errlen, "cannot read %s: %s", path, strerror(errno));
        return CS_ERR_BAD_INPUT;
    }
    FILE *f = fopen(path, "rb");
    if (!f || fgetc(f) == EOF) {
        /* a directory opens but does not read; an empty file has no format */
        int e = f && !ferror(f) ? 0 : errno;
        if (f)
            fclose(f);
        set_err(err, errlen, "cannot read %s: %s", path, e ? strerror(e) : "the file is empty");
        return CS_ERR_BAD_INPUT;
    }
    fclose(f);
    cs_mesh_precheck_result pc;
    int rc = cs_mesh_precheck(path, &pc, err, errlen);
    if (rc != CS_OK)
        return rc;
    /* no post-processing yet: it trusts face indices nothing has checked */
    const struct aiScene *scene =
        pc.data ? aiImportFileFromMemory((const char *)pc.data, (unsigned)pc.len, 0, pc.hint)
                : aiImportFile(path, 0);
    free(pc.data);
    if (!scene) {
        const char *why = aiGetErrorString();
        set_err(err, errlen, "cannot read %s: %s", path,
                why && *why ? why : "assimp could not import it");
        return why && strstr(why, "bad_alloc") ? CS_ERR_NOMEM : CS_ERR_BAD_INPUT;
    }
    if ((rc = cs_mesh_check_scene(scene, path, err, errlen)) != CS_OK) {
        aiReleaseImport(scene);
        return rc;
    }
    if (join_unindexed && pc.kind != CS_KIND_PLY && pc.kind != CS_KIND_GLTF)
        flags |= aiProcess_JoinIdenticalVertices;
    if (flags && !(scene = aiApplyPostProcessing(scene, flags))) {
        const char *why = aiGetErrorString();   /* the scene is released */
        set_err(err, errlen, "cannot read %s: %s", path,
                why && *why ? why : "assimp's post-processing failed");
        return CS_ERR_BAD_INPUT;
    }
    if (!scene->mRootNode) {
        set_err(err, errlen, "cannot read %s: the file has no scene nodes", path);
        aiReleaseImport(scene);
        return CS_ERR_BAD_INPUT;
    }
    *out = scene;
    return CS_OK;
}

static void format_name(const struct aiScene *scene, const char *path, char *out, size_t len)
{
    const struct aiMetadata *md = scene->mMetaData;
    for (unsigned i = 0; md && i < md->mNumProperties; i++)
        if (!strcmp(md->mKeys[i].data, "SourceAsset_Format") && md->mValues[i].mType == AI_AISTRING) {
            snprintf(out, len, "%.60s", ((const struct aiString *)md->mValues[i].mData)->data);
            return;
        }
    const char *dot = strrchr(path, '.');
    snprintf(out, len, "%s", dot ? dot + 1 : "unknown");
}

/* Metres per file unit as the file declares it. Only FBX says so in a form
 * assimp passes on (UnitScaleFactor, centimetres per unit); Collada's
 * <unit meter> is applied by assimp itself; glTF is metres by definition;
 * OBJ, PLY and STL carry no unit and are taken as metres (*unitless). */
static double file_units(const struct aiScene *scene, const char *format, char *why, size_t len,
                         bool *unitless)
{
    const struct aiMetadata *md = scene->mMetaData;
    *unitless = false;
    for (unsigned i = 0; md && i < md->mNumProperties; i++) {
        if (strcmp(md->mKeys[i].data, "UnitScaleFactor") != 0)
            continue;
        double f = 0;
        if (md->mValues[i].mType == AI_FLOAT)
            f = *(const float *)md->mValues[i].mData;
        else if (md->mValues[i].mType == AI_DOUBLE)
            f = *(const double *)md->mValues[i].mData;
        if (f > 0 && isfinite(f)) {
            snprintf(why, len, "%g cm per unit (the file's UnitScaleFactor)", f);
            return 0.01 * f;
        }
    }
    if (strstr(format, "glTF"))
        snprintf(why, len, "metres (glTF is in metres by definition)");
    else if (strstr(format, "Collada"))
        snprintf(why, len, "metres (the file's <unit> applied by assimp)");
    else {
        snprintf(why, len, "metres (the format has no units; set units to change)");
        *unitless = true;
    }
    return 1.0;
}

/* ---------------------------------------------------------- the walk */

typedef struct walk_state {
    const struct aiScene *scene;
    const char *node;        /* selection, NULL for all */
    double *x;               /* NULL while counting */
    int *tri;
    long nv, nt, skipped, instances;
    int nodes;               /* visited, for the report */
    int bad_vertex;          /* first non-finite vertex, else -1 */
    bool too_deep;
    bool keep_points;        /* take the vertices of meshes of points
                                only, or of no faces (point clouds) */
} walk_state;

static void mat_mul(const double a[16], const double b[16], double c[16])
{
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a[4 * i + k] * b[4 * k + j];
            c[4 * i + j] = s;
        }
}

static void mat_from_ai(const struct aiMatrix4x4 *m, double out[16])
{
    const double v[16] = {m->a1, m->a2, m->a3, m->a4, m->b1, m->b2, m->b3, m->b4,
                          m->c1, m->c2, m->c3, m->c4, m->d1, m->d2, m->d3, m->d4};
    memcpy(out, v, sizeof v);
}

static void add_mesh(walk_state *st, const struct aiMesh *mesh, const double world[16])
{
    long base = st->nv, ntri = 0, npoints = 0;
    if (!mesh->mVertices || mesh->mNumVertices == 0) {
        st->skipped += mesh->mNumFaces;
        return;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; f++) {
        const struct aiFace *face = &mesh->mFaces[f];
        if (face->mNumIndices != 3) {
            npoints += face->mNumIndices == 1;
            st->skipped++;
            continue;
        }
        bool ok = true;
        for (int k = 0; k < 3; k++)
            ok = ok && face->mIndices[k] < mesh->mNumVertices;
        if (!ok) {
            st->skipped++;
            continue;
        }
        if (st->tri)
            for (int k = 0; k < 3; k++)
                st->tri[3 * (st->nt + ntri) + k] = (int)(base + face->mIndices[k]);
        ntri++;
    }
    /* points and lines carry no surface; a point cloud is a frame */
    if (ntri == 0 && !(st->keep_points && npoints == (long)mesh->mNumFaces))
        return;
    st->instances++;
    if (st->x) {
        for (unsigned v = 0; v < mesh->mNumVertices; v++) {
            const double p[3] = {mesh->mVertices[v].x, mesh->mVertices[v].y,
                                 mesh->mVertices[v].z};
            double *x = &st->x[3 * (base + v)];
            if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
                if (st->bad_vertex < 0)
                    st->bad_vertex = (int)(base + v);
            }
            for (int r = 0; r < 3; r++)
                x[r] = world[4 * r] * p[0] + world[4 * r + 1] * p[1] + world[4 * r + 2] * p[2] +
                       world[4 * r + 3];
        }
    }
    st->nv += mesh->mNumVertices;
    st->nt += ntri;
}

/* Walks the tree; a node is taken when no selection is given, when it or an
 * ancestor has the selected name, or for its meshes of that name. */
static void walk(walk_state *st, const struct aiNode *node, const double parent[16], bool taken,
                 int depth)
{
    if (depth > 256) {
        st->too_deep = true;
        return;
    }
    double local[16], world[16];
    mat_from_ai(&node->mTransformation, local);
    mat_mul(parent, local, world);
    st->nodes++;
    if (st->node && !strcmp(node->mName.data, st->node))
        taken = true;
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= st->scene->mNumMeshes)
            continue;
        const struct aiMesh *mesh = st->scene->mMeshes[node->mMeshes[i]];
        if (taken || (st->node && !strcmp(mesh->mName.data, st->node)))
            add_mesh(st, mesh, world);
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        walk(st, node->mChildren[c], world, taken, depth + 1);
}

/* Up to a few names of nodes and meshes, for "no node X (the file has ...)". */
static void list_names(const struct aiNode *node, char *buf, size_t len, int *count, int depth)
{
    if (depth > 32)
        return;
    size_t used = strlen(buf);
    if (*count < 8 && node->mName.length > 0 && node->mName.data[0] != '<' && used + 4 < len) {
        snprintf(buf + used, len - used, "%s%.40s", *count ? ", " : "", node->mName.data);
        (*count)++;
    } else if (*count == 8 && used + 6 < len) {
        snprintf(buf + used, len - used, ", ...");
        (*count)++;
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        list_names(node->mChildren[c], buf, len, count, depth + 1);
}

/* ---------------------------------------------------------- import */

static void place_point(const cs_mesh_placement *p, double unit, const double in[3], double out[3])
{
    double s[3], r[3];
    for (int k = 0; k < 3; k++)
        s[k] = p->scale[k] * unit * in[k];
    cs_quat_rotate(p->rotation, s, r);
    for (int k = 0; k < 3; k++)
        out[k] = r[k] + p->translate[k];
}

/* The read-and-merge phase shared by cs_mesh_import and cs_mesh_read: the
 * selected meshes (node NULL: all) of an opened scene, node transforms
 * applied, in file units, vertex order as the file has it; the walk's
 * counters in stats. With keep_points, meshes without triangles give
 * their vertices (a point cloud is a valid frame). */
static int read_merged(const struct aiScene *scene, const char *path, const char *node,
                       bool keep_points, double **x_out, long *nv_out, int **tri_out,
                       long *nt_out, int *file_nodes, walk_state *stats, char *err, size_t errlen)
{
    static const double identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    walk_state st = {.scene = scene, .node = node, .bad_vertex = -1, .keep_points = keep_points};
    walk(&st, scene->mRootNode, identity, node == NULL, 0);
    *file_nodes = st.nodes;
    int rc = CS_ERR_BAD_INPUT;
    double *x = NULL;
    int *tri = NULL;
    if (st.too_deep) {
        set_err(err, errlen, "cannot read %s: node tree deeper than 256 levels", path);
        goto fail;
    }
    if (node && st.instances == 0) {
        char names[256] = "";
        int count = 0;
        list_names(scene->mRootNode, names, sizeof names, &count, 0);
        for (unsigned m = 0; m < scene->mNumMeshes && count < 9; m++) {
            size_t used = strlen(names);
            if (scene->mMeshes[m]->mName.length && used + 4 < sizeof names) {
                snprintf(names + used, sizeof names - used, "%s%.40s", count ? ", " : "",
                         scene->mMeshes[m]->mName.data);
                count++;
            }
        }
        set_err(err, errlen, "%s has no node or mesh named '%s' with triangles (it has: %s)",
                path, node, count ? names : "no named nodes");
        goto fail;
    }
    if (keep_points ? st.nv == 0 : st.nt == 0) {
        if (keep_points)
            set_err(err, errlen, "%s holds no triangles and no point cloud%s", path,
                    st.skipped ? " (only lines?)" : " (is it empty or truncated?)");
        else
            set_err(err, errlen, "%s holds no triangles%s", path,
                    st.skipped ? " (only points or lines)"
                               : " (is it empty or truncated, or only points or lines?)");
        goto fail;
    }
    if (st.nv > INT32_MAX / 3 || st.nt > INT32_MAX / 3) {
        set_err(err, errlen, "%s is too large (%ld vertices, %ld triangles)", path, st.nv, st.nt);
        goto fail;
    }
    x = malloc((3 * (size_t)st.nv + 1) * sizeof *x);
    tri = malloc((3 * (size_t)st.nt + 1) * sizeof *tri);
    if (!x || !tri) {
        set_err(err, errlen, "%s: out of memory for %ld vertices", path, st.nv);
        rc = CS_ERR_NOMEM;
        goto fail;
    }
    long nv = st.nv, nt = st.nt;
    st.x = x;
    st.tri = tri;
    st.nv = st.nt = st.skipped = st.instances = 0;
    st.nodes = 0;
    walk(&st, scene->mRootNode, identity, node == NULL, 0);
    *stats = st;
    *x_out = x;
    *tri_out = tri;
    *nv_out = nv;
    *nt_out = nt;
    return CS_OK;
fail:
    free(x);
    free(tri);
    return rc;
}

/* A mesh through the guard's pipe, and back (checked: a child that was
 * cut short never gets here, but indices are cheap to check). */
static void put_mesh(cs_bytes *b, const cs_trimesh *m)
{
    int32_t n[2] = {m->nv, m->nt};
    cs_bytes_put(b, n, sizeof n);
    cs_bytes_put(b, m->x, 3 * (size_t)m->nv * sizeof *m->x);
    cs_bytes_put(b, m->tri, 3 * (size_t)m->nt * sizeof *m->tri);
}

static cs_trimesh *get_mesh(cs_bytes_reader *r)
{
    int32_t n[2];
    cs_bytes_get(r, n, sizeof n);
    if (r->bad || n[0] < 0 || n[1] < 0 || n[0] > INT32_MAX / 3 || n[1] > INT32_MAX / 3 ||
        (size_t)n[0] * 24 + (size_t)n[1] * 12 > r->left)
        return NULL;
    cs_trimesh *m = cs_trimesh_create(n[0], n[1]);
    if (!m)
        return NULL;
    cs_bytes_get(r, m->x, 3 * (size_t)n[0] * sizeof *m->x);
    cs_bytes_get(r, m->tri, 3 * (size_t)n[1] * sizeof *m->tri);
    for (int i = 0; i < 3 * m->nt; i++)
        if (m->tri[i] < 0 || m->tri[i] >= m->nv)
            r->bad = true;
    if (r->bad) {
        cs_trimesh_destroy(m);
        return NULL;
    }
    return m;
}

/* What cs_mesh_read and cs_mesh_read_named read: every mesh merged
 * (names NULL, n 1), or per name its nodes and meshes. */
typedef struct read_request {
    const char *path;
    int n;
    const char *const *names;
} read_request;

/* In the child: a file as written, a mesh per request. */
static int read_in_child(void *ctx, cs_bytes *out, char *err, size_t errlen)
{
    const read_request *q = ctx;
    const char *path = q->path;
    const struct aiScene *scene;
    int rc = open_scene(path, aiProcess_Triangulate, true, &scene, err, errlen);
    for (int i = 0; i < q->n && rc == CS_OK; i++) {
        double *x = NULL;
        int *tri = NULL;
        long nv = 0, nt = 0;
        int nodes;
        walk_state st;
        rc = read_merged(scene, path, q->names ? q->names[i] : NULL, true, &x, &nv, &tri, &nt,
                         &nodes, &st, err, errlen);
        if (rc == CS_OK && st.bad_vertex >= 0) {
            set_err(err, errlen, "%s: vertex %d has a non-finite coordinate", path,
                    st.bad_vertex);
            rc = CS_ERR_BAD_INPUT;
        }
        if (rc == CS_OK)
            put_mesh(out, &(cs_trimesh){(int)nv, (int)nt, x, tri});
        free(x);
        free(tri);
    }
    if (scene)
        aiReleaseImport(scene);
    return rc;
}

static int read_meshes(const read_request *q, cs_trimesh **out, char *err, size_t errlen)
{
    /* Nothing is repaired or reordered: frames read back as written. PLY
     * and glTF keep the writer's vertex numbering; formats that list
     * vertices per corner (OBJ, STL) have identical ones joined by assimp. */
    cs_bytes res;
    int rc = cs_guard_run(q->path, read_in_child, (void *)q, &res, err, errlen);
    cs_bytes_reader r = {res.data, res.len, false};
    for (int i = 0; i < q->n; i++) {
        out[i] = rc == CS_OK ? get_mesh(&r) : NULL;
        if (rc == CS_OK && !out[i]) {
            set_err(err, errlen, "%s: out of memory", q->path);
            rc = CS_ERR_NOMEM;
        }
    }
    cs_bytes_free(&res);
    for (int i = 0; rc != CS_OK && i < q->n; i++) {
        cs_trimesh_destroy(out[i]);
        out[i] = NULL;
    }
    return rc;
}

cs_trimesh *cs_mesh_read(const char *path, char *err, size_t errlen)
{
    read_request q = {path, 1, NULL};
    cs_trimesh *m = NULL;
    read_meshes(&q, &m, err, errlen);
    return m;
}

int cs_mesh_read_named(const char *path, int n, const char *const *names, cs_trimesh **out,
                       char *err, size_t errlen)
{
    read_request q = {path, n, names};
    return read_meshes(&q, out, err, errlen);
}

/* A warning when a mesh read in a format without units is an implausible
 * size for a cloth or a body: an STL in millimetres comes out hundreds of
 * metres wide. */
static void check_size(const cs_mesh_report *r, char *out, size_t len)
{
    double size = 0;
    for (int k = 0; k < 3; k++)
        size = fmax(size, r->max[k] - r->min[k]);
    if (size > 20)
        snprintf(out, len, "the mesh is %.3g m across, its numbers taken as metres (the format "
                 "has no units): if it is in millimetres or centimetres, set units: mm or cm "
                 "on the mesh in the scene (mesh-info: --units)", size);
    else if (size < 0.005)
        snprintf(out, len, "the mesh is %.3g m across, its numbers taken as metres (the format "
                 "has no units): if it is in other units, set units: (m, cm, mm, km, in or ft) "
                 "on the mesh in the scene (mesh-info: --units)", size);
}

typedef struct import_job {
    const char *path;
    const cs_mesh_placement *place;
} import_job;

/* In the child: the whole import; the report goes back even on failure
 * (the scene blames the node key when the file has no such node). */
static int import_in_child(void *ctx, cs_bytes *out, char *err, size_t errlen)
{
    const import_job *job = ctx;
    const char *path = job->path;
    const cs_mesh_placement *p = job->place;
    cs_mesh_report r;
    memset(&r, 0, sizeof r);
    cs_trimesh *m = NULL;
    double *x = NULL;
    int *tri = NULL;
    /* Only triangulation: joining is done by position below, after the NaN
     * check, and degenerate triangles are counted. */
    const struct aiScene *scene = NULL;
    int rc = open_scene(path, aiProcess_Triangulate, false, &scene, err, errlen);
    if (rc != CS_OK)
        goto done;
    format_name(scene, path, r.format, sizeof r.format);
    r.file_meshes = (int)scene->mNumMeshes;
    bool unitless;
    double unit = file_units(scene, r.format, r.units, sizeof r.units, &unitless);
    if (p->unit_scale > 0) {
        unit = p->unit_scale;
        unitless = false;
        snprintf(r.units, sizeof r.units, "%g m per unit (as the scene says)", unit);
    }
    r.unit_scale = unit;

    long nv = 0, nt = 0;
    walk_state st;
    rc = read_merged(scene, path, p->node, false, &x, &nv, &tri, &nt, &r.file_nodes, &st, err,
                     errlen);
    if (rc != CS_OK)
        goto done;
    rc = CS_ERR_BAD_INPUT;
    r.instances = (int)st.instances;
    r.triangles_read = nt;
    r.skipped_primitives = st.skipped;
    if (st.bad_vertex >= 0) {
        set_err(err, errlen, "%s: vertex %d has a non-finite coordinate (NaN or infinity)", path,
                st.bad_vertex);
        goto done;
    }
    for (long i = 0; i < nv; i++) {
        double q[3];
        place_point(p, unit, x + 3 * i, q);
        if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) {
            set_err(err, errlen, "%s: vertex %ld is not finite after units and scale", path, i);
            goto done;
        }
        memcpy(x + 3 * i, q, sizeof q);
    }
    if (!(m = cs_mesh_clean(x, (int)nv, tri, (int)nt, &r))) {
        set_err(err, errlen, "%s: out of memory", path);
        rc = CS_ERR_NOMEM;
        goto done;
    }
    int kept = (int)nv - r.welded_vertices;
    if (m->nt == 0) {
        set_err(err, errlen, "%s has no triangles of nonzero area (%d degenerate)", path,
                r.degenerate_triangles);
        goto done;
    }
    if (2 * r.unreferenced_vertices > kept) {
        /* cow.ply: triangle strips the reader turns into one triangle */
        set_err(err, errlen, "most of %s was not understood: its %d triangle%s use%s %d of its "
                "%d vertices (triangle strips, or primitives the reader skips?)", path, m->nt,
                m->nt == 1 ? "" : "s", m->nt == 1 ? "s" : "", m->nv, kept);
        goto done;
    }
    cs_mesh_analyse(m, &r);
    if (unitless)
        check_size(&r, r.size_warning, sizeof r.size_warning);
    rc = CS_OK;
done:
    cs_bytes_put(out, &r, sizeof r);
    if (rc == CS_OK)
        put_mesh(out, m);
    cs_trimesh_destroy(m);
    free(x);
    free(tri);
    if (scene)
        aiReleaseImport(scene);
    return rc;
}

int cs_mesh_import(const char *path, const cs_mesh_placement *place, cs_trimesh **out,
                   cs_mesh_report *report, char *err, size_t errlen)
{
    cs_mesh_report scratch;
    cs_mesh_report *r = report ? report : &scratch;
    cs_mesh_placement def = cs_default_mesh_placement();
    import_job job = {path, place ? place : &def};
    memset(r, 0, sizeof *r);
    *out = NULL;
    cs_bytes res;
    int rc = cs_guard_run(path, import_in_child, &job, &res, err, errlen);
    cs_bytes_reader rd = {res.data, res.len, false};
    if (res.len)
        cs_bytes_get(&rd, r, sizeof *r);
    if (rc == CS_OK && !(*out = get_mesh(&rd))) {
        set_err(err, errlen, "%s: out of memory", path);
        rc = CS_ERR_NOMEM;
    }
    cs_bytes_free(&res);
    return rc;
}

/* ---------------------------------------------------------- catalog */

/* The catalog travels as: format; node count, then per node (depth first)
 * name, depth, mesh count, mesh indices; mesh count, then per mesh name,
 * vertices, triangles, other primitives. */
static int count_nodes(const struct aiNode *n, int depth)
{
    if (depth > 256)
        return 0;
    int c = 1;
    for (unsigned i = 0; i < n->mNumChildren; i++)
        c += count_nodes(n->mChildren[i], depth + 1);
    return c;
}

static void put_nodes(cs_bytes *b, const struct aiNode *n, int32_t depth, unsigned nmeshes)
{
    if (depth > 256)
        return;
    int32_t count = 0;
    for (unsigned i = 0; i < n->mNumMeshes; i++)
        count += n->mMeshes[i] < nmeshes;
    cs_bytes_put_str(b, n->mName.data);
    cs_bytes_put(b, &depth, sizeof depth);
    cs_bytes_put(b, &count, sizeof count);
    for (unsigned i = 0; i < n->mNumMeshes; i++)
        if (n->mMeshes[i] < nmeshes) {
            int32_t m = (int32_t)n->mMeshes[i];
            cs_bytes_put(b, &m, sizeof m);
        }
    for (unsigned i = 0; i < n->mNumChildren; i++)
        put_nodes(b, n->mChildren[i], depth + 1, nmeshes);
}

static int catalog_in_child(void *ctx, cs_bytes *out, char *err, size_t errlen)
{
    const char *path = ctx;
    const struct aiScene *scene;
    int rc = open_scene(path, aiProcess_Triangulate, false, &scene, err, errlen);
    if (rc != CS_OK)
        return rc;
    char format[64];
    format_name(scene, path, format, sizeof format);
    cs_bytes_put_str(out, format);
    int32_t n = count_nodes(scene->mRootNode, 0);
    cs_bytes_put(out, &n, sizeof n);
    put_nodes(out, scene->mRootNode, 0, scene->mNumMeshes);
    n = (int32_t)scene->mNumMeshes;
    cs_bytes_put(out, &n, sizeof n);
    for (unsigned m = 0; m < scene->mNumMeshes; m++) {
        const struct aiMesh *mesh = scene->mMeshes[m];
        int32_t c[3] = {(int32_t)mesh->mNumVertices, 0, 0};
        for (unsigned f = 0; f < mesh->mNumFaces; f++)
            c[mesh->mFaces[f].mNumIndices == 3 ? 1 : 2]++;
        cs_bytes_put_str(out, mesh->mName.data);
        cs_bytes_put(out, c, sizeof c);
    }
    aiReleaseImport(scene);
    return CS_OK;
}

/* A count of records of at least min bytes each that the reader can hold. */
static int get_count(cs_bytes_reader *r, size_t min)
{
    int32_t n;
    cs_bytes_get(r, &n, sizeof n);
    if (n < 0 || (size_t)n > r->left / min)
        r->bad = true;
    return r->bad ? 0 : n;
}

static bool get_catalog(cs_bytes_reader *r, cs_mesh_catalog *c)
{
    cs_bytes_get_str(r, c->format, sizeof c->format);
    int nn = get_count(r, 12);
    if (!(c->nodes = calloc((size_t)nn + 1, sizeof *c->nodes)))
        return false;
    for (int i = 0; i < nn && !r->bad; i++) {
        cs_mesh_catalog_node *node = &c->nodes[c->nnodes++];
        node->name = cs_bytes_get_strdup(r);
        cs_bytes_get(r, &node->depth, sizeof node->depth);
        int k = get_count(r, 4);
        if (!node->name || !(node->meshes = malloc(((size_t)k + 1) * sizeof *node->meshes)))
            return false;
        cs_bytes_get(r, node->meshes, (size_t)k * sizeof *node->meshes);
        node->nmeshes = k;
    }
    int nm = get_count(r, 16);
    if (!(c->meshes = calloc((size_t)nm + 1, sizeof *c->meshes)))
        return false;
    for (int i = 0; i < nm && !r->bad; i++) {
        cs_mesh_catalog_mesh *mesh = &c->meshes[c->nmeshes++];
        int32_t counts[3];
        mesh->name = cs_bytes_get_strdup(r);
        cs_bytes_get(r, counts, sizeof counts);
        if (!mesh->name)
            return false;
        mesh->vertices = counts[0];
        mesh->triangles = counts[1];
        mesh->other_primitives = counts[2];
    }
    return !r->bad;
}

int cs_mesh_catalog_read(const char *path, cs_mesh_catalog **out, char *err, size_t errlen)
{
    *out = NULL;
    cs_bytes res;
    int rc = cs_guard_run(path, catalog_in_child, (void *)path, &res, err, errlen);
    if (rc != CS_OK) {
        cs_bytes_free(&res);
        return rc;
    }
    cs_bytes_reader r = {res.data, res.len, false};
    cs_mesh_catalog *c = calloc(1, sizeof *c);
    if (c && get_catalog(&r, c)) {
        *out = c;
    } else {
        cs_mesh_catalog_destroy(c);
        set_err(err, errlen, "%s: out of memory", path);
        rc = CS_ERR_NOMEM;
    }
    cs_bytes_free(&res);
    return rc;
}

void cs_mesh_catalog_destroy(cs_mesh_catalog *c)
{
    if (!c)
        return;
    for (int i = 0; c->nodes && i < c->nnodes; i++) {
        free(c->nodes[i].name);
        free(c->nodes[i].meshes);
    }
    for (int i = 0; c->meshes && i < c->nmeshes; i++)
        free(c->meshes[i].name);
    free(c->nodes);
    free(c->meshes);
    free(c);
}
