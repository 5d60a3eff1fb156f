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

static const char *const shape_names[] = {"plane", "sphere", "box", "cylinder", "mesh"};

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
    /* for refusing a grid that cannot fit before tessellating it */
    bool self_collision;
    double particles;            /* of the cloths converted so far */
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

/* A line for the user (see cs_scene.notes); false when memory runs out. */
static bool add_note(cs_scene *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static bool add_note(cs_scene *s, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    char **notes = realloc(s->notes, ((size_t)s->nnotes + 1) * sizeof *notes);
    if (!notes)
        return false;
    s->notes = notes;
    if (!(notes[s->nnotes] = dup_str(line)))
        return false;
    s->nnotes++;
    return true;
}

/* The folder of the scene file, to which its paths are relative. */
static char *scene_dir(const char *file)
{
    const char *slash = file ? strrchr(file, '/') : NULL;
    if (!file || file[0] == '<' || !slash)
        return dup_str(".");
    size_t n = slash == file ? 1 : (size_t)(slash - file);
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, file, n);
        d[n] = '\0';
    }
    return d;
}

/* path relative to the scene's folder, unless absolute */
static char *scene_relative(const char *file, const char *path)
{
    if (path[0] == '/')
        return dup_str(path);
    char *dir = scene_dir(file);
    if (!dir)
        return NULL;
    size_t n = strlen(dir) + strlen(path) + 2;
    char *out = malloc(n);
    if (out)
        snprintf(out, n, "%s/%s", dir, path);
    free(dir);
    return out;
}

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

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
    /* Refused before the tessellation and the simulation allocate it (a
     * 5000 x 5000 grid used to take 13.8 GB before anything said no). */
    double particles = (double)(res[0] + 1) * (res[1] + 1), all = L->particles + particles;
    char why[160];
    if (!cs_memory_fits(cs_sim_estimate_bytes(all, L->self_collision), why, sizeof why)) {
        snprintf(p, sizeof p, "%s.grid.resolution", base);
        return fail(L, p, false, "%d x %d quads (%.3g particles%s) to simulate%s: %s", res[0],
                    res[1], particles, all > particles ? " with the cloths before" : "",
                    L->self_collision ? " with self-collision" : "", why);
    }
    snprintf(p, sizeof p, "%s.grid.center", base);
    if ((rc = vec(L, g->center, 3, zero3, ANY, p, center)))
        return rc;
    snprintf(p, sizeof p, "%s.grid.rotation", base);
    if ((rc = vec(L, g->rotation, 3, zero3, ANY, p, deg)))
        return rc;
    cs_quat_from_euler_degrees(deg, q);
    *mesh = cs_trimesh_create_grid(size, res, q, center);
    L->particles = all;
    return *mesh ? CS_IMPORT_OK : CS_IMPORT_NOMEM;
}

/* mesh.scale: one number (uniform) or three, each > 0. Read from the
 * document: the schema cannot say "a number or a list". */
static int read_scale(loader *L, const char *path, double out[3])
{
    static const char *want = "expected a number > 0 or a list of 3 numbers > 0";
    cs_spath p;
    cs_sloc loc;
    out[0] = out[1] = out[2] = 1;
    if (!cs_spath_parse(&p, path))
        return CS_IMPORT_OK;
    cs_sdoc_locate(&L->doc, &p, false, &loc);
    if (loc.matched != p.n || !loc.node)
        return CS_IMPORT_OK;
    const yaml_node_t *n = yaml_document_get_node(&L->doc.doc, loc.node);
    if (!n)
        return CS_IMPORT_OK;
    int items = 1;
    const yaml_node_item_t *item = NULL;
    if (n->type == YAML_SEQUENCE_NODE) {
        item = n->data.sequence.items.start;
        items = (int)(n->data.sequence.items.top - item);
        if (items != 3)
            return fail(L, path, false, "%s (got a list of %d)", want, items);
    } else if (n->type != YAML_SCALAR_NODE) {
        return fail(L, path, true, "%s", want);
    }
    for (int k = 0; k < items; k++) {
        const yaml_node_t *e = item ? yaml_document_get_node(&L->doc.doc, item[k]) : n;
        char ep[PATH_LEN + 8];
        snprintf(ep, sizeof ep, item ? "%s[%d]" : "%s", path, k);
        if (!e || e->type != YAML_SCALAR_NODE)
            return fail(L, ep, true, "%s", item ? "expected a number > 0" : want);
        const char *text = (const char *)e->data.scalar.value;
        char *end;
        double v = strtod(text, &end);
        if (!*text || isspace((unsigned char)*text) || *end || !isfinite(v))
            return fail(L, ep, true, "%s", item ? "expected a number > 0" : want);
        if (!(v > 0))
            return fail(L, ep, true, "must be > 0");
        for (int d = item ? k : 0; d < (item ? k + 1 : 3); d++)
            out[d] = v;
    }
    return CS_IMPORT_OK;
}

/* The placement keys of a mesh block. */
static int convert_placement(loader *L, const cs_raw_mesh *m, const char *mp,
                             cs_mesh_placement *pl)
{
    char p[PATH_LEN];
    double deg[3];
    int rc;
    *pl = cs_default_mesh_placement();
    snprintf(p, sizeof p, "%s.scale", mp);
    if ((rc = read_scale(L, p, pl->scale)))
        return rc;
    snprintf(p, sizeof p, "%s.rotation", mp);
    if ((rc = vec(L, m->rotation, 3, zero3, ANY, p, deg)))
        return rc;
    cs_quat_from_euler_degrees(deg, pl->rotation);
    snprintf(p, sizeof p, "%s.translate", mp);
    return vec(L, m->translate, 3, zero3, ANY, p, pl->translate);
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
        return fail(L, p, false, "is only used with vertices (remove it or the file)");
    }
    if ((rc = convert_placement(L, m, mp, &pl)))
        return rc;
    pl.node = m->node;
    if (m->units && *m->units > 0 &&
        !cs_mesh_units_from_name(cs_scene_unit_names[*m->units], &pl.unit_scale))
        pl.unit_scale = 0;
    snprintf(p, sizeof p, "%s.file", mp);
    if (!*m->file)
        return fail(L, p, false, "must not be empty");
    if (!(*file = scene_relative(L->file, m->file)))
        return CS_IMPORT_NOMEM;
    rc = cs_mesh_import(*file, &pl, mesh, rep, why, sizeof why);
    if (rc == CS_IMPORT_BAD_INPUT) {
        /* a node that is not there is the node key's fault */
        if (m->node && rep->format[0] && rep->instances == 0)
            snprintf(p, sizeof p, "%s.node", mp);
        return fail(L, p, false, "%s", why);
    }
    return rc;
}

static int convert_mesh(loader *L, const cs_raw_mesh *m, const char *base, cs_trimesh **mesh,
                        cs_mesh_report *rep, char **file)
{
    char p[PATH_LEN + 64], mp[PATH_LEN];
    int rc;
    snprintf(mp, sizeof mp, "%s.mesh", base);
    memset(rep, 0, sizeof *rep);
    *file = NULL;
    if (!m->file == !m->vertices)
        return fail(L, mp, false, "expected exactly one of file or vertices (got %s)",
                    m->file ? "both" : "neither");
    if (m->file)
        return convert_mesh_file(L, m, mp, mesh, rep, file);
    if (m->node || m->units) {
        snprintf(p, sizeof p, "%s.%s", mp, m->node ? "node" : "units");
        return fail(L, p, false, "is only used with file (remove it)");
    }
    int nv = (int)m->vertices_count, nt = (int)m->triangles_count;
    if (m->vertices_count > INT_MAX / 3 || m->triangles_count > INT_MAX / 3)
        return fail(L, mp, false, "is too large");
    for (int f = 0; f < nt; f++) {
        const int *c = m->triangles[f];
        for (int k = 0; k < 3; k++)
            if (c[k] < 0 || c[k] >= nv) {
                snprintf(p, sizeof p, "%s.triangles[%d][%d]", mp, f, k);
                return fail(L, p, true, "must be a vertex index in [0, %d]", nv - 1);
            }
        if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
            snprintf(p, sizeof p, "%s.triangles[%d]", mp, f);
            return fail(L, p, false, "must name three distinct vertices (got [%d, %d, %d])", c[0],
                        c[1], c[2]);
        }
    }
    cs_mesh_placement pl;
    if ((rc = convert_placement(L, m, mp, &pl)))
        return rc;
    *mesh = cs_trimesh_create(nv, nt);
    if (!*mesh)
        return CS_IMPORT_NOMEM;
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
    return CS_IMPORT_OK;
}

/* One line on what import did with a mesh file, and a warning for what the
 * cloth or body will feel. */
static bool note_mesh(cs_scene *s, const char *who, const char *file, const cs_mesh_report *r,
                      bool body)
{
    char fixes[256] = "";
    size_t used = 0;
    if (r->degenerate_triangles)
        used += (size_t)snprintf(fixes + used, sizeof fixes - used,
                                 "; dropped %d zero-area triangle%s", r->degenerate_triangles,
                                 r->degenerate_triangles == 1 ? "" : "s");
    if (r->duplicate_triangles && used < sizeof fixes)
        used += (size_t)snprintf(fixes + used, sizeof fixes - used,
                                 "; dropped %d duplicate triangle%s", r->duplicate_triangles,
                                 r->duplicate_triangles == 1 ? "" : "s");
    if (r->unreferenced_vertices && used < sizeof fixes)
        snprintf(fixes + used, sizeof fixes - used, "; dropped %d unused vertices",
                 r->unreferenced_vertices);
    if (!add_note(s, "%s: %s (%s, %s): %d triangles, %d vertices, %d part%s, %s%s", who,
                  base_name(file), r->format, r->units, r->triangles, r->vertices, r->parts,
                  r->parts == 1 ? "" : "s", r->closed ? "closed" : "open", fixes))
        return false;
    if (r->size_warning[0] && !add_note(s, "warning: %s: %s", who, r->size_warning))
        return false;
    if (r->nonmanifold_edges &&
        !add_note(s, "warning: %s: %d non-manifold edge%s (more than two triangles on an edge)%s",
                  who, r->nonmanifold_edges, r->nonmanifold_edges == 1 ? "" : "s",
                  body ? "" : "; bending springs join every pair of triangles across them"))
        return false;
    if (r->inconsistent_edges &&
        !add_note(s, "warning: %s: %d edge%s where neighbouring triangles disagree on "
                  "orientation", who, r->inconsistent_edges, r->inconsistent_edges == 1 ? "" : "s"))
        return false;
    return true;
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
    cs_mesh_report report;
    char *file = NULL;
    err = rc->grid ? convert_grid(L, rc->grid, base, res, &mesh)
                   : convert_mesh(L, rc->mesh, base, &mesh, &report, &file);
    cd->mesh = mesh;
    if (!err && file) {
        char who[128];
        snprintf(who, sizeof who, "%s '%.60s'", base, cd->name);
        if (!note_mesh(s, who, file, &report, false))
            err = CS_IMPORT_NOMEM;
    }
    free(file);
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

#define DEFAULT_BAND 3.0

/* The mesh of a mesh body, in the body's local frame, and its grid
 * settings; the grid itself is made once the whole scene is known
 * (finish_mesh_bodies, build_levelsets). */
static int convert_mesh_body(loader *L, const cs_raw_body *rb, int bi, cs_scene *s)
{
    cs_scene_mesh_body *mb = &s->mesh_bodies[bi];
    char base[48], p[PATH_LEN];
    int err;
    snprintf(base, sizeof base, "bodies[%d]", bi);
    if ((err = convert_mesh(L, rb->mesh, base, &mb->mesh, &mb->report, &mb->file)))
        return err;
    if (!mb->file && !(mb->file = dup_str("(inline)")))
        return CS_IMPORT_NOMEM;
    if (mb->mesh->nt == 0) {
        snprintf(p, sizeof p, "%s.mesh", base);
        return fail(L, p, false, "must have triangles for a body");
    }
    /* a band is a few voxels: beyond 1000 the default voxel size coarsens
     * to nothing and the message would blame the voxel size */
    static const range at_least_one = {GE, 1, GE, 1000};
    snprintf(p, sizeof p, "%s.voxel_size", base);
    if ((err = num(L, rb->voxel_size, 0, POSITIVE, p, &mb->voxel_size)))
        return err;
    snprintf(p, sizeof p, "%s.band", base);
    if ((err = num(L, rb->band, DEFAULT_BAND, at_least_one, p, &mb->band)))
        return err;
    mb->close_holes = rb->close_holes ? *rb->close_holes : true;
    mb->interior = rb->interior ? (cs_interior_mode)*rb->interior : CS_INTERIOR_AUTO;
    return CS_IMPORT_OK;
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
static int finish_mesh_bodies(loader *L, cs_scene *s)
{
    double edge = -1;
    for (int b = 0; b < s->def.nbodies; b++) {
        cs_scene_mesh_body *mb = &s->mesh_bodies[b];
        if (!mb->mesh)
            continue;
        char base[48], p[PATH_LEN], who[128], why[256];
        snprintf(base, sizeof base, "bodies[%d]", b);
        snprintf(who, sizeof who, "%s '%.60s'", base, s->def.bodies[b].name);
        if (strcmp(mb->file, "(inline)") && !note_mesh(s, who, mb->file, &mb->report, true))
            return CS_IMPORT_NOMEM;
        cs_trimesh *sign = mb->mesh;
        cs_mesh_report closed = mb->report;
        if (!mb->report.closed && mb->close_holes) {
            /* a copy with the holes closed; mb->mesh stays as read */
            sign = cs_trimesh_create(mb->mesh->nv, mb->mesh->nt);
            if (!sign)
                return CS_IMPORT_NOMEM;
            memcpy(sign->x, mb->mesh->x, 3 * (size_t)mb->mesh->nv * sizeof *sign->x);
            memcpy(sign->tri, mb->mesh->tri, 3 * (size_t)mb->mesh->nt * sizeof *sign->tri);
            mb->holes_closed = cs_mesh_close_holes(&sign);
            if (mb->holes_closed < 0) {
                cs_trimesh_destroy(sign);
                return CS_IMPORT_NOMEM;
            }
            cs_mesh_analyse(sign, &closed);
        }
        mb->sign_mesh = sign;
        if (!mb->report.closed) {
            bool ok;
            if (!mb->close_holes)
                ok = add_note(s, "warning: %s: the mesh is not closed (%d boundary edges) and "
                                 "close_holes is false: the sign comes from OpenVDB's flood fill "
                                 "from outside, which leaks in through holes wider than about a "
                                 "voxel",
                              who, mb->report.boundary_edges);
            else if (closed.closed)
                ok = add_note(s, "warning: %s: the mesh is not closed (%d boundary edges in %d "
                                 "loop%s); closed them with fans to each loop's centre so the "
                                 "level set has an inside",
                              who, mb->report.boundary_edges, mb->report.boundary_loops,
                              mb->report.boundary_loops == 1 ? "" : "s");
            else
                ok = add_note(s, "warning: %s: the mesh is not closed and stays open after "
                                 "closing %d loop%s (%d boundary and %d non-manifold edges "
                                 "left): the sign may be wrong near them",
                              who, mb->holes_closed, mb->holes_closed == 1 ? "" : "s",
                              closed.boundary_edges, closed.nonmanifold_edges);
            if (!ok)
                return CS_IMPORT_NOMEM;
        }
        bool given = mb->voxel_size > 0;
        bool fill = mb->interior == CS_INTERIOR_FILL;
        if (!given) {
            if (edge < 0)
                edge = cloth_edge_median(&s->def);
            mb->voxel_size = cs_levelset_default_voxel(&closed, edge, mb->band, fill);
        }
        mb->fill_interior = mb->interior == CS_INTERIOR_AUTO
                                ? cs_levelset_auto_fill(&closed, mb->voxel_size)
                                : fill;
        if (!cs_levelset_voxel_ok(&closed, mb->voxel_size, mb->band, mb->fill_interior, why,
                                  sizeof why)) {
            snprintf(p, sizeof p, "%s%s", base, given ? ".voxel_size" : "");
            if (given)
                return fail(L, p, true, "%s", why);
            return fail(L, p, false, "the default voxel_size %.3g m %s", mb->voxel_size, why);
        }
    }
    return CS_IMPORT_OK;
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
    bool mesh = shape == CS_BODY_MESH;
    if ((err = (mesh ? required : unused)(L, rb->mesh, base, "mesh", shape)) ||
        (err = unused(L, mesh ? NULL : rb->voxel_size, base, "voxel_size", shape)) ||
        (err = unused(L, mesh ? NULL : rb->band, base, "band", shape)) ||
        (err = unused(L, mesh ? NULL : rb->close_holes, base, "close_holes", shape)) ||
        (err = unused(L, mesh ? NULL : rb->interior, base, "interior", shape)))
        return err;
    if (mesh && (err = convert_mesh_body(L, rb, bi, s)))
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
    snprintf(p, sizeof p, "%s.collision_offset", base);
    if ((err = num(L, rb->collision_offset, bd->offset, NONNEG, p, &bd->offset)))
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
        (rc = s->frames > CS_MAX_FRAMES
                  ? fail(L, "time.frames", true, "must be at most %d", CS_MAX_FRAMES)
                  : CS_IMPORT_OK) ||
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
    L->self_collision = s->def.self_collision;
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
        s->mesh_bodies = calloc(r->bodies_count, sizeof *s->mesh_bodies);
        if (!s->body_colors || !s->def.bodies || !s->mesh_bodies)
            goto nomem;
        s->def.nbodies = (int)r->bodies_count;
        for (unsigned b = 0; b < r->bodies_count; b++)
            if ((rc = convert_body(L, &r->bodies[b], (int)b, s)))
                goto fail;
        if ((rc = finish_mesh_bodies(L, s)))
            goto fail;
    }
    if (r->levelset && r->levelset->cache && !*r->levelset->cache) {
        rc = fail(L, "levelset.cache", false, "must not be empty (none turns the cache off)");
        goto fail;
    }
    char *dir = scene_dir(L->file);
    if (!dir)
        goto nomem;
    s->levelset_cache = cs_levelset_cache_dir(r->levelset ? r->levelset->cache : NULL, dir);
    free(dir);
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
    for (int b = 0; s->mesh_bodies && b < s->def.nbodies; b++) {
        cs_scene_mesh_body *mb = &s->mesh_bodies[b];
        if (mb->sign_mesh != mb->mesh)
            cs_trimesh_destroy(mb->sign_mesh);
        cs_trimesh_destroy(mb->mesh);
        cs_levelset_destroy(mb->levelset);
        free(mb->file);
        free(mb->cache_path);
    }
    free(s->mesh_bodies);
    free(s->levelset_cache);
    for (int i = 0; i < s->nnotes; i++)
        free(s->notes[i]);
    free(s->notes);
    free(s->name);
    free(s->path);
    free(s->output_format);
    free(s->cloth_colors);
    free(s->body_colors);
    free(s);
}

/* ------------------------------------------------------------ level sets */

/* Makes (or reads from the cache) the grid of every mesh body and plugs it
 * into the body's phi. Only once the whole scene converted without error,
 * so nothing is converted for a scene that is then refused. */
static int build_levelsets(loader *L, cs_scene *s)
{
    for (int b = 0; s->mesh_bodies && b < s->def.nbodies; b++) {
        cs_scene_mesh_body *mb = &s->mesh_bodies[b];
        if (!mb->mesh)
            continue;
        char stem[128], who[128], why[512], p[64];
        snprintf(stem, sizeof stem, "%s", base_name(mb->file));
        char *dot = strrchr(stem, '.');
        if (dot && dot != stem)
            *dot = '\0';
        snprintf(who, sizeof who, "bodies[%d] '%.60s'", b, s->def.bodies[b].name);
        cs_levelset_request req = {
            .voxel_size = mb->voxel_size,
            .band = mb->band,
            .fill_interior = mb->fill_interior,
            .cache_dir = s->levelset_cache,
            .label = stem,
        };
        cs_levelset_result res;
        int rc = cs_levelset_build(mb->sign_mesh, &req, &res, why, sizeof why);
        if (rc != CS_IMPORT_OK) {
            snprintf(p, sizeof p, "bodies[%d].mesh", b);
            return rc == CS_IMPORT_NOMEM ? rc
                                         : fail(L, p, false, "cannot make its level set: %s", why);
        }
        mb->levelset = res.grid;
        mb->from_cache = res.from_cache;
        mb->seconds = res.seconds;
        if (res.cache_path[0] && !(mb->cache_path = dup_str(res.cache_path)))
            return CS_IMPORT_NOMEM;
        cs_levelset_info info;
        cs_levelset_get_info(mb->levelset, &info);
        cs_body_def *bd = (cs_body_def *)&s->def.bodies[b];
        bd->phi_fn = cs_levelset_phi;
        bd->phi_data = mb->levelset;
        bd->phi_bounded = true;
        memcpy(bd->phi_min, info.min, sizeof info.min);
        memcpy(bd->phi_max, info.max, sizeof info.max);
        char done[1200];
        if (res.from_cache)
            snprintf(done, sizeof done, "read from the cache %s in %.2f s", res.cache_path,
                     res.seconds);
        else if (res.cache_path[0])
            snprintf(done, sizeof done, "converted in %.2f s, cached as %s", res.seconds,
                     res.cache_path);
        else
            snprintf(done, sizeof done, "converted in %.2f s (not cached)", res.seconds);
        if (!add_note(s, "%s: level set %dx%dx%d voxels of %.3g m (band %g%s), %lld active, "
                         "%.1f MB; %s",
                      who, info.dim[0], info.dim[1], info.dim[2], info.voxel_size, mb->band,
                      mb->fill_interior ? ", interior filled" : "", info.active_voxels,
                      info.memory_bytes / 1e6, done))
            return CS_IMPORT_NOMEM;
        if (res.cache_note[0] && !add_note(s, "warning: %s: level-set cache: %s", who,
                                           res.cache_note))
            return CS_IMPORT_NOMEM;
    }
    return CS_IMPORT_OK;
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
    if (rc == CS_IMPORT_OK && (rc = build_levelsets(L, *out)) != CS_IMPORT_OK) {
        if (rc == CS_IMPORT_BAD_INPUT)
            report(L, L->noverrides > 0, err, errlen);
        cs_scene_destroy(*out);
        *out = NULL;
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
