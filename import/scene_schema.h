/* scene_schema.h: private to the scene loader.
 *
 * The raw structs libcyaml fills from a scene file, the schema that drives
 * it, and small queries on that schema (the schema of a key path, a phrase
 * for what a value should look like), all made from the table of keys,
 * scene_keys.def. Optional scalars are pointers so that an explicit 0
 * differs from an absent key (NULL).
 */
#ifndef CS_SCENE_SCHEMA_H
#define CS_SCENE_SCHEMA_H

#include <stdbool.h>
#include <stddef.h>

#include <cyaml/cyaml.h>

/* The raw structs, one per section of scene_keys.def: an optional scalar
 * is a pointer, a list a pointer and a count (<key>_count). */
#define CS_SECTION(sec, ttype, tname, heading) typedef struct cs_raw_##sec cs_raw_##sec;
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC)
#define CS_END(sec)
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END

#define CS_RAW_NUM_OPT(k, a) double *k;
#define CS_RAW_NUM_REQ(k, a) double k;
#define CS_RAW_INT_OPT(k, a) int *k;
#define CS_RAW_BOOL_OPT(k, a) bool *k;
#define CS_RAW_STR_OPT(k, a) char *k;
#define CS_RAW_DT_OPT(k, a) char *k;     /* a number or "auto": read on conversion */
#define CS_RAW_ENUM_OPT(k, a) int *k;
#define CS_RAW_ENUM_REQ(k, a) int k;
#define CS_RAW_VEC_OPT(k, a) double *k;
#define CS_RAW_VEC_REQ(k, a) double *k;
#define CS_RAW_IVEC_OPT(k, a) int *k;
#define CS_RAW_SCALE_OPT(k, a)          /* read from the document */
#define CS_RAW_MAP_OPT(k, a) struct cs_raw_##a *k;
#define CS_RAW_MAP_REQ(k, a) struct cs_raw_##a *k;
#define CS_RAW_LIST_OPT(k, a) struct cs_raw_##a *k; unsigned k##_count;
#define CS_RAW_LIST_REQ(k, a) CS_RAW_LIST_OPT(k, a)
#define CS_RAW_VLIST_OPT(k, a) double (*k)[a]; unsigned k##_count;
#define CS_RAW_ILIST_OPT(k, a) int (*k)[a]; unsigned k##_count;
#define CS_RAW_IDXLIST_OPT(k, a) int *k; unsigned k##_count;
#define CS_SECTION(sec, ttype, tname, heading) struct cs_raw_##sec {
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC) \
    CS_RAW_##TYPE##_##REQ(key, ARG)
#define CS_END(sec) };
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END

/* ------------------------------------------------------ key descriptors */

/* Sections and keys by name: CS_SEC_time, CS_KEY_time_fps. */
enum {
#define CS_SECTION(sec, ttype, tname, heading) CS_SEC_##sec,
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC)
#define CS_END(sec)
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END
    CS_SEC_COUNT
};
enum {
#define CS_SECTION(sec, ttype, tname, heading)
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC) \
    CS_KEY_##sec##_##key,
#define CS_END(sec)
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END
    CS_KEY_COUNT
};

typedef enum cs_key_type {
    CS_KT_NUM, CS_KT_INT, CS_KT_BOOL, CS_KT_STR, CS_KT_DT, CS_KT_ENUM, CS_KT_VEC, CS_KT_IVEC,
    CS_KT_SCALE, CS_KT_MAP, CS_KT_LIST, CS_KT_VLIST, CS_KT_ILIST, CS_KT_IDXLIST,
} cs_key_type;

/* Bound kinds: lo GT is "> lo", GE ">= lo"; hi GT is "< hi", GE "<= hi". */
enum { CS_BOUND_NONE, CS_BOUND_GT, CS_BOUND_GE };

typedef struct cs_key_range {
    int lo_kind;
    double lo;
    int hi_kind;
    double hi;
} cs_key_range;

typedef struct cs_scene_key {
    int section;                 /* CS_SEC_... */
    const char *key;
    cs_key_type type;
    int n;                       /* entries of a VEC, IVEC, VLIST, ILIST */
    int child;                   /* MAP, LIST: the section; else -1 */
    const cyaml_strval_t *names; /* ENUM */
    unsigned nnames;
    bool required;
    size_t raw;                  /* offset in cs_raw_<section> (not for SCALE) */
    double (*def)(int i);        /* the default (entry i of a vector); NULL: none */
    const char *deftext;         /* what the reference says instead, or NULL */
    cs_key_range range;
    const char *unit;
    long target;                 /* offset into the section's ttype; -1: by hand */
    const char *doc;
    size_t count;                /* LIST, VLIST, ILIST, IDXLIST: offset of <key>_count */
} cs_scene_key;

typedef struct cs_scene_section {
    const char *name;            /* e.g. "self" */
    const char *tname;           /* "mapping", "selection", "motion" */
    const char *heading;         /* e.g. "self_collision" */
    const cyaml_schema_field_t *fields;
    size_t size;                 /* of cs_raw_<section> */
} cs_scene_section;

extern const cs_scene_key cs_scene_keys[CS_KEY_COUNT];
extern const cs_scene_section cs_scene_sections[CS_SEC_COUNT];
#define CS_SKEY(sec, key) (&cs_scene_keys[CS_KEY_##sec##_##key])

bool cs_key_in_range(const cs_key_range *r, double x);
/* "> 0", "in (0, 1]", "" for no bound. */
void cs_key_range_text(const cs_key_range *r, char *buf, size_t len);

/* The known key of the mapping with this schema nearest to key (edit
 * distance, a transposition counting once), or NULL when none is near. */
const char *cs_scene_nearest_key(const cyaml_schema_value_t *mapping, const char *key);

/* The top-level schema (a pointer to cs_raw_scene). */
extern const cyaml_schema_value_t cs_scene_schema;

/* The name of value v of an ENUM key. */
const char *cs_scene_enum_name(const cs_scene_key *k, int v);

/* A key path: mapping keys and sequence indices, outermost first. Keys
 * longer than the buffer are cut (they then match nothing). */
#define CS_SPATH_MAX 48
#define CS_SPATH_KEY 96
typedef struct cs_spath {
    int n;
    struct {
        char key[CS_SPATH_KEY];  /* "" for an index component */
        long index;              /* >= 0 for an index component */
    } c[CS_SPATH_MAX];
} cs_spath;

void cs_spath_push_key(cs_spath *p, const char *key, size_t len);
void cs_spath_push_index(cs_spath *p, long index);
/* Parses "a.b[2].c" or "a.b.2.c" (a purely numeric component between dots
 * stays a key; the locator treats it as an index inside a sequence).
 * Returns false on an empty component or a malformed bracket. */
bool cs_spath_parse(cs_spath *p, const char *text);
/* Writes "a.b[2].c" (numeric dotted components are written as [N]). */
void cs_spath_format(const cs_spath *p, char *buf, size_t len);

/* The schema of the value at a path, or NULL where the path leaves it. */
const cyaml_schema_value_t *cs_scene_schema_at(const cs_spath *p);

/* A phrase for what a value with this schema looks like: "a number",
 * "one of ply, obj, glb", "a list of 3 numbers", ... */
void cs_scene_schema_describe(const cyaml_schema_value_t *v, char *buf, size_t len);

/* True for a non-empty string of decimal digits (a sequence index). */
bool cs_all_digits(const char *s);

#endif
