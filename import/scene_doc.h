/* scene_doc.h: private to the scene loader.
 *
 * The scene text as a libyaml document (yaml_parser_load), used beside
 * libcyaml for what cyaml does not tell: the line of a key path, the text
 * of the value found there, and --set overrides, whose values are parsed
 * into the document (from where scene_set.c takes them into the raw
 * structs). Nodes added by an override remember which one (owner), so that
 * a later error in them names the override instead of a file line.
 */
#ifndef CS_SCENE_DOC_H
#define CS_SCENE_DOC_H

#include <stdbool.h>
#include <stddef.h>

#include <yaml.h>

#include "import/scene_schema.h"

typedef struct cs_sdoc {
    yaml_document_t doc;
    bool loaded;
    int *owner;          /* per node id (1-based): override index or -1 */
    size_t owner_len;
} cs_sdoc;

enum {
    CS_SDOC_OK = 0,
    CS_SDOC_BAD = -1,    /* message written */
    CS_SDOC_NOMEM = -2,
};

/* Parses the first document of text. Syntax errors: CS_SDOC_BAD with the
 * 1-based line in *line and a phrase in msg. An empty document (nothing but
 * comments, or a lone null) loads with no root node. A second document in
 * the stream is an error too. */
int cs_sdoc_load(cs_sdoc *d, const char *text, size_t len, int *line, char *msg, size_t msglen);
void cs_sdoc_free(cs_sdoc *d);

/* Root node id, 0 for an empty document (or a lone null scalar). */
int cs_sdoc_root(const cs_sdoc *d);

typedef struct cs_sloc {
    int line;      /* 1-based line of the deepest component found */
    int matched;   /* path components found */
    int node;      /* node id of the deepest value found (0: none) */
    int owner;     /* deepest override owner met on the way, or -1 */
} cs_sloc;

/* Walks the path from the root. For a mapping key the line is the key's own;
 * for a sequence index the entry's. second: match the second occurrence of
 * the last key (a duplicate). */
void cs_sdoc_locate(const cs_sdoc *d, const cs_spath *p, bool second, cs_sloc *out);

/* "(got X)" text for a node: a scalar's value (shortened), "a mapping",
 * "a list", "nothing" for an empty scalar. */
void cs_sdoc_describe(const cs_sdoc *d, int node, char *buf, size_t len);

/* Sets the value at path p to the YAML text value, creating missing mapping
 * keys on the way; new nodes get owner k. CS_SDOC_BAD with a reason in msg
 * for a bad path, an index past the end, or a value that is not YAML. */
int cs_sdoc_set(cs_sdoc *d, const cs_spath *p, const char *value, int k, char *msg, size_t msglen);

#endif
