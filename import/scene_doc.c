/* scene_doc.c: the scene text as a libyaml document: locating key paths,
 * applying --set overrides, emitting the result. */
#include "import/scene_doc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Nesting and size limits for the recursive walks over user-controlled
 * structure (override values, alias expansion when emitting). */
#define MAX_DEPTH 256
#define MAX_EMIT_NODES (1L << 22)

static yaml_node_t *node_at(const cs_sdoc *d, int id)
{
    return id > 0 ? yaml_document_get_node((yaml_document_t *)&d->doc, id) : NULL;
}

static int node_count(const cs_sdoc *d)
{
    return (int)(d->doc.nodes.top - d->doc.nodes.start);
}

static int owner_of(const cs_sdoc *d, int id)
{
    return id > 0 && (size_t)id <= d->owner_len ? d->owner[id - 1] : -1;
}

/* Grows the owner table to cover every node, new entries unowned. */
static int owner_sync(cs_sdoc *d)
{
    size_t n = (size_t)node_count(d);
    if (n <= d->owner_len)
        return CS_SDOC_OK;
    int *o = realloc(d->owner, n * sizeof *o);
    if (!o)
        return CS_SDOC_NOMEM;
    for (size_t i = d->owner_len; i < n; i++)
        o[i] = -1;
    d->owner = o;
    d->owner_len = n;
    return CS_SDOC_OK;
}

static int parser_error(const yaml_parser_t *parser, const char *text, size_t len, int *line,
                        char *msg, size_t msglen)
{
    if (parser->error == YAML_MEMORY_ERROR)
        return CS_SDOC_NOMEM;
    if (parser->error == YAML_READER_ERROR) {
        /* Encoding errors carry a byte offset, not a mark. */
        int l = 1;
        for (size_t i = 0; i < parser->problem_offset && i < len; i++)
            l += text[i] == '\n';
        *line = l;
        snprintf(msg, msglen, "cannot read the text: %s",
                 parser->problem ? parser->problem : "invalid encoding");
        return CS_SDOC_BAD;
    }
    *line = (int)parser->problem_mark.line + 1;
    if (parser->context)
        snprintf(msg, msglen, "YAML syntax error: %s (%s at line %d)",
                 parser->problem ? parser->problem : "unknown problem", parser->context,
                 (int)parser->context_mark.line + 1);
    else
        snprintf(msg, msglen, "YAML syntax error: %s",
                 parser->problem ? parser->problem : "unknown problem");
    return CS_SDOC_BAD;
}

/* YAML allows a list or a mapping as a key ("? [a, b]"); a scene's keys
 * are names, and libcyaml answers such a key with "Internal error". */
static int plain_keys(const cs_sdoc *d, int *line, char *msg, size_t msglen)
{
    for (yaml_node_t *n = d->doc.nodes.start; n < d->doc.nodes.top; n++) {
        if (n->type != YAML_MAPPING_NODE)
            continue;
        for (yaml_node_pair_t *p = n->data.mapping.pairs.start; p < n->data.mapping.pairs.top;
             p++) {
            const yaml_node_t *k = yaml_document_get_node((yaml_document_t *)&d->doc, p->key);
            if (k && k->type != YAML_SCALAR_NODE) {
                *line = (int)k->start_mark.line + 1;
                snprintf(msg, msglen, "a key must be a plain name (got a %s)",
                         k->type == YAML_SEQUENCE_NODE ? "list" : "mapping");
                return CS_SDOC_BAD;
            }
        }
    }
    return CS_SDOC_OK;
}

int cs_sdoc_load(cs_sdoc *d, const char *text, size_t len, int *line, char *msg, size_t msglen)
{
    yaml_parser_t parser;
    int rc = CS_SDOC_OK;

    memset(d, 0, sizeof *d);
    if (!yaml_parser_initialize(&parser))
        return CS_SDOC_NOMEM;
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, len);
    if (!yaml_parser_load(&parser, &d->doc)) {
        rc = parser_error(&parser, text, len, line, msg, msglen);
        yaml_parser_delete(&parser);
        return rc;
    }
    d->loaded = true;

    /* cyaml reads only the first document; a second one is a mistake. */
    yaml_document_t extra;
    if (!yaml_parser_load(&parser, &extra)) {
        rc = parser_error(&parser, text, len, line, msg, msglen);
    } else {
        if (yaml_document_get_root_node(&extra)) {
            *line = (int)extra.start_mark.line + 1;
            snprintf(msg, msglen, "only one YAML document is allowed");
            rc = CS_SDOC_BAD;
        }
        yaml_document_delete(&extra);
    }
    yaml_parser_delete(&parser);
    if (rc == CS_SDOC_OK)
        rc = plain_keys(d, line, msg, msglen);
    if (rc == CS_SDOC_OK)
        rc = owner_sync(d);
    if (rc != CS_SDOC_OK)
        cs_sdoc_free(d);
    return rc;
}

void cs_sdoc_free(cs_sdoc *d)
{
    if (d->loaded)
        yaml_document_delete(&d->doc);
    free(d->owner);
    memset(d, 0, sizeof *d);
}

static bool is_null_scalar(const yaml_node_t *n)
{
    if (n->type != YAML_SCALAR_NODE || n->data.scalar.style != YAML_PLAIN_SCALAR_STYLE)
        return false;
    const char *v = (const char *)n->data.scalar.value;
    return !strcmp(v, "") || !strcmp(v, "~") || !strcmp(v, "null") || !strcmp(v, "Null") ||
           !strcmp(v, "NULL");
}

int cs_sdoc_root(const cs_sdoc *d)
{
    if (!d->loaded)
        return 0;
    const yaml_node_t *root = node_at(d, 1);
    if (!root || is_null_scalar(root))
        return 0;
    return 1;
}

/* The sequence index a path component names, or -1. */
static long component_index(const cs_spath *p, int i)
{
    if (p->c[i].index >= 0)
        return p->c[i].index;
    if (cs_all_digits(p->c[i].key) && strlen(p->c[i].key) < 10)
        return strtol(p->c[i].key, NULL, 10);
    return -1;
}

static bool key_is(const yaml_node_t *k, const char *key)
{
    size_t n = strlen(key);
    if (!k || k->type != YAML_SCALAR_NODE)
        return false;
    /* A key cut to fit a path component matches by its start. */
    if (n == CS_SPATH_KEY - 1 ? k->data.scalar.length < n : k->data.scalar.length != n)
        return false;
    return memcmp(k->data.scalar.value, key, n) == 0;
}

/* The pair of mapping m whose key is `key` (skip matches skipped), or NULL. */
static yaml_node_pair_t *find_pair(const cs_sdoc *d, const yaml_node_t *m, const char *key,
                                   int skip)
{
    for (yaml_node_pair_t *pair = m->data.mapping.pairs.start; pair < m->data.mapping.pairs.top;
         pair++) {
        if (key_is(node_at(d, pair->key), key) && skip-- == 0)
            return pair;
    }
    return NULL;
}

void cs_sdoc_locate(const cs_sdoc *d, const cs_spath *p, bool second, cs_sloc *out)
{
    out->line = 1;
    out->matched = 0;
    out->node = 0;
    out->owner = -1;
    if (!d->loaded || !node_at(d, 1))
        return;
    int cur = 1;
    const yaml_node_t *n = node_at(d, cur);
    out->line = (int)n->start_mark.line + 1;
    out->node = cur;
    out->owner = owner_of(d, cur);
    for (int i = 0; i < p->n; i++) {
        n = node_at(d, cur);
        int line, owner;
        if (n->type == YAML_MAPPING_NODE && p->c[i].index < 0) {
            const yaml_node_pair_t *pair =
                find_pair(d, n, p->c[i].key, second && i == p->n - 1 ? 1 : 0);
            if (!pair)
                break;
            line = (int)node_at(d, pair->key)->start_mark.line + 1;
            owner = owner_of(d, pair->key);
            if (owner_of(d, pair->value) >= 0)
                owner = owner_of(d, pair->value);
            cur = pair->value;
        } else if (n->type == YAML_SEQUENCE_NODE) {
            long index = component_index(p, i);
            long count = n->data.sequence.items.top - n->data.sequence.items.start;
            if (index < 0 || index >= count)
                break;
            cur = n->data.sequence.items.start[index];
            line = (int)node_at(d, cur)->start_mark.line + 1;
            owner = owner_of(d, cur);
        } else {
            break;
        }
        out->line = line;
        if (owner >= 0)
            out->owner = owner;
        out->matched = i + 1;
        out->node = cur;
    }
}

void cs_sdoc_describe(const cs_sdoc *d, int node, char *buf, size_t len)
{
    const yaml_node_t *n = node_at(d, node);
    if (!n) {
        snprintf(buf, len, "nothing");
    } else if (n->type == YAML_MAPPING_NODE) {
        snprintf(buf, len, "a mapping");
    } else if (n->type == YAML_SEQUENCE_NODE) {
        snprintf(buf, len, "a list");
    } else if (is_null_scalar(n)) {
        snprintf(buf, len, "%s", n->data.scalar.length ? (const char *)n->data.scalar.value
                                                        : "nothing");
    } else if (n->data.scalar.length == 0) {
        snprintf(buf, len, "\"\"");
    } else {
        /* Long values are cut: the message has to stay one readable line. */
        int w = n->data.scalar.length > 40 ? 40 : (int)n->data.scalar.length;
        snprintf(buf, len, "%.*s%s", w, (const char *)n->data.scalar.value,
                 n->data.scalar.length > 40 ? "..." : "");
    }
}

/* ------------------------------------------------------------ overrides */

/* Copies node id of src into d, recursively; new nodes are owned by k. */
static int copy_node(cs_sdoc *d, yaml_document_t *src, int id, int k, int depth, long *budget,
                     int *out)
{
    yaml_node_t *n = yaml_document_get_node(src, id);
    int copy = 0, rc;
    if (depth > MAX_DEPTH || --*budget < 0)
        return CS_SDOC_BAD;
    switch (n->type) {
    case YAML_SCALAR_NODE:
        copy = yaml_document_add_scalar(&d->doc, NULL, n->data.scalar.value,
                                        (int)n->data.scalar.length, n->data.scalar.style);
        break;
    case YAML_SEQUENCE_NODE:
        copy = yaml_document_add_sequence(&d->doc, NULL, n->data.sequence.style);
        for (int i = 0; copy && i < n->data.sequence.items.top - n->data.sequence.items.start;
             i++) {
            int item;
            if ((rc = copy_node(d, src, n->data.sequence.items.start[i], k, depth + 1, budget,
                                &item)) != CS_SDOC_OK)
                return rc;
            if (!yaml_document_append_sequence_item(&d->doc, copy, item))
                return CS_SDOC_NOMEM;
        }
        break;
    case YAML_MAPPING_NODE:
        copy = yaml_document_add_mapping(&d->doc, NULL, n->data.mapping.style);
        for (int i = 0; copy && i < n->data.mapping.pairs.top - n->data.mapping.pairs.start;
             i++) {
            int key, value;
            yaml_node_pair_t pair = n->data.mapping.pairs.start[i];
            if ((rc = copy_node(d, src, pair.key, k, depth + 1, budget, &key)) != CS_SDOC_OK ||
                (rc = copy_node(d, src, pair.value, k, depth + 1, budget, &value)) != CS_SDOC_OK)
                return rc;
            if (!yaml_document_append_mapping_pair(&d->doc, copy, key, value))
                return CS_SDOC_NOMEM;
        }
        break;
    default:
        return CS_SDOC_BAD;
    }
    if (!copy || owner_sync(d) != CS_SDOC_OK)
        return CS_SDOC_NOMEM;
    d->owner[copy - 1] = k;
    *out = copy;
    return CS_SDOC_OK;
}

/* Parses value as a YAML document and copies it into d as a new node. */
static int add_value(cs_sdoc *d, const char *value, int k, int *out, char *msg, size_t msglen)
{
    yaml_parser_t parser;
    yaml_document_t vdoc;
    int rc;
    if (!yaml_parser_initialize(&parser))
        return CS_SDOC_NOMEM;
    yaml_parser_set_input_string(&parser, (const unsigned char *)value, strlen(value));
    if (!yaml_parser_load(&parser, &vdoc)) {
        if (parser.error == YAML_MEMORY_ERROR) {
            rc = CS_SDOC_NOMEM;
        } else {
            snprintf(msg, msglen, "the value is not valid YAML: %s",
                     parser.problem ? parser.problem : "syntax error");
            rc = CS_SDOC_BAD;
        }
        yaml_parser_delete(&parser);
        return rc;
    }
    yaml_parser_delete(&parser);
    if (!yaml_document_get_root_node(&vdoc)) {
        /* "key=" sets null, which the schema then rejects with a message. */
        *out = yaml_document_add_scalar(&d->doc, NULL, (yaml_char_t *)"", 0,
                                        YAML_PLAIN_SCALAR_STYLE);
        rc = *out && owner_sync(d) == CS_SDOC_OK ? CS_SDOC_OK : CS_SDOC_NOMEM;
        if (rc == CS_SDOC_OK)
            d->owner[*out - 1] = k;
    } else {
        long budget = 1L << 16;
        rc = copy_node(d, &vdoc, 1, k, 0, &budget, out);
        if (rc == CS_SDOC_BAD)
            snprintf(msg, msglen, "the value is too large or too deeply nested");
    }
    yaml_document_delete(&vdoc);
    return rc;
}

/* A new node owned by k: a plain scalar key, or an empty block mapping. */
static int add_owned(cs_sdoc *d, const char *key, int k)
{
    int id = key ? yaml_document_add_scalar(&d->doc, NULL, (yaml_char_t *)key, -1,
                                            YAML_PLAIN_SCALAR_STYLE)
                 : yaml_document_add_mapping(&d->doc, NULL, YAML_BLOCK_MAPPING_STYLE);
    if (!id || owner_sync(d) != CS_SDOC_OK)
        return 0;
    d->owner[id - 1] = k;
    return id;
}

int cs_sdoc_set(cs_sdoc *d, const cs_spath *p, const char *value, int k, char *msg, size_t msglen)
{
    char where[512];
    cs_spath prefix = {0};
    int cur = 1, rc, newval = 0;

    if (!d->loaded || !node_at(d, 1) || p->n == 0) {
        snprintf(msg, msglen, "nothing to set");
        return CS_SDOC_BAD;
    }
    /* Adding nodes may move the node array, so node pointers below are
     * fetched afresh in each step and not kept across an addition. */
    if ((rc = add_value(d, value, k, &newval, msg, msglen)) != CS_SDOC_OK)
        return rc;

    for (int i = 0; i < p->n; i++) {
        bool last = i == p->n - 1;
        yaml_node_t *n = node_at(d, cur);
        cs_spath_format(&prefix, where, sizeof where);
        if (n->type == YAML_MAPPING_NODE) {
            if (p->c[i].index >= 0) {
                snprintf(msg, msglen, "%s is a mapping, not a list: [%ld] names no key",
                         prefix.n ? where : "the scene", p->c[i].index);
                return CS_SDOC_BAD;
            }
            yaml_node_pair_t *pair = find_pair(d, n, p->c[i].key, 0);
            if (pair) {
                if (last)
                    pair->value = newval;
                else
                    cur = pair->value;
            } else {
                int key = add_owned(d, p->c[i].key, k);
                int val = last ? newval : add_owned(d, NULL, k);
                if (!key || !val || !yaml_document_append_mapping_pair(&d->doc, cur, key, val))
                    return CS_SDOC_NOMEM;
                cur = val;
            }
            cs_spath_push_key(&prefix, p->c[i].key, strlen(p->c[i].key));
        } else if (n->type == YAML_SEQUENCE_NODE) {
            long index = component_index(p, i);
            long count = n->data.sequence.items.top - n->data.sequence.items.start;
            if (index < 0) {
                snprintf(msg, msglen, "%s is a list: '%s' is not an index", where, p->c[i].key);
                return CS_SDOC_BAD;
            }
            if (index >= count) {
                snprintf(msg, msglen, "index %ld is past the end of %s (%ld %s)", index, where,
                         count, count == 1 ? "entry" : "entries");
                return CS_SDOC_BAD;
            }
            if (last)
                n->data.sequence.items.start[index] = newval;
            else
                cur = n->data.sequence.items.start[index];
            cs_spath_push_index(&prefix, index);
        } else {
            snprintf(msg, msglen, "%s is a single value, it has no keys or entries", where);
            return CS_SDOC_BAD;
        }
    }
    return CS_SDOC_OK;
}
