/* scene_load.c: the load driver: a scene file (or text) through the stages
 * of scene_internal.h, with --set overrides applied to the parsed scene. */
#include "import/scene_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --------------------------------------------------------------- loading */

/* Applies the overrides to L->doc and, through the rows of their keys, to
 * raw; nothing is parsed again. */
static int apply_overrides(loader *L, cs_raw_scene *raw, char *err, size_t errlen)
{
    char msg[MSG_LEN];
    for (int k = 0; k < L->noverrides; k++) {
        const char *ov = L->overrides[k];
        const char *eq = ov ? strchr(ov, '=') : NULL;
        cs_spath p;
        if (!eq) {
            cs_sl_set_err(err, errlen, "--set %s: expected PATH=VALUE", ov ? ov : "(null)");
            return CS_ERR_BAD_INPUT;
        }
        char path[PATH_LEN];
        size_t n = (size_t)(eq - ov);
        if (n >= sizeof path || (memcpy(path, ov, n), path[n] = '\0', !cs_spath_parse(&p, path))) {
            cs_sl_set_err(
                err, errlen,
                "--set %s: expected a key path like cloths.0.material.node_mass before '='", ov);
            return CS_ERR_BAD_INPUT;
        }
        int rc = cs_sdoc_set(&L->doc, &p, eq + 1, k, msg, sizeof msg);
        if (rc == CS_SDOC_NOMEM)
            return CS_ERR_NOMEM;
        if (rc != CS_SDOC_OK) {
            cs_sl_set_err(err, errlen, "--set %s: %s", ov, msg);
            return CS_ERR_BAD_INPUT;
        }
        if ((rc = cs_sl_apply_override(L, raw, &p)) != CS_OK)
            return rc == CS_ERR_BAD_INPUT ? cs_sl_report(L, true, err, errlen) : rc;
    }
    cs_spath top = {0};
    int rc = cs_sl_check_required(L, CS_SEC_scene, raw, &top);
    return rc == CS_ERR_BAD_INPUT ? cs_sl_report(L, true, err, errlen) : rc;
}

/* The merged scene failed to convert. Errors in nodes an override made are
 * that override's; others are checked against the file alone, which may be
 * where the error really is. */
static int report_merged(loader *L, const char *text, size_t len, const char *default_name,
                         char *err, size_t errlen)
{
    cs_sloc loc;
    cs_sdoc_locate(&L->doc, &L->err_path, false, &loc);
    if (loc.owner >= 0)
        return cs_sl_report(L, true, err, errlen);
    cs_spath path = L->err_path;
    char msg[MSG_LEN];
    memcpy(msg, L->err_msg, sizeof msg);
    /* the file alone, loaded again only to place this error */
    cs_raw_scene *orig = NULL;
    cs_scene *alone = NULL;
    int rc = cs_sl_load_raw(L, text, len, &orig);
    if (rc == CS_OK)
        rc = cs_sl_convert_scene(L, orig, default_name, &alone);
    cs_scene_destroy(alone);
    cs_sl_free_raw(L, orig);
    if (rc == CS_ERR_NOMEM)
        return rc;
    if (rc == CS_ERR_BAD_INPUT) {
        cs_sdoc_locate(&L->doc, &L->err_path, false, &loc);
        if (loc.owner < 0)
            return cs_sl_report(L, false, err, errlen);
    }
    L->err_path = path;
    memcpy(L->err_msg, msg, sizeof msg);
    return cs_sl_report(L, true, err, errlen);
}

static int load(const char *text, size_t len, const char *file, const char *default_name,
                int noverrides, const char *const *overrides, cs_scene **out, char *err,
                size_t errlen)
{
    loader *L = calloc(1, sizeof *L);
    cs_raw_scene *raw = NULL;
    char msg[MSG_LEN];
    int line = 1, rc;

    if (!L)
        return CS_ERR_NOMEM;
    L->file = file;
    L->noverrides = overrides ? noverrides : 0;
    L->overrides = overrides;

    rc = cs_sdoc_load(&L->doc, text, len, &line, msg, sizeof msg);
    if (rc == CS_SDOC_BAD) {
        cs_sl_set_err(err, errlen, "%s:%d: %s", file, line, msg);
        rc = CS_ERR_BAD_INPUT;
    } else if (rc == CS_SDOC_NOMEM) {
        rc = CS_ERR_NOMEM;
    } else if (!cs_sdoc_root(&L->doc)) {
        cs_sl_set_err(err, errlen,
                      "%s:1: the scene is empty (expected a mapping with at least cloths)", file);
        rc = CS_ERR_BAD_INPUT;
    } else if ((rc = cs_sl_load_raw(L, text, len, &raw)) == CS_ERR_BAD_INPUT) {
        rc = cs_sl_report(L, false, err, errlen);
    } else if (rc == CS_OK && L->noverrides > 0) {
        rc = apply_overrides(L, raw, err, errlen);
        if (rc == CS_OK) {
            rc = cs_sl_convert_scene(L, raw, default_name, out);
            if (rc == CS_ERR_BAD_INPUT)
                rc = report_merged(L, text, len, default_name, err, errlen);
        }
    } else if (rc == CS_OK) {
        rc = cs_sl_convert_scene(L, raw, default_name, out);
        if (rc == CS_ERR_BAD_INPUT)
            rc = cs_sl_report(L, false, err, errlen);
    }
    if (rc == CS_OK && ((rc = cs_sl_build_levelsets(L, *out)) != CS_OK ||
                               (rc = cs_sl_resolve(L, raw, *out)) !=
                                   CS_OK)) {
        if (rc == CS_ERR_BAD_INPUT)
            cs_sl_report(L, L->noverrides > 0, err, errlen);
        cs_scene_destroy(*out);
        *out = NULL;
    }
    if (rc == CS_ERR_NOMEM)
        cs_sl_set_err(err, errlen, "%s: out of memory", file);
    cs_sl_free_raw(L, raw);
    cs_sdoc_free(&L->doc);
    free(L);
    return rc;
}

int cs_scene_load_string(const char *text, const char *origin, int noverrides,
                         const char *const *overrides, cs_scene **out, char *err, size_t errlen)
{
    if (!out)
        return CS_ERR_BAD_INPUT;
    *out = NULL;
    if (!text) {
        cs_sl_set_err(err, errlen, "%s: no text", origin ? origin : "<string>");
        return CS_ERR_BAD_INPUT;
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

int cs_scene_load(const char *path, int noverrides, const char *const *overrides, cs_scene **out,
                  char *err, size_t errlen)
{
    size_t len = 0;
    if (!out)
        return CS_ERR_BAD_INPUT;
    *out = NULL;
    if (!path) {
        cs_sl_set_err(err, errlen, "no scene file given");
        return CS_ERR_BAD_INPUT;
    }
    char *text = read_file(path, &len);
    if (!text) {
        cs_sl_set_err(err, errlen, "%s: cannot read: %s", path, strerror(errno));
        return errno == ENOMEM ? CS_ERR_NOMEM : CS_ERR_BAD_INPUT;
    }
    /* libyaml would stop at a NUL byte without saying so. */
    if (strlen(text) != len) {
        int line = 1;
        for (const char *c = text; *c; c++)
            line += *c == '\n';
        cs_sl_set_err(err, errlen, "%s:%d: the file contains a NUL byte (not a text file?)", path,
                      line);
        free(text);
        return CS_ERR_BAD_INPUT;
    }
    int rc = load(text, len, path, NULL, noverrides, overrides, out, err, errlen);
    free(text);
    return rc;
}
