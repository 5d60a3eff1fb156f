/* scene_schema.c: the libcyaml schema of a scene file, the key descriptors,
 * and queries on them; all made from scene_keys.def, which
 * docs/scene-reference.md is printed from too (tests/cli_scene_reference.sh). */
#include "import/scene_schema.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "import/import.h"
#include "sim/sim.h"

/* Every optional key: absent leaves the member NULL. */
#define OPT (CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL)
#define REQ CYAML_FLAG_POINTER

static const cyaml_schema_value_t float_value = {
    CYAML_VALUE_FLOAT(CYAML_FLAG_DEFAULT, double),
};
static const cyaml_schema_value_t int_value = {
    CYAML_VALUE_INT(CYAML_FLAG_DEFAULT, int),
};
static const cyaml_schema_value_t vec3_value = {
    CYAML_VALUE_SEQUENCE_FIXED(CYAML_FLAG_DEFAULT, double, &float_value, 3),
};
static const cyaml_schema_value_t int3_value = {
    CYAML_VALUE_SEQUENCE_FIXED(CYAML_FLAG_DEFAULT, int, &int_value, 3),
};
static const cyaml_schema_value_t int2_value = {
    CYAML_VALUE_SEQUENCE_FIXED(CYAML_FLAG_DEFAULT, int, &int_value, 2),
};

/* The names of the ENUM keys' values (ARG in scene_keys.def). */
static const cyaml_strval_t friction_names[] = {
    {"improved", CS_FRICTION_IMPROVED},
    {"projection", CS_FRICTION_PROJECTION},
};
static const cyaml_strval_t step_limit_names[] = {
    {"undamped", CS_STEP_UNDAMPED},
    {"damped", CS_STEP_DAMPED},
    {"auto", CS_STEP_AUTO},
};
static const cyaml_strval_t scheme_names[] = {
    {"fixed", CS_COLLISION_FIXED},
    {"rewind", CS_COLLISION_REWIND},
};
static const cyaml_strval_t script_zones_names[] = {
    {"follow", CS_SCRIPT_ZONES_FOLLOW},
    {"hold", CS_SCRIPT_ZONES_HOLD},
};
static const cyaml_strval_t pruning_names[] = {
    {"speed", CS_PRUNING_SPEED},
    {"path", CS_PRUNING_PATH},
};
static const cyaml_strval_t format_names[] = {{"ply", 0}, {"obj", 1}, {"glb", 2}};
static const cyaml_strval_t shape_names[] = {
    {"plane", CS_BODY_PLANE},       {"sphere", CS_BODY_SPHERE}, {"box", CS_BODY_BOX},
    {"cylinder", CS_BODY_CYLINDER}, {"mesh", CS_BODY_MESH},
};
static const cyaml_strval_t interior_names[] = {
    {"auto", CS_INTERIOR_AUTO}, {"fill", CS_INTERIOR_FILL}, {"band", CS_INTERIOR_BAND}};
static const cyaml_strval_t unit_names[] = {{"auto", 0}, {"m", 1},  {"cm", 2}, {"mm", 3},
                                            {"km", 4},   {"in", 5}, {"ft", 6}};

/* The lower bound of a range: the least entries of a list. */
#define CS_LO_ANY 0
#define CS_LO_POS 0
#define CS_LO_NONNEG 0
#define CS_LO_UNIT 0
#define CS_LO_R(lk, lo, hk, hi) lo
#define CS_MIN(RANGE) CS_LO_##RANGE

/* One cyaml field per key. */
#define F_NUM_OPT(t, k, a, r) CYAML_FIELD_FLOAT_PTR(#k, OPT, t, k)
#define F_NUM_REQ(t, k, a, r) CYAML_FIELD_FLOAT(#k, CYAML_FLAG_DEFAULT, t, k)
#define F_INT_OPT(t, k, a, r) CYAML_FIELD_INT_PTR(#k, OPT, t, k)
#define F_BOOL_OPT(t, k, a, r) CYAML_FIELD_BOOL_PTR(#k, OPT, t, k)
#define F_STR_OPT(t, k, a, r) CYAML_FIELD_STRING_PTR(#k, OPT, t, k, 0, CYAML_UNLIMITED)
#define F_DT_OPT(t, k, a, r) F_STR_OPT(t, k, a, r)
#define F_ENUM_OPT(t, k, a, r)                                                          \
    CYAML_FIELD_ENUM_PTR(#k, OPT | CYAML_FLAG_STRICT, t, k, a##_names,                  \
                         CYAML_ARRAY_LEN(a##_names))
#define F_ENUM_REQ(t, k, a, r)                                                          \
    CYAML_FIELD_ENUM(#k, CYAML_FLAG_STRICT, t, k, a##_names, CYAML_ARRAY_LEN(a##_names))
#define F_VEC_OPT(t, k, a, r) CYAML_FIELD_SEQUENCE_FIXED(#k, OPT, t, k, &float_value, a)
#define F_VEC_REQ(t, k, a, r) CYAML_FIELD_SEQUENCE_FIXED(#k, REQ, t, k, &float_value, a)
#define F_IVEC_OPT(t, k, a, r) CYAML_FIELD_SEQUENCE_FIXED(#k, OPT, t, k, &int_value, a)
#define F_SCALE_OPT(t, k, a, r) CYAML_FIELD_IGNORE(#k, CYAML_FLAG_OPTIONAL)
#define F_MAP_OPT(t, k, a, r) CYAML_FIELD_MAPPING_PTR(#k, OPT, t, k, a##_fields)
#define F_MAP_REQ(t, k, a, r) CYAML_FIELD_MAPPING_PTR(#k, REQ, t, k, a##_fields)
#define F_LIST_OPT(t, k, a, r)                                                          \
    CYAML_FIELD_SEQUENCE(#k, OPT, t, k, &a##_value, CS_MIN(r), CYAML_UNLIMITED)
#define F_LIST_REQ(t, k, a, r)                                                          \
    CYAML_FIELD_SEQUENCE(#k, REQ, t, k, &a##_value, CS_MIN(r), CYAML_UNLIMITED)
#define F_VLIST_OPT(t, k, a, r)                                                         \
    CYAML_FIELD_SEQUENCE(#k, OPT, t, k, &vec##a##_value, CS_MIN(r), CYAML_UNLIMITED)
#define F_ILIST_OPT(t, k, a, r)                                                         \
    CYAML_FIELD_SEQUENCE(#k, OPT, t, k, &int##a##_value, CS_MIN(r), CYAML_UNLIMITED)
#define F_IDXLIST_OPT(t, k, a, r)                                                       \
    CYAML_FIELD_SEQUENCE(#k, OPT, t, k, &int_value, CS_MIN(r), CYAML_UNLIMITED)

#define CS_SECTION(sec, ttype, tname, heading) static const cyaml_schema_field_t sec##_fields[] = {
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC) \
    F_##TYPE##_##REQ(cs_raw_##sec, key, ARG, RANGE),
#define CS_END(sec)                                                                     \
    CYAML_FIELD_END                                                                     \
    }                                                                                   \
    ;                                                                                   \
    static const cyaml_schema_value_t sec##_value = {                                   \
        CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, cs_raw_##sec, sec##_fields),            \
    };
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END

const cyaml_schema_value_t cs_scene_schema = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, cs_raw_scene, scene_fields),
};

/* ------------------------------------------------------ key descriptors */

/* Defaults: a function per key with one (i: the entry of a vector). */
#define DEFVAL_D(x) (x)
#define DEFVAL_NODEF 0
#define HASDEF_D(x) 1
#define HASDEF_NODEF 0
#define CS_SECTION(sec, ttype, tname, heading)
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC) \
    static double def_##sec##_##key(int i)                                          \
    {                                                                               \
        (void)i;                                                                    \
        return (double)(DEFVAL_##DEF);                                              \
    }
#define CS_END(sec)
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END

/* What the TO keys of a section are converted into. */
#define CS_SECTION(sec, ttype, tname, heading) typedef ttype cs_target_##sec;
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC)
#define CS_END(sec)
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END

#define TARGET_TO(sec, f) (long)offsetof(cs_target_##sec, f)
#define TARGET_HAND(sec, f) -1L
#define RANGE_ANY {CS_BOUND_NONE, 0, CS_BOUND_NONE, 0}
#define RANGE_POS {CS_BOUND_GT, 0, CS_BOUND_NONE, 0}
#define RANGE_NONNEG {CS_BOUND_GE, 0, CS_BOUND_NONE, 0}
#define RANGE_UNIT {CS_BOUND_GE, 0, CS_BOUND_GE, 1}
#define RANGE_R(lk, lo, hk, hi) {CS_BOUND_##lk, lo, CS_BOUND_##hk, hi}
#define RAW_SCALE(sec, key) 0
#define RAW_NUM(sec, key) offsetof(cs_raw_##sec, key)
#define RAW_INT RAW_NUM
#define RAW_BOOL RAW_NUM
#define RAW_STR RAW_NUM
#define RAW_DT RAW_NUM
#define RAW_ENUM RAW_NUM
#define RAW_VEC RAW_NUM
#define RAW_IVEC RAW_NUM
#define RAW_MAP RAW_NUM
#define RAW_LIST RAW_NUM
#define RAW_VLIST RAW_NUM
#define RAW_ILIST RAW_NUM
#define RAW_IDXLIST RAW_NUM
#define N_VEC(a) a
#define N_IVEC(a) a
#define N_VLIST(a) a
#define N_ILIST(a) a
#define CHILD_MAP(a) CS_SEC_##a
#define CHILD_LIST(a) CS_SEC_##a
#define NAMES_ENUM(a) a##_names, CYAML_ARRAY_LEN(a##_names)
/* the ARG of other types means nothing */
#define N_NUM(a) 0
#define N_INT(a) 0
#define N_BOOL(a) 0
#define N_STR(a) 0
#define N_DT(a) 0
#define N_ENUM(a) 0
#define N_SCALE(a) 3
#define N_MAP(a) 0
#define N_LIST(a) 0
#define N_IDXLIST(a) 1
#define CHILD_NUM(a) -1
#define CHILD_INT(a) -1
#define CHILD_BOOL(a) -1
#define CHILD_STR(a) -1
#define CHILD_DT(a) -1
#define CHILD_ENUM(a) -1
#define CHILD_VEC(a) -1
#define CHILD_IVEC(a) -1
#define CHILD_SCALE(a) -1
#define CHILD_VLIST(a) -1
#define CHILD_ILIST(a) -1
#define CHILD_IDXLIST(a) -1
#define NAMES_NUM(a) NULL, 0
#define NAMES_INT(a) NULL, 0
#define NAMES_BOOL(a) NULL, 0
#define NAMES_STR(a) NULL, 0
#define NAMES_DT(a) NULL, 0
#define NAMES_VEC(a) NULL, 0
#define NAMES_IVEC(a) NULL, 0
#define NAMES_SCALE(a) NULL, 0
#define NAMES_MAP(a) NULL, 0
#define NAMES_LIST(a) NULL, 0
#define NAMES_VLIST(a) NULL, 0
#define NAMES_ILIST(a) NULL, 0
#define NAMES_IDXLIST(a) NULL, 0
#define COUNT_LIST(sec, key) offsetof(cs_raw_##sec, key##_count)
#define COUNT_VLIST COUNT_LIST
#define COUNT_ILIST COUNT_LIST
#define COUNT_IDXLIST COUNT_LIST
#define COUNT_NUM(sec, key) 0
#define COUNT_INT COUNT_NUM
#define COUNT_BOOL COUNT_NUM
#define COUNT_STR COUNT_NUM
#define COUNT_DT COUNT_NUM
#define COUNT_ENUM COUNT_NUM
#define COUNT_VEC COUNT_NUM
#define COUNT_IVEC COUNT_NUM
#define COUNT_SCALE COUNT_NUM
#define COUNT_MAP COUNT_NUM

const cs_scene_key cs_scene_keys[CS_KEY_COUNT] = {
#define CS_SECTION(sec, ttype, tname, heading)
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC)          \
    {CS_SEC_##sec, #key, CS_KT_##TYPE, N_##TYPE(ARG), CHILD_##TYPE(ARG), NAMES_##TYPE(ARG), \
     CS_IS_##REQ, RAW_##TYPE(sec, key), HASDEF_##DEF ? def_##sec##_##key : NULL, DEFTEXT,    \
     RANGE_##RANGE, UNIT, TARGET_##HOW(sec, FIELD), DOC, COUNT_##TYPE(sec, key)},
#define CS_END(sec)
#define CS_IS_OPT false
#define CS_IS_REQ true
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END
};

const cs_scene_section cs_scene_sections[CS_SEC_COUNT] = {
#define CS_SECTION(sec, ttype, tname, heading) \
    {#sec, tname, heading, sec##_fields, sizeof(cs_raw_##sec)},
#define CS_KEY(sec, key, TYPE, ARG, REQ, DEF, DEFTEXT, RANGE, UNIT, HOW, FIELD, DOC)
#define CS_END(sec)
#include "import/scene_keys.def"
#undef CS_SECTION
#undef CS_KEY
#undef CS_END
};

const char *cs_scene_enum_name(const cs_scene_key *k, int v)
{
    for (unsigned i = 0; i < k->nnames; i++)
        if (k->names[i].val == v)
            return k->names[i].str;
    return "?";
}

bool cs_key_in_range(const cs_key_range *r, double x)
{
    if (r->lo_kind == CS_BOUND_GT && !(x > r->lo))
        return false;
    if (r->lo_kind == CS_BOUND_GE && !(x >= r->lo))
        return false;
    if (r->hi_kind == CS_BOUND_GT && !(x < r->hi))
        return false;
    if (r->hi_kind == CS_BOUND_GE && !(x <= r->hi))
        return false;
    return true;
}

void cs_key_range_text(const cs_key_range *r, char *buf, size_t len)
{
    if (r->lo_kind == CS_BOUND_NONE && r->hi_kind == CS_BOUND_NONE)
        snprintf(buf, len, "%s", "");
    else if (r->hi_kind == CS_BOUND_NONE)
        snprintf(buf, len, "%s %g", r->lo_kind == CS_BOUND_GT ? ">" : ">=", r->lo);
    else if (r->lo_kind == CS_BOUND_NONE)
        snprintf(buf, len, "%s %g", r->hi_kind == CS_BOUND_GT ? "<" : "<=", r->hi);
    else
        snprintf(buf, len, "in %c%g, %g%c", r->lo_kind == CS_BOUND_GT ? '(' : '[', r->lo, r->hi,
                 r->hi_kind == CS_BOUND_GT ? ')' : ']');
}

/* Edit distance with adjacent transpositions (optimal string alignment). */
static int edit_distance(const char *a, const char *b)
{
    enum { MAX = 64 };
    size_t n = strlen(a), m = strlen(b);
    if (n >= MAX || m >= MAX)
        return MAX;
    int d[MAX][MAX];
    for (size_t i = 0; i <= n; i++)
        d[i][0] = (int)i;
    for (size_t j = 0; j <= m; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= n; i++)
        for (size_t j = 1; j <= m; j++) {
            int cost = a[i - 1] != b[j - 1];
            int best = d[i - 1][j - 1] + cost;
            if (d[i - 1][j] + 1 < best)
                best = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < best)
                best = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                d[i - 2][j - 2] + 1 < best)
                best = d[i - 2][j - 2] + 1;
            d[i][j] = best;
        }
    return d[n][m];
}

const char *cs_scene_nearest_key(const cyaml_schema_value_t *mapping, const char *key)
{
    if (!mapping || mapping->type != CYAML_MAPPING)
        return NULL;
    const char *best = NULL;
    /* near: a third of the key's letters wrong at the most (one for short keys) */
    int best_d = (int)(strlen(key) + 2) / 3 + 1;
    for (const cyaml_schema_field_t *f = mapping->mapping.fields; f->key; f++) {
        int d = edit_distance(key, f->key);
        if (d < best_d) {
            best = f->key;
            best_d = d;
        }
    }
    return best;
}

/* ------------------------------------------------------------ key paths */

void cs_spath_push_key(cs_spath *p, const char *key, size_t len)
{
    if (p->n >= CS_SPATH_MAX)
        return;
    if (len >= CS_SPATH_KEY)
        len = CS_SPATH_KEY - 1;
    memcpy(p->c[p->n].key, key, len);
    p->c[p->n].key[len] = '\0';
    p->c[p->n].index = -1;
    p->n++;
}

void cs_spath_push_index(cs_spath *p, long index)
{
    if (p->n >= CS_SPATH_MAX)
        return;
    p->c[p->n].key[0] = '\0';
    p->c[p->n].index = index;
    p->n++;
}

bool cs_spath_parse(cs_spath *p, const char *text)
{
    p->n = 0;
    const char *s = text;
    if (*s == '\0')
        return false;
    for (;;) {
        size_t len = strcspn(s, ".[");
        if (len == 0)
            return false;
        cs_spath_push_key(p, s, len);
        s += len;
        while (*s == '[') {
            char *end;
            long index = strtol(s + 1, &end, 10);
            if (end == s + 1 || *end != ']' || index < 0 || s[1] == '-' || s[1] == '+' ||
                s[1] == ' ')
                return false;
            cs_spath_push_index(p, index);
            s = end + 1;
        }
        if (*s == '\0')
            return p->n <= CS_SPATH_MAX;
        if (*s != '.')
            return false;
        s++;
    }
}

bool cs_all_digits(const char *s)
{
    if (*s == '\0')
        return false;
    for (; *s; s++)
        if (*s < '0' || *s > '9')
            return false;
    return true;
}

void cs_spath_format(const cs_spath *p, char *buf, size_t len)
{
    size_t used = 0;
    if (len == 0)
        return;
    buf[0] = '\0';
    for (int i = 0; i < p->n && used < len; i++) {
        int w;
        if (p->c[i].index >= 0)
            w = snprintf(buf + used, len - used, "[%ld]", p->c[i].index);
        else if (i > 0 && cs_all_digits(p->c[i].key))
            w = snprintf(buf + used, len - used, "[%s]", p->c[i].key);
        else
            w = snprintf(buf + used, len - used, "%s%s", i > 0 ? "." : "", p->c[i].key);
        if (w < 0)
            break;
        used += (size_t)w;
    }
}

/* ------------------------------------------------------- schema queries */

const cyaml_schema_value_t *cs_scene_schema_at(const cs_spath *p)
{
    const cyaml_schema_value_t *v = &cs_scene_schema;
    for (int i = 0; i < p->n && v; i++) {
        if (v->type == CYAML_MAPPING) {
            const cyaml_schema_field_t *f = v->mapping.fields;
            while (f->key && strcmp(f->key, p->c[i].key) != 0)
                f++;
            v = f->key ? &f->value : NULL;
        } else if (v->type == CYAML_SEQUENCE || v->type == CYAML_SEQUENCE_FIXED) {
            v = v->sequence.entry;
        } else {
            v = NULL;
        }
    }
    return v;
}

/* The value of a DT key (a string in the schema only so that "auto" loads). */
static bool is_auto_number(const cyaml_schema_value_t *v)
{
    for (int k = 0; k < CS_KEY_COUNT; k++) {
        if (cs_scene_keys[k].type != CS_KT_DT)
            continue;
        const cyaml_schema_field_t *f = cs_scene_sections[cs_scene_keys[k].section].fields;
        for (; f->key; f++)
            if (v == &f->value && strcmp(f->key, cs_scene_keys[k].key) == 0)
                return true;
    }
    return false;
}

void cs_scene_schema_describe(const cyaml_schema_value_t *v, char *buf, size_t len)
{
    if (!v) {
        snprintf(buf, len, "a valid value");
        return;
    }
    if (is_auto_number(v)) {
        snprintf(buf, len, "a number >= 0 or auto");
        return;
    }
    switch (v->type) {
    case CYAML_INT:
        snprintf(buf, len, "an integer");
        break;
    case CYAML_FLOAT:
        snprintf(buf, len, "a number");
        break;
    case CYAML_BOOL:
        snprintf(buf, len, "true or false");
        break;
    case CYAML_STRING:
        snprintf(buf, len, "a string");
        break;
    case CYAML_ENUM: {
        size_t used = (size_t)snprintf(buf, len, "one of");
        for (uint32_t i = 0; i < v->enumeration.count && used < len; i++)
            used += (size_t)snprintf(buf + used, len - used, "%s %s", i ? "," : "",
                                     v->enumeration.strings[i].str);
        break;
    }
    case CYAML_MAPPING:
        snprintf(buf, len, "a mapping");
        break;
    case CYAML_SEQUENCE_FIXED: {
        const cyaml_schema_value_t *e = v->sequence.entry;
        const char *what = e->type == CYAML_INT     ? "integers"
                           : e->type == CYAML_FLOAT ? "numbers"
                                                    : "values";
        snprintf(buf, len, "a list of %u %s", (unsigned)v->sequence.min, what);
        break;
    }
    case CYAML_SEQUENCE:
        snprintf(buf, len, "a list");
        break;
    default:
        snprintf(buf, len, "a valid value");
        break;
    }
}
