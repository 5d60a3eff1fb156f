/* scene_values.c: a key's value checked against its range, entry names,
 * and the small string helpers every scene converter shares.
 *
 * The lowest layer of the conversion (scene_convert.c -> scene_cloth.c ->
 * scene_mesh.c -> here), so that each converter can use these without
 * calling back up into the one that called it.
 */
#include "import/scene_internal.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------- value checks */

static void key_path(const char *base, const cs_scene_key *k, int index, char *buf, size_t len)
{
    int w = snprintf(buf, len, "%s%s%s", base, *base ? "." : "", k->key);
    if (index >= 0 && w > 0 && (size_t)w < len)
        snprintf(buf + w, len - (size_t)w, "[%d]", index);
}

static int fail_range(loader *L, const char *path, const cs_key_range *r)
{
    char text[64];
    cs_key_range_text(r, text, sizeof text);
    return cs_sl_fail(L, path, true, "must be %s", text);
}

static double key_default(const cs_scene_key *k, int i)
{
    return k->def ? k->def(i) : 0.0;
}

int cs_sl_num(loader *L, const cs_scene_key *k, const double *v, const char *base, double *out)
{
    char p[PATH_LEN];
    if (v && !cs_key_in_range(&k->range, *v)) {
        key_path(base, k, -1, p, sizeof p);
        return fail_range(L, p, &k->range);
    }
    *out = v ? *v : key_default(k, 0);
    return CS_OK;
}

int cs_sl_int(loader *L, const cs_scene_key *k, const int *v, const char *base, int index, int *out)
{
    char p[PATH_LEN];
    const cs_key_range *r = &k->range;
    if (v && r->lo_kind == CS_BOUND_GE && *v < r->lo) {
        key_path(base, k, index, p, sizeof p);
        return cs_sl_fail(L, p, true, "must be >= %d", (int)r->lo);
    }
    if (v && r->hi_kind == CS_BOUND_GE && *v > r->hi) {
        key_path(base, k, index, p, sizeof p);
        return cs_sl_fail(L, p, true, "must be at most %d", (int)r->hi);
    }
    *out = v ? *v : (int)key_default(k, index < 0 ? 0 : index);
    return CS_OK;
}

int cs_sl_vec(loader *L, const cs_scene_key *k, const double *v, const char *base,
              const double *def, double *out)
{
    char p[PATH_LEN];
    for (int i = 0; i < k->n; i++) {
        if (v && !cs_key_in_range(&k->range, v[i])) {
            key_path(base, k, i, p, sizeof p);
            return fail_range(L, p, &k->range);
        }
        out[i] = v ? v[i] : def ? def[i] : key_default(k, i);
    }
    return CS_OK;
}

int cs_sl_convert_keys(loader *L, int section, const void *raw, const char *base, void *target)
{
    int rc = CS_OK;
    for (int i = 0; i < CS_KEY_COUNT && !rc; i++) {
        const cs_scene_key *k = &cs_scene_keys[i];
        if (k->section != section || k->target < 0)
            continue;
        const void *v = raw ? *(const void *const *)((const char *)raw + k->raw) : NULL;
        char *t = (char *)target + k->target;
        switch (k->type) {
        case CS_KT_NUM: rc = cs_sl_num(L, k, v, base, (double *)t); break;
        case CS_KT_INT: rc = cs_sl_int(L, k, v, base, -1, (int *)t); break;
        case CS_KT_VEC: rc = cs_sl_vec(L, k, v, base, NULL, (double *)t); break;
        case CS_KT_BOOL: *(bool *)t = v ? *(const bool *)v : key_default(k, 0) != 0; break;
        case CS_KT_ENUM: /* into an enum type: an int to the compilers we build with */
            *(int *)t = v ? *(const int *)v : (int)key_default(k, 0);
            break;
        default: assert(!"a TO key of a type cs_sl_convert_keys does not convert");
        }
    }
    return rc;
}

int cs_sl_check_name(loader *L, const char *name, const char *path)
{
    if (name && !*name)
        return cs_sl_fail(L, path, false, "must not be empty");
    return CS_OK;
}

int cs_sl_entry_name(loader *L, const char *given, const char *list, const char *stem, int index,
                     const char *(*before)(const cs_scene *, int), const cs_scene *s, char **out)
{
    char base[48], p[PATH_LEN], fallback[48];
    int err;
    snprintf(base, sizeof base, "%s[%d]", list, index);
    snprintf(p, sizeof p, "%s.name", base);
    if ((err = cs_sl_check_name(L, given, p)))
        return err;
    snprintf(fallback, sizeof fallback, "%s%d", stem, index);
    if (!(*out = cs_sl_strdup(given ? given : fallback)))
        return CS_ERR_NOMEM;
    for (int j = 0; j < index; j++)
        if (!strcmp(before(s, j), *out))
            return cs_sl_fail(L, given ? p : base, false,
                              "must differ from the name of %s[%d] (got %s)", list, j, *out);
    return CS_OK;
}

char *cs_sl_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

bool cs_sl_note(cs_scene *s, const char *fmt, ...)
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
    if (!(notes[s->nnotes] = cs_sl_strdup(line)))
        return false;
    s->nnotes++;
    return true;
}

char *cs_sl_scene_dir(const char *file)
{
    const char *slash = file ? strrchr(file, '/') : NULL;
    if (!file || file[0] == '<' || !slash)
        return cs_sl_strdup(".");
    size_t n = slash == file ? 1 : (size_t)(slash - file);
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, file, n);
        d[n] = '\0';
    }
    return d;
}

const char *cs_sl_base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}
