/* scene_errors.c: placing a scene's errors, and libcyaml's stage.
 *
 * Every problem becomes one line naming the key path, placed at the key's
 * line in the file or at the --set override that made it. libcyaml's log is
 * captured and turned into "KEY.PATH: what was expected (got X)", the line
 * coming from the document rather than cyaml's backtrace, which points at
 * the enclosing node; number and boolean text is checked more strictly
 * than cyaml does.
 */
#include "import/scene_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cyaml/cyaml.h>
#include <yaml.h>

/* ------------------------------------------------------------ messages */

void cs_sl_set_err(char *err, size_t errlen, const char *fmt, ...)
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

int cs_sl_fail_at(loader *L, const cs_spath *p, bool with_got, const char *fmt, ...)
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
    return CS_ERR_BAD_INPUT;
}

int cs_sl_fail(loader *L, const char *path, bool with_got, const char *fmt, ...)
{
    cs_spath p;
    char msg[MSG_LEN];
    va_list ap;
    if (!cs_spath_parse(&p, path))
        p.n = 0;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cs_sl_fail_at(L, &p, with_got, "%s", msg);
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

int cs_sl_report(loader *L, bool blame, char *err, size_t errlen)
{
    char path[PATH_LEN];
    cs_sloc loc;
    cs_spath_format(&L->err_path, path, sizeof path);
    cs_sdoc_locate(&L->doc, &L->err_path, L->err_second, &loc);
    int k = L->noverrides > 0 ? loc.owner : -1;
    if (k < 0 && blame && L->noverrides > 0)
        k = blame_override(L);
    if (k >= 0)
        cs_sl_set_err(err, errlen, "--set %s: %s%s%s", L->overrides[k], path, *path ? ": " : "",
                      L->err_msg);
    else
        cs_sl_set_err(err, errlen, "%s:%d: %s%s%s", L->file, loc.line, path, *path ? ": " : "",
                      L->err_msg);
    return CS_ERR_BAD_INPUT;
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
        L->log_len +=
            (size_t)w < sizeof L->log - L->log_len ? (size_t)w : sizeof L->log - L->log_len - 1;
}

static bool starts(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* Expected-versus-found for a value of the wrong kind at p. */
int cs_sl_fail_type(loader *L, const cs_spath *p)
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
        return cs_sl_fail_at(L, p, false, "expected a mapping of scene keys (got %s)", got);
    return cs_sl_fail_at(L, p, false, "expected %s (got %s)", want, got);
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
        return cs_sl_fail_at(L, &p, false, "%s", cyaml_strerror(e));
    if (starts(what, "Unexpected key: ")) {
        const char *k = what + strlen("Unexpected key: ");
        const char *near = cs_scene_nearest_key(cs_scene_schema_at(&p), k);
        cs_spath_push_key(&p, k, strlen(k));
        if (near)
            return cs_sl_fail_at(L, &p, false, "unknown key; did you mean %s?", near);
        return cs_sl_fail_at(L, &p, false, "unknown key");
    }
    if (missing) {
        const char *k = what + strlen("Missing required mapping field: ");
        cs_spath_push_key(&p, k, strlen(k));
        return cs_sl_fail_at(L, &p, false, "required key is missing");
    }
    if (starts(what, "Mapping field already seen: ")) {
        cs_sl_fail_at(L, &p, false, "duplicate key");
        L->err_second = true;
        return CS_ERR_BAD_INPUT;
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
            return cs_sl_fail_at(L, &p, false, "expected %s (got a list of %ld)", want, have);
        }
        if (v && starts(what, "Insufficient"))
            return cs_sl_fail_at(L, &p, false, "expected at least %u %s (got %ld)",
                                 (unsigned)v->sequence.min,
                                 v->sequence.min == 1 ? "entry" : "entries", have);
        if (v)
            return cs_sl_fail_at(L, &p, false, "expected at most %u entries (got %ld)",
                                 (unsigned)v->sequence.max, have);
    }
    if (starts(what, "Invalid ") || starts(what, "Expecting "))
        return cs_sl_fail_type(L, &p);
    return cs_sl_fail_at(L, &p, false, "%s", what);
}

/* Number and boolean text, stricter than cyaml: whole text, finite, and
 * booleans that cyaml reads the way they look. */
int cs_sl_check_scalar(loader *L, const yaml_node_t *n, const cyaml_schema_value_t *v,
                       const cs_spath *p)
{
    const char *s = (const char *)n->data.scalar.value;
    char *end;
    switch (v->type) {
    case CYAML_FLOAT: {
        errno = 0;
        double x = strtod(s, &end);
        if (!*s || isspace((unsigned char)*s) || *end)
            return cs_sl_fail_at(L, p, true, "expected a number");
        if (!isfinite(x))
            return cs_sl_fail_at(L, p, true, "expected a finite number");
        return CS_OK;
    }
    case CYAML_INT: {
        const char *d = s + (*s == '-' || *s == '+');
        bool digits = *d != '\0';
        for (const char *c = d; *c; c++)
            digits = digits && isdigit((unsigned char)*c);
        if (!digits)
            return cs_sl_fail_at(L, p, true, "expected an integer");
        /* cyaml reads "010" as octal 8. */
        if (d[0] == '0' && d[1] != '\0')
            return cs_sl_fail_at(L, p, true, "expected an integer without leading zeros");
        return CS_OK;
    }
    case CYAML_BOOL:
        /* cyaml takes anything but false/no/disable/0 as true ("off" too). */
        if (strcasecmp(s, "true") && strcasecmp(s, "false") && strcasecmp(s, "yes") &&
            strcasecmp(s, "no"))
            return cs_sl_fail_at(L, p, true, "expected true or false");
        return CS_OK;
    default: return CS_OK;
    }
}

static int check_scalars(loader *L, int id, const cyaml_schema_value_t *v, cs_spath *p)
{
    const yaml_node_t *n = yaml_document_get_node(&L->doc.doc, id);
    int rc = CS_OK;
    if (!n || !v)
        return CS_OK;
    if (n->type == YAML_SCALAR_NODE)
        return cs_sl_check_scalar(L, n, v, p);
    if (n->type == YAML_MAPPING_NODE && v->type == CYAML_MAPPING) {
        long npairs = n->data.mapping.pairs.top - n->data.mapping.pairs.start;
        for (long i = 0; rc == CS_OK && i < npairs; i++) {
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
        for (long i = 0; rc == CS_OK && i < nitems; i++) {
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

/* Stage 2 on text whose document is L->doc. */
int cs_sl_load_raw(loader *L, const char *text, size_t len, cs_raw_scene **raw)
{
    cyaml_config_t cfg;
    cs_spath p = {0};
    L->log_len = 0;
    L->log[0] = '\0';
    cyaml_err_t e = cyaml_load_data((const uint8_t *)text, len, cyaml_config_for(L, &cfg),
                                    &cs_scene_schema, (cyaml_data_t **)raw, NULL);
    if (e == CYAML_ERR_OOM)
        return CS_ERR_NOMEM;
    if (e != CYAML_OK)
        return translate_cyaml(L, e);
    if (!*raw)
        return cs_sl_fail_type(L, &p);
    return check_scalars(L, cs_sdoc_root(&L->doc), &cs_scene_schema, &p);
}

void cs_sl_free_raw(loader *L, cs_raw_scene *raw)
{
    cyaml_config_t cfg;
    if (raw)
        cyaml_free(cyaml_config_for(L, &cfg), &cs_scene_schema, raw, 0);
}

void cs_sl_free_value(loader *L, const cyaml_schema_value_t *v, void *data, unsigned count)
{
    cyaml_config_t cfg;
    cyaml_free(cyaml_config_for(L, &cfg), v, data, count);
}
