/* scene_set.c: --set overrides applied to the parsed scene.
 *
 * An override's value is parsed once, into the scene's document
 * (cs_sdoc_set: there its nodes name the override in messages and keep
 * their text for "(got X)"); from there it goes into the raw structs
 * through the row of scene_keys.def the key has, as the file's own keys
 * come from libcyaml: the same types, the same strict number and boolean
 * text (cs_sl_check_scalar), the same messages; the conversion that
 * follows checks the range and sets defaults for both alike. The member of
 * the innermost section on the path is replaced whole (a list by every
 * entry, a vector by every number), so an override naming an entry or a
 * number of it takes the rest from the document.
 */
#include "import/scene_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <yaml.h>

static const yaml_node_t *node(const loader *L, int id)
{
    return yaml_document_get_node((yaml_document_t *)&L->doc.doc, id);
}

static long items(const yaml_node_t *n)
{
    return n->type == YAML_SEQUENCE_NODE ? n->data.sequence.items.top - n->data.sequence.items.start
                                         : -1;
}

/* The row of sec named key, or NULL. */
static const cs_scene_key *row(int sec, const char *key)
{
    for (int i = 0; i < CS_KEY_COUNT; i++)
        if (cs_scene_keys[i].section == sec && !strcmp(cs_scene_keys[i].key, key))
            return &cs_scene_keys[i];
    return NULL;
}

/* The libcyaml field of k: what frees its value. */
static const cyaml_schema_field_t *field(const cs_scene_key *k)
{
    const cyaml_schema_field_t *f = cs_scene_sections[k->section].fields;
    while (f->key && strcmp(f->key, k->key) != 0)
        f++;
    return f->key ? f : NULL;
}

static int fail_node(loader *L, const cs_spath *p)
{
    return cs_sl_fail_type(L, p);
}

/* One scalar of type t (CS_KT_NUM, INT, BOOL) at node id into out. */
static int scalar_value(loader *L, int id, cs_key_type t, const cs_spath *p, void *out)
{
    static const cyaml_schema_value_t num = {CYAML_VALUE_FLOAT(CYAML_FLAG_DEFAULT, double)};
    static const cyaml_schema_value_t in = {CYAML_VALUE_INT(CYAML_FLAG_DEFAULT, int)};
    static const cyaml_schema_value_t bo = {CYAML_VALUE_BOOL(CYAML_FLAG_DEFAULT, bool)};
    const yaml_node_t *n = node(L, id);
    if (!n || n->type != YAML_SCALAR_NODE)
        return fail_node(L, p);
    int rc = cs_sl_check_scalar(L, n, t == CS_KT_NUM ? &num : t == CS_KT_INT ? &in : &bo, p);
    if (rc)
        return rc;
    const char *s = (const char *)n->data.scalar.value;
    if (t == CS_KT_NUM)
        *(double *)out = strtod(s, NULL);
    else if (t == CS_KT_INT) {
        long v = strtol(s, NULL, 10);
        if (v < -2147483647L || v > 2147483647L)
            return cs_sl_fail_at(L, p, true, "expected an integer of at most 10 digits");
        *(int *)out = (int)v;
    } else
        *(bool *)out = !strcasecmp(s, "true") || !strcasecmp(s, "yes");
    return CS_OK;
}

/* A sequence of n scalars (n < 0: any number, counted in *count) of type
 * t, each of size bytes, as one malloc'd array. */
static int scalars(loader *L, int id, cs_key_type t, int n, size_t size, cs_spath *p, void **out,
                   unsigned *count)
{
    const yaml_node_t *s = node(L, id);
    if (!s || s->type != YAML_SEQUENCE_NODE)
        return fail_node(L, p);
    long have = items(s);
    if (n >= 0 && have != n) {
        char want[160];
        cs_scene_schema_describe(cs_scene_schema_at(p), want, sizeof want);
        return cs_sl_fail_at(L, p, false, "expected %s (got a list of %ld)", want, have);
    }
    char *a = calloc((size_t)have + 1, size);
    if (!a)
        return CS_ERR_NOMEM;
    *out = a;
    for (long i = 0; i < have; i++) {
        cs_spath_push_index(p, i);
        int rc = scalar_value(L, s->data.sequence.items.start[i], t, p, a + (size_t)i * size);
        p->n--;
        if (rc)
            return rc;
    }
    if (count)
        *count = (unsigned)have;
    return CS_OK;
}

static int section(loader *L, int sec, int id, cs_spath *p, void *raw);

/* Key k of a section from node id into raw (NULL members only). */
static int member(loader *L, const cs_scene_key *k, int id, cs_spath *p, void *raw)
{
    char *m = (char *)raw + k->raw;
    unsigned *count = k->count ? (unsigned *)((char *)raw + k->count) : NULL;
    const yaml_node_t *n = node(L, id);
    bool inline_value = k->required && (k->type == CS_KT_NUM || k->type == CS_KT_ENUM);
    void *v = NULL;
    int rc = CS_OK;
    switch (k->type) {
    case CS_KT_NUM:
    case CS_KT_INT:
    case CS_KT_BOOL: {
        size_t size = k->type == CS_KT_NUM ? sizeof(double) : k->type == CS_KT_INT ? sizeof(int)
                                                                                   : sizeof(bool);
        if (inline_value)
            return scalar_value(L, id, k->type, p, m);
        if (!(v = calloc(1, size)))
            return CS_ERR_NOMEM;
        rc = scalar_value(L, id, k->type, p, v);
        break;
    }
    case CS_KT_STR:
    case CS_KT_DT:
        if (!n || n->type != YAML_SCALAR_NODE)
            return fail_node(L, p);
        if (!(v = cs_sl_strdup((const char *)n->data.scalar.value)))
            return CS_ERR_NOMEM;
        break;
    case CS_KT_ENUM: {
        unsigned i = 0;
        while (n && n->type == YAML_SCALAR_NODE && i < k->nnames &&
               strcmp(k->names[i].str, (const char *)n->data.scalar.value) != 0)
            i++;
        if (!n || n->type != YAML_SCALAR_NODE || i == k->nnames)
            return fail_node(L, p);
        if (inline_value) {
            *(int *)m = (int)k->names[i].val;
            return CS_OK;
        }
        if (!(v = malloc(sizeof(int))))
            return CS_ERR_NOMEM;
        *(int *)v = (int)k->names[i].val;
        break;
    }
    case CS_KT_VEC:
    case CS_KT_IVEC:
        rc = scalars(L, id, k->type == CS_KT_VEC ? CS_KT_NUM : CS_KT_INT, k->n,
                     k->type == CS_KT_VEC ? sizeof(double) : sizeof(int), p, &v, NULL);
        break;
    case CS_KT_IDXLIST: rc = scalars(L, id, CS_KT_INT, -1, sizeof(int), p, &v, count); break;
    case CS_KT_SCALE: return CS_OK; /* read from the document */
    case CS_KT_MAP:
        if (!(v = calloc(1, cs_scene_sections[k->child].size)))
            return CS_ERR_NOMEM;
        rc = section(L, k->child, id, p, v);
        break;
    case CS_KT_LIST:
    case CS_KT_VLIST:
    case CS_KT_ILIST: {
        if (!n || n->type != YAML_SEQUENCE_NODE)
            return fail_node(L, p);
        long have = items(n);
        if (have < (long)k->range.lo && k->type == CS_KT_LIST)
            return cs_sl_fail_at(L, p, false, "expected at least %d %s (got %ld)", (int)k->range.lo,
                                 k->range.lo == 1 ? "entry" : "entries", have);
        size_t size = k->type == CS_KT_LIST ? cs_scene_sections[k->child].size
                      : (size_t)k->n * (k->type == CS_KT_VLIST ? sizeof(double) : sizeof(int));
        char *a = calloc((size_t)have + 1, size);
        if (!a)
            return CS_ERR_NOMEM;
        v = a;
        *(void **)m = v;
        *count = (unsigned)have; /* what is filled is freed with it */
        for (long i = 0; rc == CS_OK && i < have; i++) {
            cs_spath_push_index(p, i);
            int e = n->data.sequence.items.start[i];
            void *entry = NULL;
            if (k->type == CS_KT_LIST)
                rc = section(L, k->child, e, p, a + (size_t)i * size);
            else if ((rc = scalars(L, e, k->type == CS_KT_VLIST ? CS_KT_NUM : CS_KT_INT, k->n,
                                   size / (size_t)k->n, p, &entry, NULL)) == CS_OK)
                memcpy(a + (size_t)i * size, entry, size);
            free(entry);
            p->n--;
            n = node(L, id);
        }
        return rc;
    }
    }
    *(void **)m = v; /* freed with raw, also when it failed half-way */
    return rc;
}

/* The mapping at node id into raw, a zeroed cs_raw_<sec>. */
static int section(loader *L, int sec, int id, cs_spath *p, void *raw)
{
    const yaml_node_t *n = node(L, id);
    if (!n || n->type != YAML_MAPPING_NODE)
        return fail_node(L, p);
    long npairs = n->data.mapping.pairs.top - n->data.mapping.pairs.start;
    bool seen[CS_KEY_COUNT] = {false};
    for (long i = 0; i < npairs; i++) {
        n = node(L, id);
        yaml_node_pair_t pair = n->data.mapping.pairs.start[i];
        const yaml_node_t *kn = node(L, pair.key);
        const char *name = kn && kn->type == YAML_SCALAR_NODE ? (const char *)kn->data.scalar.value
                                                              : "";
        const cs_scene_key *k = row(sec, name);
        cs_spath_push_key(p, name, strlen(name));
        if (!k) {
            p->n--;
            const char *near = cs_scene_nearest_key(cs_scene_schema_at(p), name);
            cs_spath_push_key(p, name, strlen(name));
            return near ? cs_sl_fail_at(L, p, false, "unknown key; did you mean %s?", near)
                        : cs_sl_fail_at(L, p, false, "unknown key");
        }
        if (seen[k - cs_scene_keys]) {
            cs_sl_fail_at(L, p, false, "duplicate key");
            L->err_second = true;
            return CS_ERR_BAD_INPUT;
        }
        seen[k - cs_scene_keys] = true;
        int rc = member(L, k, pair.value, p, raw);
        p->n--;
        if (rc)
            return rc;
    }
    for (int i = 0; i < CS_KEY_COUNT; i++)
        if (cs_scene_keys[i].section == sec && cs_scene_keys[i].required && !seen[i]) {
            cs_spath_push_key(p, cs_scene_keys[i].key, strlen(cs_scene_keys[i].key));
            return cs_sl_fail_at(L, p, false, "required key is missing");
        }
    return CS_OK;
}

/* Frees what raw's member k holds, and clears it. */
static void clear(loader *L, const cs_scene_key *k, void *raw)
{
    char *m = (char *)raw + k->raw;
    const cyaml_schema_field_t *f = field(k);
    if (k->type == CS_KT_SCALE || (k->required && (k->type == CS_KT_NUM || k->type == CS_KT_ENUM)))
        return;
    unsigned *count = k->count ? (unsigned *)((char *)raw + k->count) : NULL;
    if (f && *(void **)m)
        cs_sl_free_value(L, &f->value, *(void **)m, count ? *count : 0);
    *(void **)m = NULL;
    if (count)
        *count = 0;
}

/* A component of a path as a list index, or -1. */
static long index_of(const cs_spath *p, int i)
{
    if (p->c[i].index >= 0)
        return p->c[i].index;
    return cs_all_digits(p->c[i].key) ? strtol(p->c[i].key, NULL, 10) : -1;
}

int cs_sl_apply_override(loader *L, cs_raw_scene *raw, const cs_spath *p)
{
    int sec = CS_SEC_scene;
    void *cur = raw;
    cs_spath at = {0};
    for (int i = 0; i < p->n; i++) {
        const char *key = p->c[i].key;
        const cs_scene_key *k = p->c[i].index < 0 ? row(sec, key) : NULL;
        cs_spath_push_key(&at, key, strlen(key));
        if (!k) {
            at.n--;
            const char *near = cs_scene_nearest_key(cs_scene_schema_at(&at), key);
            cs_spath_push_key(&at, key, strlen(key));
            return near ? cs_sl_fail_at(L, &at, false, "unknown key; did you mean %s?", near)
                        : cs_sl_fail_at(L, &at, false, "unknown key");
        }
        bool into_map = k->type == CS_KT_MAP && i + 1 < p->n;
        bool into_entry = k->type == CS_KT_LIST && i + 2 < p->n;
        if (!into_map && !into_entry) {
            /* the member whole, from the document, which holds the override */
            cs_sloc loc;
            cs_sdoc_locate(&L->doc, &at, false, &loc);
            clear(L, k, cur);
            return loc.matched == at.n ? member(L, k, loc.node, &at, cur) : CS_OK;
        }
        void **child = (void **)((char *)cur + k->raw);
        if (into_map) {
            if (!*child && !(*child = calloc(1, cs_scene_sections[k->child].size)))
                return CS_ERR_NOMEM;
            cur = *child;
        } else {
            long j = index_of(p, ++i); /* in range: the document has the entry */
            cs_spath_push_index(&at, j);
            cur = (char *)*child + (size_t)j * cs_scene_sections[k->child].size;
        }
        sec = k->child;
    }
    return CS_OK;
}

/* A mapping an override made has every required key, once all are applied
 * (camera.position, then camera.target). */
int cs_sl_check_required(loader *L, int sec, const void *raw, cs_spath *p)
{
    for (int i = 0; i < CS_KEY_COUNT; i++) {
        const cs_scene_key *k = &cs_scene_keys[i];
        if (k->section != sec || k->type == CS_KT_SCALE ||
            (k->required && (k->type == CS_KT_NUM || k->type == CS_KT_ENUM)))
            continue;
        const void *v = *(const void *const *)((const char *)raw + k->raw);
        cs_spath_push_key(p, k->key, strlen(k->key));
        int rc = CS_OK;
        if (!v && k->required)
            rc = cs_sl_fail_at(L, p, false, "required key is missing");
        else if (v && k->type == CS_KT_MAP)
            rc = cs_sl_check_required(L, k->child, v, p);
        for (unsigned j = 0; v && k->type == CS_KT_LIST && !rc &&
                             j < *(const unsigned *)((const char *)raw + k->count);
             j++) {
            cs_spath_push_index(p, j);
            rc = cs_sl_check_required(L, k->child,
                                      (const char *)v + j * cs_scene_sections[k->child].size, p);
            p->n--;
        }
        p->n--;
        if (rc)
            return rc;
    }
    return CS_OK;
}
