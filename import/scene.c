/* scene.c: scene files (YAML) -> cs_scene.
 *
 * A load runs in stages, each with one-line error messages:
 *   1. libyaml parses the text into a document (syntax errors, with line);
 *   2. libcyaml loads it against the schema (scene_schema.c); its log is
 *      captured and turned into "KEY.PATH: what was expected (got X)", the
 *      line coming from the document rather than cyaml's backtrace, which
 *      points at the enclosing node;
 *   3. a pass over the document checks number and boolean text strictly
 *      (cyaml 1.3 reads "3x" as 3 and "maybe" as true);
 *   4. --set overrides edit the document, which is emitted and loaded again;
 *   5. the raw structs become a cs_scene with defaults, and values are
 *      checked against their ranges (negative masses and the like).
 * The document stays alive to the end so that every message can be placed.
 */
#include "import/import.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cyaml/cyaml.h>
#include <yaml.h>

#include "import/scene_doc.h"
#include "import/scene_schema.h"

#define MSG_LEN 512
#define PATH_LEN 256

/* Scene-level defaults that are not part of cs_sim_def. */
#define DEFAULT_FRAMES 48
#define DEFAULT_FOV 40.0
static const double default_cloth_color[3] = {0.8, 0.3, 0.2};
static const double default_body_color[3] = {0.7, 0.7, 0.7};

static const char *const shape_names[] = {"plane", "sphere", "box", "cylinder"};

typedef struct loader {
    const char *file;            /* the name messages use */
    cs_sdoc doc;
    int noverrides;
    const char *const *overrides;
    /* The pending error, placed (file line or override) by report(). */
    cs_spath err_path;
    bool err_second;             /* the path's last key is a duplicate */
    char err_msg[MSG_LEN];
    /* libcyaml's log of the current load. */
    char log[16384];
    size_t log_len;
} loader;

/* ------------------------------------------------------------ messages */

/* One line, whatever the values quoted in it contain. */
static void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    if (!err || errlen == 0)
        return;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    for (char *c = err; *c; c++)
        if (*c == '\n' || *c == '\r' || *c == '\t')
            *c = ' ';
}

/* Records an error at a key path. with_got appends "(got X)" with the value
 * found there in the document. Returns CS_IMPORT_BAD_INPUT. */
static int fail_at(loader *L, const cs_spath *p, bool with_got, const char *fmt, ...)
{
    va_list ap;
    L->err_path = *p;
    L->err_second = false;
    va_start(ap, fmt);
    vsnprintf(L->err_msg, sizeof L->err_msg, fmt, ap);
    va_end(ap);
    if (with_got) {
        cs_sloc loc;
        char got[128];
        cs_sdoc_locate(&L->doc, p, false, &loc);
        if (loc.matched == p->n) {
            cs_sdoc_describe(&L->doc, loc.node, got, sizeof got);
            size_t used = strlen(L->err_msg);
            snprintf(L->err_msg + used, sizeof L->err_msg - used, " (got %s)", got);
        }
    }
    return CS_IMPORT_BAD_INPUT;
}

static int fail(loader *L, const char *path, bool with_got, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static int fail(loader *L, const char *path, bool with_got, const char *fmt, ...)
{
    cs_spath p;
    char msg[MSG_LEN];
    va_list ap;
    if (!cs_spath_parse(&p, path))
        p.n = 0;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return fail_at(L, &p, with_got, "%s", msg);
}

/* Components the two paths share from the start. */
static int common_prefix(const cs_spath *a, const cs_spath *b)
{
    int i = 0;
    for (; i < a->n && i < b->n; i++) {
        char x[32], y[32];
        const char *ka = a->c[i].key, *kb = b->c[i].key;
        if (a->c[i].index >= 0)
            snprintf(x, sizeof x, "%ld", a->c[i].index), ka = x;
        if (b->c[i].index >= 0)
            snprintf(y, sizeof y, "%ld", b->c[i].index), kb = y;
        if (strcmp(ka, kb) != 0)
            break;
    }
    return i;
}

static void override_path(const char *ov, cs_spath *p)
{
    char path[PATH_LEN];
    size_t n = strcspn(ov, "=");
    if (n >= sizeof path)
        n = sizeof path - 1;
    memcpy(path, ov, n);
    path[n] = '\0';
    if (!cs_spath_parse(p, path))
        p->n = 0;
}

/* The override most likely at fault for an error its nodes do not contain
 * (say, a shape changed by --set that now needs a radius): the one sharing
 * the longest path prefix, else the last. */
static int blame_override(const loader *L)
{
    int best = L->noverrides - 1, best_len = 0;
    for (int k = 0; k < L->noverrides; k++) {
        cs_spath p;
        override_path(L->overrides[k], &p);
        int len = common_prefix(&p, &L->err_path);
        if (len >= best_len && len > 0) {
            best = k;
            best_len = len;
        }
    }
    return best;
}

/* Writes the pending error: "--set OVERRIDE: PATH: msg" where an override
 * made the nodes on the path (or blame says so), else "FILE:LINE: PATH: msg". */
static int report(loader *L, bool blame, char *err, size_t errlen)
{
    char path[PATH_LEN];
    cs_sloc loc;
    cs_spath_format(&L->err_path, path, sizeof path);
    cs_sdoc_locate(&L->doc, &L->err_path, L->err_second, &loc);
    int k = L->noverrides > 0 ? loc.owner : -1;
    if (k < 0 && blame && L->noverrides > 0)
        k = blame_override(L);
    if (k >= 0)
        set_err(err, errlen, "--set %s: %s%s%s", L->overrides[k], path, *path ? ": " : "",
                L->err_msg);
    else
        set_err(err, errlen, "%s:%d: %s%s%s", L->file, loc.line, path, *path ? ": " : "",
                L->err_msg);
    return CS_IMPORT_BAD_INPUT;
}

/* ---------------------------------------------------------- cyaml stage */

static void capture_log(cyaml_log_t level, void *ctx, const char *fmt, va_list args)
{
    loader *L = ctx;
    (void)level;
    if (L->log_len + 1 >= sizeof L->log)
        return;
    int w = vsnprintf(L->log + L->log_len, sizeof L->log - L->log_len, fmt, args);
    if (w > 0)
        L->log_len += (size_t)w < sizeof L->log - L->log_len ? (size_t)w
                                                              : sizeof L->log - L->log_len - 1;
}

static bool starts(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* Expected-versus-found for a value of the wrong kind at p. */
static int fail_type(loader *L, const cs_spath *p)
{
    char want[160], got[128];
    cs_sloc loc;
    cs_scene_schema_describe(cs_scene_schema_at(p), want, sizeof want);
    cs_sdoc_locate(&L->doc, p, false, &loc);
    if (loc.matched == p->n)
        cs_sdoc_describe(&L->doc, loc.node, got, sizeof got);
    else
        snprintf(got, sizeof got, "nothing");
    if (p->n == 0)
        return fail_at(L, p, false, "expected a mapping of scene keys (got %s)", got);
    return fail_at(L, p, false, "expected %s (got %s)", want, got);
}

/* Turns cyaml's captured log into the pending error. The log has a message
 * line ("Load: Invalid FLOAT value: x") and a backtrace, innermost first:
 * "in mapping field 'k'", "in sequence entry 'n'" (1-based), "in mapping". */
static int translate_cyaml(loader *L, cyaml_err_t e)
{
    char *lines[CS_SPATH_MAX * 2 + 8];
    int nlines = 0;
    const char *what = NULL;
    cs_spath p = {0};

    for (char *s = L->log; *s && nlines < (int)(sizeof lines / sizeof *lines);) {
        char *nl = strchr(s, '\n');
        lines[nlines++] = s;
        if (!nl)
            break;
        *nl = '\0';
        s = nl + 1;
    }
    /* Backtrace entries, innermost first; the path is built outermost first. */
    int bt[CS_SPATH_MAX * 2 + 8], nbt = 0;
    for (int i = 0; i < nlines; i++) {
        if (starts(lines[i], "Load: ") && !starts(lines[i], "Load: Backtrace")) {
            if (!what)
                what = lines[i] + strlen("Load: ");
        } else if (starts(lines[i], "  in ")) {
            bt[nbt++] = i;
        }
    }
    bool innermost_is_field = nbt > 0 && starts(lines[bt[0]], "  in mapping field '");
    bool innermost_is_entry = nbt > 0 && starts(lines[bt[0]], "  in sequence entry '");
    bool missing = what && starts(what, "Missing required mapping field: ");
    bool count =
        what && (starts(what, "Insufficient entries") || starts(what, "Excessive entries"));
    for (int j = nbt - 1; j >= 0; j--) {
        const char *l = lines[bt[j]];
        /* A missing-field error is raised at the end of the mapping, whose
         * "current field" is then stale; a count error names the entry
         * after the last, which is not part of the sequence's path. */
        if (j == 0 && ((missing && innermost_is_field) || (count && innermost_is_entry)))
            break;
        if (starts(l, "  in mapping field '")) {
            const char *k = l + strlen("  in mapping field '");
            const char *end = strstr(k, "' (line");
            cs_spath_push_key(&p, k, end ? (size_t)(end - k) : strlen(k));
        } else if (starts(l, "  in sequence entry '")) {
            long n = strtol(l + strlen("  in sequence entry '"), NULL, 10);
            cs_spath_push_index(&p, n > 0 ? n - 1 : 0);
        }
    }

    if (!what)
        return fail_at(L, &p, false, "%s", cyaml_strerror(e));
    if (starts(what, "Unexpected key: ")) {
        const char *k = what + strlen("Unexpected key: ");
        cs_spath_push_key(&p, k, strlen(k));
        return fail_at(L, &p, false, "unknown key");
    }
    if (missing) {
        const char *k = what + strlen("Missing required mapping field: ");
        cs_spath_push_key(&p, k, strlen(k));
        return fail_at(L, &p, false, "required key is missing");
    }
    if (starts(what, "Mapping field already seen: ")) {
        fail_at(L, &p, false, "duplicate key");
        L->err_second = true;
        return CS_IMPORT_BAD_INPUT;
    }
    if (count) {
        const cyaml_schema_value_t *v = cs_scene_schema_at(&p);
        cs_sloc loc;
        long have = 0;
        cs_sdoc_locate(&L->doc, &p, false, &loc);
        if (loc.matched == p.n && loc.node) {
            const yaml_node_t *n = yaml_document_get_node(&L->doc.doc, loc.node);
            if (n && n->type == YAML_SEQUENCE_NODE)
                have = n->data.sequence.items.top - n->data.sequence.items.start;
        }
        if (v && v->type == CYAML_SEQUENCE_FIXED) {
            char want[160];
            cs_scene_schema_describe(v, want, sizeof want);
            return fail_at(L, &p, false, "expected %s (got a list of %ld)", want, have);
        }
        if (v && starts(what, "Insufficient"))
            return fail_at(L, &p, false, "expected at least %u %s (got %ld)",
                           (unsigned)v->sequence.min, v->sequence.min == 1 ? "entry" : "entries",
                           have);
        if (v)
            return fail_at(L, &p, false, "expected at most %u entries (got %ld)",
                           (unsigned)v->sequence.max, have);
    }
    if (starts(what, "Invalid ") || starts(what, "Expecting "))
        return fail_type(L, &p);
    return fail_at(L, &p, false, "%s", what);
}

/* Number and boolean text, stricter than cyaml: whole text, finite, and
 * booleans that cyaml reads the way they look. */
static int check_scalar(loader *L, const yaml_node_t *n, const cyaml_schema_value_t *v,
                        const cs_spath *p)
{
    const char *s = (const char *)n->data.scalar.value;
    char *end;
    switch (v->type) {
    case CYAML_FLOAT: {
        errno = 0;
        double x = strtod(s, &end);
        if (!*s || isspace((unsigned char)*s) || *end)
            return fail_at(L, p, true, "expected a number");
        if (!isfinite(x))
            return fail_at(L, p, true, "expected a finite number");
        return CS_IMPORT_OK;
    }
    case CYAML_INT: {
        const char *d = s + (*s == '-' || *s == '+');
        bool digits = *d != '\0';
        for (const char *c = d; *c; c++)
            digits = digits && isdigit((unsigned char)*c);
        if (!digits)
            return fail_at(L, p, true, "expected an integer");
        /* cyaml reads "010" as octal 8. */
        if (d[0] == '0' && d[1] != '\0')
            return fail_at(L, p, true, "expected an integer without leading zeros");
        return CS_IMPORT_OK;
    }
    case CYAML_BOOL:
        /* cyaml takes anything but false/no/disable/0 as true ("off" too). */
        if (strcasecmp(s, "true") && strcasecmp(s, "false") && strcasecmp(s, "yes") &&
            strcasecmp(s, "no"))
            return fail_at(L, p, true, "expected true or false");
        return CS_IMPORT_OK;
    default:
        return CS_IMPORT_OK;
    }
}

static int check_scalars(loader *L, int id, const cyaml_schema_value_t *v, cs_spath *p)
{
    const yaml_node_t *n = yaml_document_get_node(&L->doc.doc, id);
    int rc = CS_IMPORT_OK;
    if (!n || !v)
        return CS_IMPORT_OK;
    if (n->type == YAML_SCALAR_NODE)
        return check_scalar(L, n, v, p);
    if (n->type == YAML_MAPPING_NODE && v->type == CYAML_MAPPING) {
        long npairs = n->data.mapping.pairs.top - n->data.mapping.pairs.start;
        for (long i = 0; rc == CS_IMPORT_OK && i < npairs; i++) {
            yaml_node_pair_t pair = n->data.mapping.pairs.start[i];
            const yaml_node_t *k = yaml_document_get_node(&L->doc.doc, pair.key);
            if (!k || k->type != YAML_SCALAR_NODE || p->n >= CS_SPATH_MAX)
                continue;
            const cyaml_schema_field_t *f = v->mapping.fields;
            while (f->key && strcmp(f->key, (const char *)k->data.scalar.value) != 0)
                f++;
            if (!f->key)
                continue;
            cs_spath_push_key(p, f->key, strlen(f->key));
            rc = check_scalars(L, pair.value, &f->value, p);
            p->n--;
        }
    } else if (n->type == YAML_SEQUENCE_NODE &&
               (v->type == CYAML_SEQUENCE || v->type == CYAML_SEQUENCE_FIXED)) {
        long nitems = n->data.sequence.items.top - n->data.sequence.items.start;
        for (long i = 0; rc == CS_IMPORT_OK && i < nitems; i++) {
            if (p->n >= CS_SPATH_MAX)
                break;
            cs_spath_push_index(p, i);
            rc = check_scalars(L, n->data.sequence.items.start[i], v->sequence.entry, p);
            p->n--;
        }
    }
    return rc;
}

static const cyaml_config_t *cyaml_config_for(loader *L, cyaml_config_t *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->log_fn = capture_log;
    cfg->log_ctx = L;
    cfg->mem_fn = cyaml_mem;
    cfg->log_level = CYAML_LOG_ERROR;
    cfg->flags = CYAML_CFG_DEFAULT;
    return cfg;
}

/* Stage 2 and 3 on text whose document is L->doc. */
static int load_raw(loader *L, const char *text, size_t len, cs_raw_scene **raw)
{
    cyaml_config_t cfg;
    cs_spath p = {0};
    L->log_len = 0;
    L->log[0] = '\0';
    cyaml_err_t e = cyaml_load_data((const uint8_t *)text, len, cyaml_config_for(L, &cfg),
                                    &cs_scene_schema, (cyaml_data_t **)raw, NULL);
    if (e == CYAML_ERR_OOM)
        return CS_IMPORT_NOMEM;
    if (e != CYAML_OK)
        return translate_cyaml(L, e);
    if (!*raw)
        return fail_type(L, &p);
    return check_scalars(L, cs_sdoc_root(&L->doc), &cs_scene_schema, &p);
}

static void free_raw(loader *L, cs_raw_scene *raw)
{
    cyaml_config_t cfg;
    if (raw)
        cyaml_free(cyaml_config_for(L, &cfg), &cs_scene_schema, raw, 0);
}

/* ------------------------------------------------------------ geometry */

/* ------------------------------------------------------- value checks */

enum { NONE, GT, GE };   /* bound kinds */

typedef struct range {
    int lo_kind;
    double lo;
    int hi_kind;   /* NONE, GT means "<", GE means "<=" */
    double hi;
} range;

static const range ANY = {NONE, 0, NONE, 0};
static const range POSITIVE = {GT, 0, NONE, 0};
static const range NONNEG = {GE, 0, NONE, 0};
static const range UNIT = {GE, 0, GE, 1};

static bool in_range(double x, range r)
{
    if (r.lo_kind == GT && !(x > r.lo))
        return false;
    if (r.lo_kind == GE && !(x >= r.lo))
        return false;
    if (r.hi_kind == GT && !(x < r.hi))
        return false;
    if (r.hi_kind == GE && !(x <= r.hi))
        return false;
    return true;
}

static int fail_range(loader *L, const char *path, range r)
{
    if (r.hi_kind == NONE)
        return fail(L, path, true, "must be %s %g", r.lo_kind == GT ? ">" : ">=", r.lo);
    return fail(L, path, true, "must be in %c%g, %g%c", r.lo_kind == GT ? '(' : '[', r.lo, r.hi,
                r.hi_kind == GT ? ')' : ']');
}

/* An optional number: the value if given (checked), else the default. */
static int num(loader *L, const double *v, double def, range r, const char *path, double *out)
{
    if (v && !in_range(*v, r))
        return fail_range(L, path, r);
    *out = v ? *v : def;
    return CS_IMPORT_OK;
}

static int inum(loader *L, const int *v, int def, int lo, const char *path, int *out)
{
    if (v && *v < lo)
        return fail(L, path, true, "must be >= %d", lo);
    *out = v ? *v : def;
    return CS_IMPORT_OK;
}

/* An optional vector of n numbers, each checked. */
static int vec(loader *L, const double *v, int n, const double *def, range r, const char *path,
               double *out)
{
    char p[PATH_LEN + 16]; /* room for "[i]" after a full path */
    for (int i = 0; i < n; i++) {
        if (v && !in_range(v[i], r)) {
            snprintf(p, sizeof p, "%s[%d]", path, i);
            return fail_range(L, p, r);
        }
        out[i] = v ? v[i] : def ? def[i] : 0.0;
    }
    return CS_IMPORT_OK;
}

static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static const double zero3[3] = {0, 0, 0};
static const double identity_quat[4] = {1, 0, 0, 0};

/* ------------------------------------------------------------- motions */

/* A motion of a frame whose initial pose is (pos, rot). */
static int convert_motion(loader *L, const cs_raw_motion *rm, const char *path,
                          const double pos[3], const double rot[4], cs_motion *m)
{
    char p[PATH_LEN];
    int rc;
    memset(m, 0, sizeof *m);
    m->kind = CS_MOTION_STATIC;
    memcpy(m->position, pos, sizeof m->position);
    memcpy(m->rotation, rot, sizeof m->rotation);
    if (!rm)
        return CS_IMPORT_OK;
    bool constant = rm->velocity || rm->angular_velocity;
    if (constant && rm->keys)
        return fail(L, path, false,
                    "expected either velocity/angular_velocity or keys (got both)");
    if (constant) {
        m->kind = CS_MOTION_CONSTANT;
        snprintf(p, sizeof p, "%s.velocity", path);
        if ((rc = vec(L, rm->velocity, 3, zero3, ANY, p, m->velocity)))
            return rc;
        snprintf(p, sizeof p, "%s.angular_velocity", path);
        return vec(L, rm->angular_velocity, 3, zero3, ANY, p, m->angular_velocity);
    }
    if (!rm->keys)
        return CS_IMPORT_OK;
    cs_keyframe *keys = calloc(rm->keys_count, sizeof *keys);
    if (!keys)
        return CS_IMPORT_NOMEM;
    m->kind = CS_MOTION_KEYFRAMES;
    m->keys = keys;   /* owned by the scene from here on */
    m->nkeys = (int)rm->keys_count;
    for (unsigned k = 0; k < rm->keys_count; k++) {
        const cs_raw_key *rk = &rm->keys[k];
        double t[3], deg[3], q[4];
        if (k > 0 && !(rk->time > rm->keys[k - 1].time)) {
            snprintf(p, sizeof p, "%s.keys[%u].time", path, k);
            return fail(L, p, true, "must be greater than the previous key's time %g",
                        rm->keys[k - 1].time);
        }
        snprintf(p, sizeof p, "%s.keys[%u].translate", path, k);
        if ((rc = vec(L, rk->translate, 3, zero3, ANY, p, t)))
            return rc;
        snprintf(p, sizeof p, "%s.keys[%u].rotate", path, k);
        if ((rc = vec(L, rk->rotate, 3, zero3, ANY, p, deg)))
            return rc;
        keys[k].time = rk->time;
        for (int i = 0; i < 3; i++)
            keys[k].position[i] = pos[i] + t[i];
        cs_quat_from_euler_degrees(deg, q);
        cs_quat_multiply(q, rot, keys[k].rotation);
    }
    return CS_IMPORT_OK;
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
        return fail(L, path, false,
                    "expected exactly one of vertices, box or grid_points (got %d)", forms);
    unsigned char *mark = calloc((size_t)mesh->nv, 1);
    if (!mark)
        return CS_IMPORT_NOMEM;
    int rc = CS_IMPORT_OK;
    const char *form = "vertices";
    if (sel->vertices) {
        for (unsigned i = 0; i < sel->vertices_count && !rc; i++) {
            int v = sel->vertices[i];
            snprintf(p, sizeof p, "%s.vertices[%u]", path, i);
            if (v < 0 || v >= mesh->nv)
                rc = fail(L, p, true, "must be a vertex index in [0, %d]", mesh->nv - 1);
            else
                mark[v] = 1;
        }
    } else if (sel->box) {
        form = "box";
        for (int k = 0; k < 3 && !rc; k++)
            if (sel->box->min[k] > sel->box->max[k]) {
                snprintf(p, sizeof p, "%s.box.max[%d]", path, k);
                rc = fail(L, p, true, "must be >= min[%d] = %g", k, sel->box->min[k]);
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
            rc = fail(L, p, false, "only a grid cloth has grid points (this cloth is a mesh)");
        }
        for (unsigned i = 0; i < sel->grid_points_count && !rc; i++) {
            const int *ij = sel->grid_points[i];
            for (int k = 0; k < 2 && !rc; k++)
                if (ij[k] < 0 || ij[k] > grid_res[k]) {
                    snprintf(p, sizeof p, "%s.grid_points[%u][%d]", path, i, k);
                    rc = fail(L, p, true, "must be in [0, %d]", grid_res[k]);
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
        rc = fail(L, p, false, "selects no vertex");
    }
    if (!rc) {
        *out = malloc((size_t)n * sizeof **out);
        if (!*out)
            rc = CS_IMPORT_NOMEM;
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
static int convert_scripts(loader *L, const cs_raw_cloth *rc, const char *base,
                           const int *grid_res, cs_cloth_def *cd)
{
    const cs_trimesh *mesh = cd->mesh;
    char p[PATH_LEN];
    int err = CS_IMPORT_OK;
    int nscripts = (rc->pins_count > 0) + (int)rc->scripts_count;
    if (nscripts == 0)
        return CS_IMPORT_OK;
    cs_vertex_script *scripts = calloc((size_t)nscripts, sizeof *scripts);
    /* Who holds each vertex: 0 nobody, -(p+1) pin p, s+1 script s. */
    int *holder = calloc((size_t)mesh->nv, sizeof *holder);
    if (!scripts || !holder) {
        free(scripts);
        free(holder);
        return CS_IMPORT_NOMEM;
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
            err = CS_IMPORT_NOMEM;
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
                err = fail(L, p, false,
                           "must not select a pinned vertex (got vertex %d, pinned by %s.pins[%d])",
                           v[i], base, -h - 1);
            else if (h > 0)
                err = fail(L, p, false,
                           "must not select a vertex of another script "
                           "(got vertex %d, also in %s.scripts[%d])",
                           v[i], base, h - 1);
            else
                holder[v[i]] = (int)s + 1;
        }
        if (err)
            break;
        centroid(mesh, v, n, pivot);
        snprintf(p, sizeof p, "%s.scripts[%u].pivot", base, s);
        if ((err = vec(L, rs->pivot, 3, pivot, ANY, p, pivot)))
            break;
        snprintf(p, sizeof p, "%s.scripts[%u].motion", base, s);
        err = convert_motion(L, rs->motion, p, pivot, identity_quat, &vs->motion);
    }
    free(holder);
    return err;
}

/* --------------------------------------------------------------- cloths */

static int convert_grid(loader *L, const cs_raw_grid *g, const char *base, int res[2],
                        cs_trimesh **mesh)
{
    static const double default_size[2] = {1, 1};
    char p[PATH_LEN];
    double size[2], center[3], deg[3], q[4];
    int rc;
    snprintf(p, sizeof p, "%s.grid.size", base);
    if ((rc = vec(L, g->size, 2, default_size, POSITIVE, p, size)))
        return rc;
    res[0] = res[1] = 20;
    for (int k = 0; k < 2 && g->resolution; k++) {
        snprintf(p, sizeof p, "%s.grid.resolution[%d]", base, k);
        if ((rc = inum(L, &g->resolution[k], 20, 1, p, &res[k])))
            return rc;
    }
    /* Counts stay ints, and 3 * count indexes the arrays. */
    if ((int64_t)res[0] * res[1] > INT_MAX / 6 ||
        (int64_t)(res[0] + 1) * (res[1] + 1) > INT_MAX / 3) {
        snprintf(p, sizeof p, "%s.grid.resolution", base);
        return fail(L, p, false, "must give at most %d quads (got %d x %d)", INT_MAX / 6,
                    res[0], res[1]);
    }
    snprintf(p, sizeof p, "%s.grid.center", base);
    if ((rc = vec(L, g->center, 3, zero3, ANY, p, center)))
        return rc;
    snprintf(p, sizeof p, "%s.grid.rotation", base);
    if ((rc = vec(L, g->rotation, 3, zero3, ANY, p, deg)))
        return rc;
    cs_quat_from_euler_degrees(deg, q);
    *mesh = cs_trimesh_create_grid(size, res, q, center);
    return *mesh ? CS_IMPORT_OK : CS_IMPORT_NOMEM;
}

static int convert_mesh(loader *L, const cs_raw_mesh *m, const char *base, cs_trimesh **mesh)
{
    char p[PATH_LEN];
    double deg[3], t[3], q[4];
    int rc;
    int nv = (int)m->vertices_count, nt = (int)m->triangles_count;
    if (m->vertices_count > INT_MAX / 3 || m->triangles_count > INT_MAX / 3) {
        snprintf(p, sizeof p, "%s.mesh", base);
        return fail(L, p, false, "is too large");
    }
    for (int f = 0; f < nt; f++) {
        const int *c = m->triangles[f];
        for (int k = 0; k < 3; k++)
            if (c[k] < 0 || c[k] >= nv) {
                snprintf(p, sizeof p, "%s.mesh.triangles[%d][%d]", base, f, k);
                return fail(L, p, true, "must be a vertex index in [0, %d]", nv - 1);
            }
        if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
            snprintf(p, sizeof p, "%s.mesh.triangles[%d]", base, f);
            return fail(L, p, false, "must name three distinct vertices (got [%d, %d, %d])", c[0],
                        c[1], c[2]);
        }
    }
    snprintf(p, sizeof p, "%s.mesh.rotation", base);
    if ((rc = vec(L, m->rotation, 3, zero3, ANY, p, deg)))
        return rc;
    snprintf(p, sizeof p, "%s.mesh.translate", base);
    if ((rc = vec(L, m->translate, 3, zero3, ANY, p, t)))
        return rc;
    cs_quat_from_euler_degrees(deg, q);
    *mesh = cs_trimesh_create(nv, nt);
    if (!*mesh)
        return CS_IMPORT_NOMEM;
    for (int v = 0; v < nv; v++) {
        double r[3];
        cs_quat_rotate(q, m->vertices[v], r);
        for (int k = 0; k < 3; k++)
            (*mesh)->x[3 * v + k] = r[k] + t[k];
    }
    for (int f = 0; f < nt; f++)
        for (int k = 0; k < 3; k++)
            (*mesh)->tri[3 * f + k] = m->triangles[f][k];
    return CS_IMPORT_OK;
}

static int convert_material(loader *L, const cs_raw_material *m, const char *base,
                            cs_cloth_material *out)
{
    char p[PATH_LEN];
    int rc = CS_IMPORT_OK;
    *out = cs_default_cloth_material();
    if (!m)
        return CS_IMPORT_OK;
#define MAT(key, r)                                                        \
    do {                                                                   \
        snprintf(p, sizeof p, "%s.material." #key, base);                  \
        if ((rc = num(L, m->key, out->key, r, p, &out->key)))              \
            return rc;                                                     \
    } while (0)
    MAT(edge_stiffness, NONNEG);
    MAT(edge_overdamping, NONNEG);
    MAT(bend_stiffness, NONNEG);
    MAT(bend_overdamping, NONNEG);
    MAT(node_mass, POSITIVE);
    MAT(density, NONNEG);
#undef MAT
    return rc;
}

static int check_name(loader *L, const char *name, const char *path)
{
    if (name && !*name)
        return fail(L, path, false, "must not be empty");
    return CS_IMPORT_OK;
}

static int convert_cloth(loader *L, const cs_raw_cloth *rc, int ci, cs_scene *s)
{
    cs_cloth_def *cd = (cs_cloth_def *)&s->def.cloths[ci];
    char base[48], p[PATH_LEN];
    int err, res[2];
    cs_trimesh *mesh = NULL;

    snprintf(base, sizeof base, "cloths[%d]", ci);
    snprintf(p, sizeof p, "%s.name", base);
    if ((err = check_name(L, rc->name, p)))
        return err;
    char fallback[32];
    snprintf(fallback, sizeof fallback, "cloth%d", ci);
    if (!(cd->name = dup_str(rc->name ? rc->name : fallback)))
        return CS_IMPORT_NOMEM;
    for (int j = 0; j < ci; j++)
        if (!strcmp(s->def.cloths[j].name, cd->name))
            return fail(L, rc->name ? p : base, false,
                        "must differ from the name of cloths[%d] (got %s)", j, cd->name);
    snprintf(p, sizeof p, "%s.color", base);
    if ((err = vec(L, rc->color, 3, default_cloth_color, UNIT, p, s->cloth_colors + 3 * ci)))
        return err;

    if (!rc->grid == !rc->mesh)
        return fail(L, base, false, "expected exactly one of grid or mesh (got %s)",
                    rc->grid ? "both" : "neither");
    err = rc->grid ? convert_grid(L, rc->grid, base, res, &mesh)
                   : convert_mesh(L, rc->mesh, base, &mesh);
    cd->mesh = mesh;
    if (err)
        return err;

    if ((err = convert_material(L, rc->material, base, &cd->material)))
        return err;
    snprintf(p, sizeof p, "%s.velocity", base);
    if ((err = vec(L, rc->velocity, 3, zero3, ANY, p, cd->velocity)))
        return err;
    return convert_scripts(L, rc, base, rc->grid ? res : NULL, cd);
}

/* --------------------------------------------------------------- bodies */

/* A key that the body's shape does not use is a mistake, not a no-op. */
static int unused(loader *L, const void *given, const char *base, const char *key, int shape)
{
    char p[PATH_LEN];
    if (!given)
        return CS_IMPORT_OK;
    snprintf(p, sizeof p, "%s.%s", base, key);
    return fail(L, p, false, "is not used by a %s (remove it)", shape_names[shape]);
}

static int required(loader *L, const void *given, const char *base, const char *key, int shape)
{
    char p[PATH_LEN];
    if (given)
        return CS_IMPORT_OK;
    snprintf(p, sizeof p, "%s.%s", base, key);
    return fail(L, p, false, "is required for a %s", shape_names[shape]);
}

static int convert_body(loader *L, const cs_raw_body *rb, int bi, cs_scene *s)
{
    cs_body_def *bd = (cs_body_def *)&s->def.bodies[bi];
    char base[48], p[PATH_LEN];
    double pos[3], q[4];
    int err, shape = rb->shape;

    *bd = cs_default_body_def();
    bd->name = NULL;
    memset(&bd->motion, 0, sizeof bd->motion);
    snprintf(base, sizeof base, "bodies[%d]", bi);
    snprintf(p, sizeof p, "%s.name", base);
    if ((err = check_name(L, rb->name, p)))
        return err;
    char fallback[32];
    snprintf(fallback, sizeof fallback, "body%d", bi);
    if (!(bd->name = dup_str(rb->name ? rb->name : fallback)))
        return CS_IMPORT_NOMEM;
    for (int j = 0; j < bi; j++)
        if (!strcmp(s->def.bodies[j].name, bd->name))
            return fail(L, rb->name ? p : base, false,
                        "must differ from the name of bodies[%d] (got %s)", j, bd->name);
    bd->shape = (cs_body_shape)shape;

    snprintf(p, sizeof p, "%s.position", base);
    if ((err = vec(L, rb->position, 3, zero3, ANY, p, pos)))
        return err;
    if (rb->normal) {
        double n[3], len;
        if ((err = unused(L, shape == CS_BODY_PLANE ? NULL : rb->normal, base, "normal", shape)))
            return err;
        snprintf(p, sizeof p, "%s.normal", base);
        if (rb->rotation)
            return fail(L, p, false, "expected either normal or rotation (got both)");
        len = sqrt(rb->normal[0] * rb->normal[0] + rb->normal[1] * rb->normal[1] +
                   rb->normal[2] * rb->normal[2]);
        if (!(len > 0) || !isfinite(len))
            return fail(L, p, false, "must be a nonzero vector");
        for (int k = 0; k < 3; k++)
            n[k] = rb->normal[k] / len;
        cs_quat_from_y_to(n, q);
    } else {
        double deg[3];
        snprintf(p, sizeof p, "%s.rotation", base);
        if ((err = vec(L, rb->rotation, 3, zero3, ANY, p, deg)))
            return err;
        cs_quat_from_euler_degrees(deg, q);
    }

    bool radius = shape == CS_BODY_SPHERE || shape == CS_BODY_CYLINDER;
    bool size = shape == CS_BODY_BOX, height = shape == CS_BODY_CYLINDER;
    if ((err = (radius ? required : unused)(L, rb->radius, base, "radius", shape)) ||
        (err = (size ? required : unused)(L, rb->size, base, "size", shape)) ||
        (err = (height ? required : unused)(L, rb->height, base, "height", shape)))
        return err;
    snprintf(p, sizeof p, "%s.radius", base);
    if ((err = num(L, rb->radius, bd->radius, POSITIVE, p, &bd->radius)))
        return err;
    if (rb->size) {
        snprintf(p, sizeof p, "%s.size", base);
        if ((err = vec(L, rb->size, 3, NULL, POSITIVE, p, bd->half_extents)))
            return err;
        for (int k = 0; k < 3; k++)
            bd->half_extents[k] *= 0.5;
    }
    if (rb->height) {
        snprintf(p, sizeof p, "%s.height", base);
        if ((err = num(L, rb->height, 0, POSITIVE, p, &bd->half_height)))
            return err;
        bd->half_height *= 0.5;
    }
    snprintf(p, sizeof p, "%s.friction", base);
    if ((err = num(L, rb->friction, bd->friction, NONNEG, p, &bd->friction)))
        return err;
    snprintf(p, sizeof p, "%s.color", base);
    if ((err = vec(L, rb->color, 3, default_body_color, UNIT, p, s->body_colors + 3 * bi)))
        return err;
    snprintf(p, sizeof p, "%s.motion", base);
    return convert_motion(L, rb->motion, p, pos, q, &bd->motion);
}

/* ---------------------------------------------------------------- scene */

static int convert_time(loader *L, const cs_raw_time *t, cs_scene *s)
{
    cs_sim_def *d = &s->def;
    int rc;
    s->frames = DEFAULT_FRAMES;
    if (!t)
        return CS_IMPORT_OK;
    static const range safety = {GT, 0, GE, 1};
    if ((rc = num(L, t->fps, d->fps, POSITIVE, "time.fps", &d->fps)) ||
        (rc = inum(L, t->frames, DEFAULT_FRAMES, 0, "time.frames", &s->frames)) ||
        (rc = num(L, t->dt_safety, d->dt_safety, safety, "time.dt_safety", &d->dt_safety)) ||
        (rc = inum(L, t->collision_steps, d->collision_steps, 1, "time.collision_steps",
                   &d->collision_steps)) ||
        (rc = num(L, t->cg_tolerance, d->cg_tolerance, POSITIVE, "time.cg_tolerance",
                  &d->cg_tolerance)) ||
        (rc = inum(L, t->cg_max_iterations, d->cg_max_iterations, 1, "time.cg_max_iterations",
                   &d->cg_max_iterations)))
        return rc;
    if (t->dt) {
        /* A string in the schema so that "auto" loads; read the number here. */
        char *end;
        double dt = 0;
        bool automatic = !strcmp(t->dt, "auto");
        if (!automatic) {
            dt = strtod(t->dt, &end);
            if (!*t->dt || isspace((unsigned char)*t->dt) || *end || !isfinite(dt) || dt < 0)
                return fail(L, "time.dt", true, "expected a number >= 0 or auto");
        }
        d->dt = dt;
    }
    return CS_IMPORT_OK;
}

static int convert_camera(loader *L, const cs_raw_camera *c, cs_camera_def *cam)
{
    static const double up[3] = {0, 1, 0};
    static const range fov = {GT, 0, GT, 180};
    int rc;
    memset(cam, 0, sizeof *cam);
    memcpy(cam->up, up, sizeof cam->up);
    cam->fov_degrees = DEFAULT_FOV;
    if (!c)
        return CS_IMPORT_OK;
    cam->given = true;
    if ((rc = vec(L, c->position, 3, NULL, ANY, "camera.position", cam->position)) ||
        (rc = vec(L, c->target, 3, NULL, ANY, "camera.target", cam->target)) ||
        (rc = vec(L, c->up, 3, up, ANY, "camera.up", cam->up)) ||
        (rc = num(L, c->fov, DEFAULT_FOV, fov, "camera.fov", &cam->fov_degrees)))
        return rc;
    double dir[3], cross[3];
    for (int k = 0; k < 3; k++)
        dir[k] = cam->target[k] - cam->position[k];
    if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0)
        return fail(L, "camera.target", false, "must differ from camera.position");
    cross[0] = cam->up[1] * dir[2] - cam->up[2] * dir[1];
    cross[1] = cam->up[2] * dir[0] - cam->up[0] * dir[2];
    cross[2] = cam->up[0] * dir[1] - cam->up[1] * dir[0];
    double lc = sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    double lu = sqrt(cam->up[0] * cam->up[0] + cam->up[1] * cam->up[1] + cam->up[2] * cam->up[2]);
    double ld = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (!(lc > 1e-9 * lu * ld))
        return fail(L, "camera.up", false,
                    "must be nonzero and not along the view direction (target - position)");
    return CS_IMPORT_OK;
}

/* "dir/name.yaml" -> "name". */
static char *file_stem(const char *file)
{
    const char *base = strrchr(file, '/');
    base = base ? base + 1 : file;
    const char *dot = strrchr(base, '.');
    size_t n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    char *stem = malloc(n + 1);
    if (stem) {
        memcpy(stem, base, n);
        stem[n] = '\0';
    }
    return stem;
}

static int convert_scene(loader *L, const cs_raw_scene *r, const char *default_name,
                         cs_scene **out)
{
    int rc;
    cs_scene *s = calloc(1, sizeof *s);
    *out = NULL;
    if (!s)
        return CS_IMPORT_NOMEM;
    s->def = cs_default_sim_def();
    s->def.cloths = NULL;
    s->def.ncloths = 0;
    s->def.bodies = NULL;
    s->def.nbodies = 0;

    if ((rc = check_name(L, r->name, "name")))
        goto fail;
    s->name = r->name        ? dup_str(r->name)
              : default_name ? dup_str(default_name)
                             : file_stem(L->file);
    s->path = dup_str(L->file);
    if (!s->name || !s->path)
        goto nomem;

    if ((rc = convert_time(L, r->time, s)) ||
        (rc = vec(L, r->gravity, 3, s->def.gravity, ANY, "gravity", s->def.gravity)))
        goto fail;

    /* Effects default on, except self-collision and friction, which keep
     * cs_default_sim_def()'s choice. */
    bool wind_effect = true;
    s->def.bodies_enabled = true;
    if (r->effects) {
        if (r->effects->bodies)
            s->def.bodies_enabled = *r->effects->bodies;
        if (r->effects->wind)
            wind_effect = *r->effects->wind;
        if (r->effects->self_collision)
            s->def.self_collision = *r->effects->self_collision;
        if (r->effects->friction)
            s->def.friction_method = (cs_friction_method)*r->effects->friction;
    }
    if (r->self_collision) {
        const cs_raw_self *c = r->self_collision;
        cs_self_collision_def *d = &s->def.self;
        static const range epsilon = {GE, -1, GE, 1};
        if ((rc = num(L, c->thickness, d->thickness, POSITIVE, "self_collision.thickness",
                      &d->thickness)) ||
            (rc = num(L, c->stiffness, d->stiffness, NONNEG, "self_collision.stiffness",
                      &d->stiffness)) ||
            (rc = num(L, c->friction, d->friction, NONNEG, "self_collision.friction",
                      &d->friction)) ||
            (rc = num(L, c->edge_flip_epsilon, d->edge_flip_epsilon, epsilon,
                      "self_collision.edge_flip_epsilon", &d->edge_flip_epsilon)) ||
            (rc = inum(L, c->zone_iterations, d->zone_iterations, 1,
                       "self_collision.zone_iterations", &d->zone_iterations)))
            goto fail;
        if (c->scheme)
            d->scheme = (cs_collision_scheme)*c->scheme;
        if (c->verify)
            d->verify = *c->verify;
    }
    memset(&s->def.wind, 0, sizeof s->def.wind);
    if (r->wind) {
        if ((rc = vec(L, r->wind->velocity, 3, zero3, ANY, "wind.velocity",
                      s->def.wind.velocity)) ||
            (rc = num(L, r->wind->drag, 0, NONNEG, "wind.drag", &s->def.wind.drag)))
            goto fail;
    }
    s->def.wind_enabled = r->wind && wind_effect && s->def.wind.drag > 0;

    s->output_format = dup_str(cs_scene_format_names[r->output && r->output->format
                                                         ? *r->output->format
                                                         : 0]);
    if (!s->output_format)
        goto nomem;
    if ((rc = convert_camera(L, r->camera, &s->camera)))
        goto fail;

    /* Arrays are zeroed first so that a partly filled scene frees cleanly. */
    s->cloth_colors = calloc(3 * (size_t)r->cloths_count, sizeof *s->cloth_colors);
    s->def.cloths = calloc(r->cloths_count, sizeof *s->def.cloths);
    if (!s->cloth_colors || !s->def.cloths)
        goto nomem;
    s->def.ncloths = (int)r->cloths_count;
    for (unsigned c = 0; c < r->cloths_count; c++)
        if ((rc = convert_cloth(L, &r->cloths[c], (int)c, s)))
            goto fail;

    if (r->bodies_count > 0) {
        s->body_colors = calloc(3 * (size_t)r->bodies_count, sizeof *s->body_colors);
        s->def.bodies = calloc(r->bodies_count, sizeof *s->def.bodies);
        if (!s->body_colors || !s->def.bodies)
            goto nomem;
        s->def.nbodies = (int)r->bodies_count;
        for (unsigned b = 0; b < r->bodies_count; b++)
            if ((rc = convert_body(L, &r->bodies[b], (int)b, s)))
                goto fail;
    }
    *out = s;
    return CS_IMPORT_OK;
nomem:
    rc = CS_IMPORT_NOMEM;
fail:
    cs_scene_destroy(s);
    return rc;
}

void cs_scene_destroy(cs_scene *s)
{
    if (!s)
        return;
    for (int c = 0; s->def.cloths && c < s->def.ncloths; c++) {
        cs_cloth_def *cd = (cs_cloth_def *)&s->def.cloths[c];
        free((void *)cd->name);
        if (cd->mesh)
            cs_trimesh_destroy((cs_trimesh *)cd->mesh);
        for (int i = 0; cd->scripts && i < cd->nscripts; i++) {
            free((void *)cd->scripts[i].vertices);
            free((void *)cd->scripts[i].motion.keys);
        }
        free((void *)cd->scripts);
    }
    free((void *)s->def.cloths);
    for (int b = 0; s->def.bodies && b < s->def.nbodies; b++) {
        free((void *)s->def.bodies[b].name);
        free((void *)s->def.bodies[b].motion.keys);
    }
    free((void *)s->def.bodies);
    free(s->name);
    free(s->path);
    free(s->output_format);
    free(s->cloth_colors);
    free(s->body_colors);
    free(s);
}

/* --------------------------------------------------------------- loading */

/* Applies the overrides to L->doc and loads the result into *raw. */
static int apply_overrides(loader *L, cs_raw_scene **raw, char *err, size_t errlen)
{
    char msg[MSG_LEN];
    for (int k = 0; k < L->noverrides; k++) {
        const char *ov = L->overrides[k];
        const char *eq = ov ? strchr(ov, '=') : NULL;
        cs_spath p;
        if (!eq) {
            set_err(err, errlen, "--set %s: expected PATH=VALUE", ov ? ov : "(null)");
            return CS_IMPORT_BAD_INPUT;
        }
        char path[PATH_LEN];
        size_t n = (size_t)(eq - ov);
        if (n >= sizeof path || (memcpy(path, ov, n), path[n] = '\0', !cs_spath_parse(&p, path))) {
            set_err(err, errlen,
                    "--set %s: expected a key path like cloths.0.material.node_mass before '='",
                    ov);
            return CS_IMPORT_BAD_INPUT;
        }
        int rc = cs_sdoc_set(&L->doc, &p, eq + 1, k, msg, sizeof msg);
        if (rc == CS_SDOC_NOMEM)
            return CS_IMPORT_NOMEM;
        if (rc != CS_SDOC_OK) {
            set_err(err, errlen, "--set %s: %s", ov, msg);
            return CS_IMPORT_BAD_INPUT;
        }
    }
    char *text;
    size_t len;
    int rc = cs_sdoc_emit(&L->doc, &text, &len, msg, sizeof msg);
    if (rc == CS_SDOC_NOMEM)
        return CS_IMPORT_NOMEM;
    if (rc != CS_SDOC_OK) {
        set_err(err, errlen, "--set %s: %s", L->overrides[L->noverrides - 1], msg);
        return CS_IMPORT_BAD_INPUT;
    }
    rc = load_raw(L, text, len, raw);
    free(text);
    if (rc == CS_IMPORT_BAD_INPUT)
        return report(L, true, err, errlen);
    return rc;
}

/* The merged scene failed to convert. Errors in nodes an override made are
 * that override's; others are checked against the file alone, which may be
 * where the error really is. */
static int report_merged(loader *L, const cs_raw_scene *orig, const char *default_name,
                         char *err, size_t errlen)
{
    cs_sloc loc;
    cs_sdoc_locate(&L->doc, &L->err_path, false, &loc);
    if (loc.owner >= 0)
        return report(L, true, err, errlen);
    cs_spath path = L->err_path;
    char msg[MSG_LEN];
    memcpy(msg, L->err_msg, sizeof msg);
    cs_scene *alone = NULL;
    int rc = convert_scene(L, orig, default_name, &alone);
    cs_scene_destroy(alone);
    if (rc == CS_IMPORT_NOMEM)
        return rc;
    if (rc == CS_IMPORT_BAD_INPUT) {
        cs_sdoc_locate(&L->doc, &L->err_path, false, &loc);
        if (loc.owner < 0)
            return report(L, false, err, errlen);
    }
    L->err_path = path;
    memcpy(L->err_msg, msg, sizeof msg);
    return report(L, true, err, errlen);
}

static int load(const char *text, size_t len, const char *file, const char *default_name,
                int noverrides, const char *const *overrides, cs_scene **out, char *err,
                size_t errlen)
{
    loader *L = calloc(1, sizeof *L);
    cs_raw_scene *raw = NULL, *merged = NULL;
    char msg[MSG_LEN];
    int line = 1, rc;

    if (!L)
        return CS_IMPORT_NOMEM;
    L->file = file;
    L->noverrides = overrides ? noverrides : 0;
    L->overrides = overrides;

    rc = cs_sdoc_load(&L->doc, text, len, &line, msg, sizeof msg);
    if (rc == CS_SDOC_BAD) {
        set_err(err, errlen, "%s:%d: %s", file, line, msg);
        rc = CS_IMPORT_BAD_INPUT;
    } else if (rc == CS_SDOC_NOMEM) {
        rc = CS_IMPORT_NOMEM;
    } else if (!cs_sdoc_root(&L->doc)) {
        set_err(err, errlen, "%s:1: the scene is empty (expected a mapping with at least cloths)",
                file);
        rc = CS_IMPORT_BAD_INPUT;
    } else if ((rc = load_raw(L, text, len, &raw)) == CS_IMPORT_BAD_INPUT) {
        rc = report(L, false, err, errlen);
    } else if (rc == CS_IMPORT_OK && L->noverrides > 0) {
        rc = apply_overrides(L, &merged, err, errlen);
        if (rc == CS_IMPORT_OK) {
            rc = convert_scene(L, merged, default_name, out);
            if (rc == CS_IMPORT_BAD_INPUT)
                rc = report_merged(L, raw, default_name, err, errlen);
        }
    } else if (rc == CS_IMPORT_OK) {
        rc = convert_scene(L, raw, default_name, out);
        if (rc == CS_IMPORT_BAD_INPUT)
            rc = report(L, false, err, errlen);
    }
    if (rc == CS_IMPORT_NOMEM)
        set_err(err, errlen, "%s: out of memory", file);
    free_raw(L, raw);
    free_raw(L, merged);
    cs_sdoc_free(&L->doc);
    free(L);
    return rc;
}

int cs_scene_load_string(const char *text, const char *origin, int noverrides,
                         const char *const *overrides, cs_scene **out, char *err, size_t errlen)
{
    if (!out)
        return CS_IMPORT_BAD_INPUT;
    *out = NULL;
    if (!text) {
        set_err(err, errlen, "%s: no text", origin ? origin : "<string>");
        return CS_IMPORT_BAD_INPUT;
    }
    return load(text, strlen(text), origin ? origin : "<string>", origin ? NULL : "scene",
                noverrides, overrides, out, err, errlen);
}

/* The whole file, NUL-terminated; NULL with errno set on failure. */
static char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *data = NULL;
    size_t cap = 0, n = 0;
    if (!f)
        return NULL;
    for (;;) {
        if (n + 4096 + 1 > cap) {
            size_t ncap = cap ? 2 * cap : 65536;
            char *p = realloc(data, ncap);
            if (!p) {
                free(data);
                fclose(f);
                errno = ENOMEM;
                return NULL;
            }
            data = p;
            cap = ncap;
        }
        size_t got = fread(data + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0) {
            int e = ferror(f) ? errno : 0;
            fclose(f);
            if (e) {
                free(data);
                errno = e;
                return NULL;
            }
            break;
        }
    }
    data[n] = '\0';
    *len = n;
    return data;
}

int cs_scene_load(const char *path, int noverrides, const char *const *overrides,
                  cs_scene **out, char *err, size_t errlen)
{
    size_t len = 0;
    if (!out)
        return CS_IMPORT_BAD_INPUT;
    *out = NULL;
    if (!path) {
        set_err(err, errlen, "no scene file given");
        return CS_IMPORT_BAD_INPUT;
    }
    char *text = read_file(path, &len);
    if (!text) {
        set_err(err, errlen, "%s: cannot read: %s", path, strerror(errno));
        return errno == ENOMEM ? CS_IMPORT_NOMEM : CS_IMPORT_BAD_INPUT;
    }
    /* libyaml would stop at a NUL byte without saying so. */
    if (strlen(text) != len) {
        int line = 1;
        for (const char *c = text; *c; c++)
            line += *c == '\n';
        set_err(err, errlen, "%s:%d: the file contains a NUL byte (not a text file?)", path, line);
        free(text);
        return CS_IMPORT_BAD_INPUT;
    }
    int rc = load(text, len, path, NULL, noverrides, overrides, out, err, errlen);
    free(text);
    return rc;
}
