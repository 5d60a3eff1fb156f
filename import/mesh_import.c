/* mesh_import.c: mesh files as cloths and bodies.
 *
 * assimp reads and triangulates; everything after is done here so that it
 * is the same for every format and can be counted: the node tree is walked
 * with its transforms (only the selected nodes or meshes), coordinates are
 * checked for NaN before anything could hide them (assimp's own vertex
 * joining merges all NaN vertices into one), units and the placement are
 * applied, vertices at identical positions are joined (STL and unwelded PLY
 * store one per triangle corner, and glTF splits at UV seams), and
 * zero-area and duplicate triangles are dropped. The topology is then
 * analysed: boundary, non-manifold and inconsistently oriented edges,
 * parts, closedness.
 */
#include "import/import.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

static void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

cs_mesh_placement cs_default_mesh_placement(void)
{
    cs_mesh_placement p;
    memset(&p, 0, sizeof p);
    p.scale[0] = p.scale[1] = p.scale[2] = 1;
    p.rotation[0] = 1;
    return p;
}

bool cs_mesh_units_from_name(const char *name, double *metres)
{
    static const struct {
        const char *name;
        double metres;
    } units[] = {{"m", 1}, {"cm", 0.01}, {"mm", 0.001}, {"km", 1000},
                 {"in", 0.0254}, {"ft", 0.3048}};
    for (size_t i = 0; name && i < sizeof units / sizeof *units; i++)
        if (strcmp(name, units[i].name) == 0) {
            if (metres)
                *metres = units[i].metres;
            return true;
        }
    return false;
}

/* ----------------------------------------------------------- opening */

/* Opens with assimp; on failure says why, the system's reason first
 * (assimp only says "Unable to open file"). */
static const struct aiScene *open_scene(const char *path, unsigned flags, char *err,
                                        size_t errlen)
{
    if (!path || !*path) {
        set_err(err, errlen, "no mesh file given");
        return NULL;
    }
    if (access(path, R_OK) != 0) {
        set_err(err, errlen, "cannot read %s: %s", path, strerror(errno));
        return NULL;
    }
    FILE *f = fopen(path, "rb");
    if (!f || fgetc(f) == EOF) {
        /* a directory opens but does not read; an empty file has no format */
        int e = f && !ferror(f) ? 0 : errno;
        if (f)
            fclose(f);
        set_err(err, errlen, "cannot read %s: %s", path, e ? strerror(e) : "the file is empty");
        return NULL;
    }
    fclose(f);
    const struct aiScene *scene = aiImportFile(path, flags);
    if (!scene) {
        const char *why = aiGetErrorString();
        set_err(err, errlen, "cannot read %s: %s", path,
                why && *why ? why : "assimp could not import it");
        return NULL;
    }
    if (!scene->mRootNode) {
        set_err(err, errlen, "cannot read %s: the file has no scene nodes", path);
        aiReleaseImport(scene);
        return NULL;
    }
    return scene;
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
 * OBJ, PLY and STL carry no unit and are taken as metres. */
static double file_units(const struct aiScene *scene, const char *format, char *why, size_t len)
{
    const struct aiMetadata *md = scene->mMetaData;
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
    else
        snprintf(why, len, "metres (the format has no units; set units to change)");
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
    long base = st->nv, ntri = 0;
    if (!mesh->mVertices || mesh->mNumVertices == 0) {
        st->skipped += mesh->mNumFaces;
        return;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; f++) {
        const struct aiFace *face = &mesh->mFaces[f];
        if (face->mNumIndices != 3) {
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
    if (ntri == 0)
        return;   /* points and lines carry no surface */
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

/* ---------------------------------------------------------- welding */

static uint64_t mix64(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    h ^= h >> 33;
    return h;
}

static uint64_t hash_point(const double *p)
{
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (int k = 0; k < 3; k++) {
        double v = p[k] + 0.0; /* -0.0 and 0.0 are one position */
        uint64_t bits;
        memcpy(&bits, &v, sizeof bits);
        h = mix64(h ^ bits) + (uint64_t)k;
    }
    return h;
}

/* Joins vertices at exactly equal positions: remap[i] is the kept index,
 * kept vertices renumbered from 0 in first-seen order. Returns the count
 * kept, or -1 when memory runs out. */
static int weld(const double *x, int nv, int *remap)
{
    size_t cap = 16;
    while (cap < 2 * (size_t)nv)
        cap *= 2;
    int *table = malloc(cap * sizeof *table);   /* original index of a kept vertex */
    int *first = malloc((size_t)nv * sizeof *first);
    if (!table || !first) {
        free(table);
        free(first);
        return -1;
    }
    for (size_t i = 0; i < cap; i++)
        table[i] = -1;
    int kept = 0;
    for (int i = 0; i < nv; i++) {
        const double *p = x + 3 * i;
        size_t h = (size_t)hash_point(p) & (cap - 1);
        for (;;) {
            int j = table[h];
            if (j < 0) {
                table[h] = i;
                first[i] = kept;
                remap[i] = kept++;
                break;
            }
            const double *q = x + 3 * j;
            if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                remap[i] = first[j];
                break;
            }
            h = (h + 1) & (cap - 1);
        }
    }
    free(table);
    free(first);
    return kept;
}

/* ------------------------------------------------------ clean-up */

static double tri_area2(const double *x, const int *t, double cr[3])
{
    const double *a = x + 3 * t[0], *b = x + 3 * t[1], *c = x + 3 * t[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    cr[0] = u[1] * w[2] - u[2] * w[1];
    cr[1] = u[2] * w[0] - u[0] * w[2];
    cr[2] = u[0] * w[1] - u[1] * w[0];
    return sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
}

typedef struct tri_key {
    int v[3];   /* sorted */
    int index;
} tri_key;

static int tri_key_cmp(const void *pa, const void *pb)
{
    const tri_key *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k])
            return a->v[k] < b->v[k] ? -1 : 1;
    return (a->index > b->index) - (a->index < b->index);
}

static void sort3(int v[3])
{
    int t;
    if (v[0] > v[1])
        t = v[0], v[0] = v[1], v[1] = t;
    if (v[1] > v[2])
        t = v[1], v[1] = v[2], v[2] = t;
    if (v[0] > v[1])
        t = v[0], v[0] = v[1], v[1] = t;
}

/* Welds, drops zero-area and duplicate triangles and unreferenced vertices.
 * x/tri are the raw arrays (nv, nt); returns a new mesh or NULL (memory). */
static cs_trimesh *clean(const double *x, int nv, const int *tri, int nt, cs_mesh_report *r)
{
    int *remap = malloc(((size_t)nv + 1) * sizeof *remap);
    int *t2 = malloc(((size_t)nt * 3 + 1) * sizeof *t2);
    tri_key *keys = malloc(((size_t)nt + 1) * sizeof *keys);
    unsigned char *drop = calloc((size_t)nt + 1, 1);
    int *used = NULL;
    cs_trimesh *out = NULL;
    if (!remap || !t2 || !keys || !drop)
        goto done;
    int kept = weld(x, nv, remap);
    if (kept < 0)
        goto done;
    r->welded_vertices = nv - kept;

    /* zero area, relative to the mesh's size so that units do not matter */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], x[3 * i + k]);
            hi[k] = fmax(hi[k], x[3 * i + k]);
        }
    double diag2 = 0;
    for (int k = 0; k < 3; k++)
        diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    int nk = 0;
    for (int t = 0; t < nt; t++) {
        int v[3];
        double cr[3];
        for (int k = 0; k < 3; k++)
            v[k] = t2[3 * t + k] = remap[tri[3 * t + k]];
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2] ||
            !(tri_area2(x, tri + 3 * t, cr) > 1e-14 * diag2)) {
            drop[t] = 1;
            r->degenerate_triangles++;
            continue;
        }
        sort3(v);
        memcpy(keys[nk].v, v, sizeof v);
        keys[nk++].index = t;
    }
    /* duplicates, either orientation: the first in file order stays */
    qsort(keys, (size_t)nk, sizeof *keys, tri_key_cmp);
    for (int i = 1; i < nk; i++)
        if (!memcmp(keys[i].v, keys[i - 1].v, sizeof keys[i].v)) {
            drop[keys[i].index] = 1;
            r->duplicate_triangles++;
        }

    /* keep referenced vertices, in order */
    used = malloc(((size_t)kept + 1) * sizeof *used);
    if (!used)
        goto done;
    for (int i = 0; i < kept; i++)
        used[i] = -1;
    int ntri = 0, nvert = 0;
    for (int t = 0; t < nt; t++) {
        if (drop[t])
            continue;
        ntri++;
        for (int k = 0; k < 3; k++)
            if (used[t2[3 * t + k]] < 0)
                used[t2[3 * t + k]] = nvert++;
    }
    r->unreferenced_vertices = kept - nvert;
    out = cs_trimesh_create(nvert, ntri);
    if (!out)
        goto done;
    for (int i = 0; i < nv; i++) {
        int j = used[remap[i]];
        if (j >= 0)
            memcpy(out->x + 3 * j, x + 3 * i, 3 * sizeof(double));
    }
    int o = 0;
    for (int t = 0; t < nt; t++) {
        if (drop[t])
            continue;
        for (int k = 0; k < 3; k++)
            out->tri[3 * o + k] = used[t2[3 * t + k]];
        o++;
    }
done:
    free(remap);
    free(t2);
    free(keys);
    free(drop);
    free(used);
    return out;
}

/* ---------------------------------------------------------- topology */

typedef struct half_edge {
    int a, b;   /* a < b */
    int dir;    /* +1: a -> b in its triangle, -1: b -> a */
    int tri;
} half_edge;

static int half_edge_cmp(const void *pa, const void *pb)
{
    const half_edge *p = pa, *q = pb;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return (p->tri > q->tri) - (p->tri < q->tri);
}

static int find_root(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Boundary half-edges (as the triangle walks them: from -> to). */
typedef struct bedge {
    int from, to;
} bedge;

static int bedge_cmp(const void *pa, const void *pb)
{
    const bedge *p = pa, *q = pb;
    if (p->from != q->from)
        return p->from < q->from ? -1 : 1;
    return (p->to > q->to) - (p->to < q->to);
}

/* The boundary half-edges sorted by start vertex; count in *n. */
static bedge *boundary_edges(const cs_trimesh *m, int *n)
{
    size_t ne = 3 * (size_t)m->nt;
    half_edge *e = malloc((ne + 1) * sizeof *e);
    bedge *b = malloc((ne + 1) * sizeof *b);
    *n = 0;
    if (!e || !b) {
        free(e);
        free(b);
        return NULL;
    }
    for (int t = 0; t < m->nt; t++)
        for (int k = 0; k < 3; k++) {
            int u = m->tri[3 * t + k], v = m->tri[3 * t + (k + 1) % 3];
            half_edge *h = &e[3 * t + k];
            h->a = u < v ? u : v;
            h->b = u < v ? v : u;
            h->dir = u < v ? 1 : -1;
            h->tri = t;
        }
    qsort(e, ne, sizeof *e, half_edge_cmp);
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && e[j].a == e[i].a && e[j].b == e[i].b)
            j++;
        if (j - i == 1) {
            b[*n].from = e[i].dir > 0 ? e[i].a : e[i].b;
            b[*n].to = e[i].dir > 0 ? e[i].b : e[i].a;
            (*n)++;
        }
        i = j;
    }
    free(e);
    qsort(b, (size_t)*n, sizeof *b, bedge_cmp);
    return b;
}

/* Walks boundary half-edges into loops. For each closed loop calls fn with
 * its vertices in order (when fn is given). Returns the number of loops, or
 * -1 on memory. Half-edges that do not close a loop (inconsistent
 * orientation) are left alone. */
typedef int (*loop_fn)(void *ctx, const int *v, int n);

static int walk_loops(const cs_trimesh *m, loop_fn fn, void *ctx)
{
    int nb;
    bedge *b = boundary_edges(m, &nb);
    if (!b)
        return m->nt > 0 ? -1 : 0;
    int *start = malloc(((size_t)m->nv + 1) * sizeof *start);
    unsigned char *done = calloc((size_t)nb + 1, 1);
    int *loop = malloc(((size_t)nb + 1) * sizeof *loop);
    int loops = 0;
    if (!start || !done || !loop) {
        loops = -1;
        goto out;
    }
    for (int i = 0; i <= m->nv; i++)
        start[i] = nb;
    for (int i = nb - 1; i >= 0; i--)
        start[b[i].from] = i;
    for (int s = 0; s < nb; s++) {
        if (done[s])
            continue;
        /* follow unused half-edges from b[s].from until back at it */
        int n = 0, cur = s;
        bool closed = false;
        while (cur < nb && !done[cur]) {
            done[cur] = 1;
            loop[n++] = b[cur].from;
            if (b[cur].to == b[s].from) {
                closed = true;
                break;
            }
            int v = b[cur].to, next = nb;
            for (int k = start[v]; k < nb && b[k].from == v; k++)
                if (!done[k]) {
                    next = k;
                    break;
                }
            cur = next;
        }
        if (closed && n >= 3) {
            loops++;
            if (fn && fn(ctx, loop, n) != 0) {
                loops = -1;
                goto out;
            }
        } else if (closed) {
            loops++; /* a two-edge loop (a slit): nothing to fill */
        }
    }
out:
    free(b);
    free(start);
    free(done);
    free(loop);
    return loops;
}

void cs_mesh_analyse(const cs_trimesh *m, cs_mesh_report *r)
{
    r->boundary_edges = r->nonmanifold_edges = r->inconsistent_edges = 0;
    r->boundary_loops = r->parts = 0;
    r->area = r->volume = 0;
    for (int k = 0; k < 3; k++) {
        r->min[k] = m->nv > 0 ? INFINITY : 0;
        r->max[k] = m->nv > 0 ? -INFINITY : 0;
    }
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            r->min[k] = fmin(r->min[k], m->x[3 * i + k]);
            r->max[k] = fmax(r->max[k], m->x[3 * i + k]);
        }
    r->vertices = m->nv;
    r->triangles = m->nt;
    for (int t = 0; t < m->nt; t++) {
        double cr[3];
        const double *a = m->x + 3 * m->tri[3 * t];
        r->area += 0.5 * tri_area2(m->x, m->tri + 3 * t, cr);
        r->volume += (a[0] * cr[0] + a[1] * cr[1] + a[2] * cr[2]) / 6.0;
    }
    r->volume = fabs(r->volume);

    size_t ne = 3 * (size_t)m->nt;
    half_edge *e = malloc((ne + 1) * sizeof *e);
    int *parent = malloc(((size_t)m->nv + 1) * sizeof *parent);
    if (e && parent) {
        for (int t = 0; t < m->nt; t++)
            for (int k = 0; k < 3; k++) {
                int u = m->tri[3 * t + k], v = m->tri[3 * t + (k + 1) % 3];
                half_edge *h = &e[3 * t + k];
                h->a = u < v ? u : v;
                h->b = u < v ? v : u;
                h->dir = u < v ? 1 : -1;
                h->tri = t;
            }
        qsort(e, ne, sizeof *e, half_edge_cmp);
        for (size_t i = 0; i < ne;) {
            size_t j = i;
            while (j < ne && e[j].a == e[i].a && e[j].b == e[i].b)
                j++;
            if (j - i == 1)
                r->boundary_edges++;
            else if (j - i > 2)
                r->nonmanifold_edges++;
            else if (e[i].dir == e[i + 1].dir)
                r->inconsistent_edges++;
            i = j;
        }
        for (int i = 0; i < m->nv; i++)
            parent[i] = i;
        for (int t = 0; t < m->nt; t++) {
            int a = find_root(parent, m->tri[3 * t]);
            for (int k = 1; k < 3; k++) {
                int b = find_root(parent, m->tri[3 * t + k]);
                if (a != b)
                    parent[b] = a;
            }
        }
        for (int i = 0; i < m->nv; i++)
            r->parts += parent[i] == i;
    }
    free(e);
    free(parent);
    int loops = walk_loops(m, NULL, NULL);
    r->boundary_loops = loops > 0 ? loops : 0;
    r->closed = r->boundary_edges == 0 && r->nonmanifold_edges == 0;
}

/* ---------------------------------------------------------- hole filling */

typedef struct fill_state {
    int filled;
    double *x;
    int nv, cap_v;
    int *tri;
    int nt, cap_t;
} fill_state;

static int fill_loop(void *ctx, const int *v, int n)
{
    fill_state *f = ctx;
    if (f->nv + 1 > f->cap_v || f->nt + n > f->cap_t) {
        int cv = 2 * (f->nv + 1), ct = 2 * (f->nt + n);
        double *x = realloc(f->x, 3 * (size_t)cv * sizeof *x);
        if (!x)
            return -1;
        f->x = x;
        int *t = realloc(f->tri, 3 * (size_t)ct * sizeof *t);
        if (!t)
            return -1;
        f->tri = t;
        f->cap_v = cv;
        f->cap_t = ct;
    }
    double c[3] = {0, 0, 0};
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            c[k] += f->x[3 * v[i] + k] / n;
    int ci = f->nv++;
    f->filled++;
    memcpy(f->x + 3 * ci, c, sizeof c);
    /* The loop runs the way its triangles walk their boundary edges; the
     * fan walks each edge the other way, as a neighbour must. */
    for (int i = 0; i < n; i++) {
        int *t = f->tri + 3 * f->nt++;
        t[0] = v[(i + 1) % n];
        t[1] = v[i];
        t[2] = ci;
    }
    return 0;
}

int cs_mesh_close_holes(cs_trimesh **mesh)
{
    cs_trimesh *m = *mesh;
    fill_state f = {0};
    f.nv = f.cap_v = m->nv;
    f.nt = f.cap_t = m->nt;
    f.x = malloc(3 * ((size_t)m->nv + 1) * sizeof *f.x);
    f.tri = malloc(3 * ((size_t)m->nt + 1) * sizeof *f.tri);
    if (!f.x || !f.tri) {
        free(f.x);
        free(f.tri);
        return -1;
    }
    memcpy(f.x, m->x, 3 * (size_t)m->nv * sizeof *f.x);
    memcpy(f.tri, m->tri, 3 * (size_t)m->nt * sizeof *f.tri);
    int loops = walk_loops(m, fill_loop, &f);
    if (loops > 0 && f.filled > 0) {
        cs_trimesh *out = cs_trimesh_create(f.nv, f.nt);
        if (!out) {
            loops = -1;
        } else {
            memcpy(out->x, f.x, 3 * (size_t)f.nv * sizeof *f.x);
            memcpy(out->tri, f.tri, 3 * (size_t)f.nt * sizeof *f.tri);
            cs_trimesh_destroy(m);
            *mesh = out;
        }
    }
    free(f.x);
    free(f.tri);
    return loops < 0 ? -1 : f.filled;
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
 * counters in stats. */
static int read_merged(const struct aiScene *scene, const char *path, const char *node,
                       double **x_out, long *nv_out, int **tri_out, long *nt_out,
                       int *file_nodes, walk_state *stats, char *err, size_t errlen)
{
    static const double identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    walk_state st = {.scene = scene, .node = node, .bad_vertex = -1};
    walk(&st, scene->mRootNode, identity, node == NULL, 0);
    *file_nodes = st.nodes;
    int rc = CS_IMPORT_BAD_INPUT;
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
    if (st.nt == 0) {
        set_err(err, errlen, "%s holds no triangles%s", path,
                st.skipped ? " (only points or lines)"
                           : " (is it empty or truncated, or only points or lines?)");
        goto fail;
    }
    if (st.nv > INT32_MAX / 3 || st.nt > INT32_MAX / 3) {
        set_err(err, errlen, "%s is too large (%ld vertices, %ld triangles)", path, st.nv, st.nt);
        goto fail;
    }
    x = malloc(3 * (size_t)st.nv * sizeof *x);
    tri = malloc(3 * (size_t)st.nt * sizeof *tri);
    if (!x || !tri) {
        set_err(err, errlen, "%s: out of memory for %ld vertices", path, st.nv);
        rc = CS_IMPORT_NOMEM;
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
    return CS_IMPORT_OK;
fail:
    free(x);
    free(tri);
    return rc;
}

cs_trimesh *cs_mesh_read(const char *path, char *err, size_t errlen)
{
    /* assimp joins identical vertices (an OBJ lists them per corner) but
     * nothing is repaired or reordered: frames read back as written */
    const struct aiScene *scene =
        open_scene(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices, err, errlen);
    if (!scene)
        return NULL;
    double *x = NULL;
    int *tri = NULL;
    long nv = 0, nt = 0;
    int nodes;
    walk_state st;
    cs_trimesh *m = NULL;
    if (read_merged(scene, path, NULL, &x, &nv, &tri, &nt, &nodes, &st, err, errlen) ==
        CS_IMPORT_OK) {
        if (st.bad_vertex >= 0)
            set_err(err, errlen, "%s: vertex %d has a non-finite coordinate", path,
                    st.bad_vertex);
        else if (!(m = cs_trimesh_create((int)nv, (int)nt)))
            set_err(err, errlen, "%s: out of memory", path);
        else {
            memcpy(m->x, x, sizeof *x * 3 * (size_t)nv);
            memcpy(m->tri, tri, sizeof *tri * 3 * (size_t)nt);
        }
    }
    free(x);
    free(tri);
    aiReleaseImport(scene);
    return m;
}

int cs_mesh_import(const char *path, const cs_mesh_placement *place, cs_trimesh **out,
                   cs_mesh_report *report, char *err, size_t errlen)
{
    cs_mesh_report scratch;
    cs_mesh_report *r = report ? report : &scratch;
    cs_mesh_placement def = cs_default_mesh_placement();
    const cs_mesh_placement *p = place ? place : &def;
    memset(r, 0, sizeof *r);
    *out = NULL;

    /* Only triangulation: joining is done by position below, after the NaN
     * check, and degenerate triangles are counted. */
    const struct aiScene *scene = open_scene(path, aiProcess_Triangulate, err, errlen);
    if (!scene)
        return CS_IMPORT_BAD_INPUT;
    format_name(scene, path, r->format, sizeof r->format);
    r->file_meshes = (int)scene->mNumMeshes;
    double unit = file_units(scene, r->format, r->units, sizeof r->units);
    if (p->unit_scale > 0) {
        unit = p->unit_scale;
        snprintf(r->units, sizeof r->units, "%g m per unit (as the scene says)", unit);
    }
    r->unit_scale = unit;

    double *x = NULL;
    int *tri = NULL;
    long nv = 0, nt = 0;
    walk_state st;
    int rc = read_merged(scene, path, p->node, &x, &nv, &tri, &nt, &r->file_nodes, &st, err,
                         errlen);
    if (rc != CS_IMPORT_OK)
        goto done;
    rc = CS_IMPORT_BAD_INPUT;
    r->instances = (int)st.instances;
    r->triangles_read = nt;
    r->skipped_primitives = st.skipped;
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
    cs_trimesh *m = clean(x, (int)nv, tri, (int)nt, r);
    if (!m) {
        set_err(err, errlen, "%s: out of memory", path);
        rc = CS_IMPORT_NOMEM;
        goto done;
    }
    if (m->nt == 0) {
        set_err(err, errlen, "%s has no triangles of nonzero area (%d degenerate)", path,
                r->degenerate_triangles);
        cs_trimesh_destroy(m);
        goto done;
    }
    cs_mesh_analyse(m, r);
    *out = m;
    rc = CS_IMPORT_OK;
done:
    free(x);
    free(tri);
    aiReleaseImport(scene);
    return rc;
}

/* ---------------------------------------------------------- catalog */

static char *dup_name(const struct aiString *s)
{
    size_t n = s->length < MAXLEN ? s->length : MAXLEN - 1;
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s->data, n);
        d[n] = '\0';
    }
    return d;
}

static int count_nodes(const struct aiNode *n, int depth)
{
    if (depth > 256)
        return 0;
    int c = 1;
    for (unsigned i = 0; i < n->mNumChildren; i++)
        c += count_nodes(n->mChildren[i], depth + 1);
    return c;
}

static bool fill_nodes(cs_mesh_catalog *c, const struct aiNode *n, int depth, int nmeshes)
{
    if (depth > 256)
        return true;
    cs_mesh_catalog_node *out = &c->nodes[c->nnodes++];
    out->name = dup_name(&n->mName);
    out->depth = depth;
    out->meshes = malloc(((size_t)n->mNumMeshes + 1) * sizeof *out->meshes);
    if (!out->name || !out->meshes)
        return false;
    for (unsigned i = 0; i < n->mNumMeshes; i++)
        if ((int)n->mMeshes[i] < nmeshes)
            out->meshes[out->nmeshes++] = (int)n->mMeshes[i];
    for (unsigned i = 0; i < n->mNumChildren; i++)
        if (!fill_nodes(c, n->mChildren[i], depth + 1, nmeshes))
            return false;
    return true;
}

int cs_mesh_catalog_read(const char *path, cs_mesh_catalog **out, char *err, size_t errlen)
{
    *out = NULL;
    const struct aiScene *scene = open_scene(path, aiProcess_Triangulate, err, errlen);
    if (!scene)
        return CS_IMPORT_BAD_INPUT;
    cs_mesh_catalog *c = calloc(1, sizeof *c);
    int total = count_nodes(scene->mRootNode, 0);
    if (!c)
        goto nomem;
    format_name(scene, path, c->format, sizeof c->format);
    c->nodes = calloc((size_t)total + 1, sizeof *c->nodes);
    c->meshes = calloc((size_t)scene->mNumMeshes + 1, sizeof *c->meshes);
    if (!c->nodes || !c->meshes)
        goto nomem;
    for (unsigned m = 0; m < scene->mNumMeshes; m++) {
        const struct aiMesh *mesh = scene->mMeshes[m];
        cs_mesh_catalog_mesh *cm = &c->meshes[c->nmeshes++];
        cm->name = dup_name(&mesh->mName);
        if (!cm->name)
            goto nomem;
        cm->vertices = (int)mesh->mNumVertices;
        for (unsigned f = 0; f < mesh->mNumFaces; f++) {
            if (mesh->mFaces[f].mNumIndices == 3)
                cm->triangles++;
            else
                cm->other_primitives++;
        }
    }
    if (!fill_nodes(c, scene->mRootNode, 0, (int)scene->mNumMeshes))
        goto nomem;
    aiReleaseImport(scene);
    *out = c;
    return CS_IMPORT_OK;
nomem:
    aiReleaseImport(scene);
    cs_mesh_catalog_destroy(c);
    set_err(err, errlen, "%s: out of memory", path);
    return CS_IMPORT_NOMEM;
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
