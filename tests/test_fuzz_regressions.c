/* test_fuzz_regressions.c: every input the fuzzers of fuzz/
 * found to crash or hang, replayed through the normal code path. Each
 * file of tests/data/fuzz/scene/ is loaded with cs_scene_load (its
 * "#set PATH=VALUE" lines passed as overrides, as scene_fuzz does); each
 * file of tests/data/fuzz/mesh/ is read with cs_mesh_import, cs_mesh_read
 * and cs_mesh_catalog_read, with the reading process's isolation as a
 * user gets it. Each must end in a result or a clean error with a
 * message: never a crash, a hang or a sanitizer report. A new reproducer
 * is a new file there, not a new line here. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "import/import.h"

#ifndef CS_SOURCE_DIR
#error "CS_SOURCE_DIR must name the repository (tests/CMakeLists.txt defines it)"
#endif
#define FUZZ_DATA CS_SOURCE_DIR "/tests/data/fuzz"
#define MAX_FILES 256
#define MAX_OVERRIDES 4

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The regular files of dir (sorted, without dot files); count in *n. */
static char **list_dir(const char *dir, int *n)
{
    char **names = calloc(MAX_FILES, sizeof *names);
    assert_non_null(names);
    *n = 0;
    DIR *d = opendir(dir);
    if (!d)
        return names;
    struct dirent *e;
    while ((e = readdir(d)) && *n < MAX_FILES) {
        if (e->d_name[0] == '.')
            continue;
        size_t len = strlen(dir) + strlen(e->d_name) + 2;
        names[*n] = malloc(len);
        assert_non_null(names[*n]);
        snprintf(names[*n], len, "%s/%s", dir, e->d_name);
        (*n)++;
    }
    closedir(d);
    qsort(names, (size_t)*n, sizeof *names, cmp_names);
    return names;
}

static void free_list(char **names, int n)
{
    for (int i = 0; i < n; i++)
        free(names[i]);
    free(names);
}

/* The "#set PATH=VALUE" lines of a scene file, as scene_fuzz passes them. */
static int read_overrides(const char *path, char ov[MAX_OVERRIDES][512])
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char line[512];
    int n = 0;
    while (n < MAX_OVERRIDES && fgets(line, sizeof line, f))
        if (!strncmp(line, "#set ", 5)) {
            line[strcspn(line, "\r\n")] = '\0';
            snprintf(ov[n++], 512, "%s", line + 5);
        }
    fclose(f);
    return n;
}

static void scenes_end_cleanly(void **state)
{
    (void)state;
    int n;
    char **files = list_dir(FUZZ_DATA "/scene", &n);
    for (int i = 0; i < n; i++) {
        char ov[MAX_OVERRIDES][512];
        const char *ovp[MAX_OVERRIDES];
        int nov = read_overrides(files[i], ov);
        for (int k = 0; k < nov; k++)
            ovp[k] = ov[k];
        char err[1024] = "";
        cs_scene *s = NULL;
        int rc = cs_scene_load(files[i], nov, ovp, &s, err, sizeof err);
        print_message("%s: %s\n", files[i], rc == CS_OK ? "loaded" : err);
        if (rc == CS_OK) {
            assert_non_null(s);
        } else {
            assert_null(s);
            assert_true(rc == CS_ERR_BAD_INPUT || rc == CS_ERR_NOMEM);
            assert_true(err[0] != '\0');
        }
        cs_scene_destroy(s);
    }
    free_list(files, n);
}

static void meshes_end_cleanly(void **state)
{
    (void)state;
    /* the guard as a user has it, whatever the caller's environment says,
     * but 5 s of CPU instead of 30 (unless the environment sets it): the
     * hangs among the reproducers are stopped by the limit, three readers
     * each */
    unsetenv("CLOTHSIM_IMPORT_ISOLATION");
    setenv("CLOTHSIM_IMPORT_SECONDS", "5", 0);
    int n;
    char **files = list_dir(FUZZ_DATA "/mesh", &n);
    for (int i = 0; i < n; i++) {
        char err[1024] = "";
        cs_trimesh *m = NULL;
        cs_mesh_report r;
        int rc = cs_mesh_import(files[i], NULL, &m, &r, err, sizeof err);
        print_message("%s: import: %s\n", files[i], rc == CS_OK ? "read" : err);
        if (rc == CS_OK) {
            assert_non_null(m);
        } else {
            assert_null(m);
            assert_true(err[0] != '\0');
        }
        cs_trimesh_destroy(m);

        err[0] = '\0';
        m = cs_mesh_read(files[i], err, sizeof err);
        print_message("%s: read: %s\n", files[i], m ? "read" : err);
        assert_true(m || err[0] != '\0');
        cs_trimesh_destroy(m);

        err[0] = '\0';
        cs_mesh_catalog *c = NULL;
        rc = cs_mesh_catalog_read(files[i], &c, err, sizeof err);
        print_message("%s: catalog: %s\n", files[i], rc == CS_OK ? "read" : err);
        assert_true(rc == CS_OK ? c != NULL : c == NULL && err[0] != '\0');
        cs_mesh_catalog_destroy(c);
    }
    free_list(files, n);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(scenes_end_cleanly),
        cmocka_unit_test(meshes_end_cleanly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
