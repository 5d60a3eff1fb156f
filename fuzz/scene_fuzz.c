/* scene_fuzz.c: libFuzzer target for the scene loader.
 *
 * Each input is a scene file's text, loaded with cs_scene_load_string (the
 * in-memory twin of cs_scene_load: the same parse, schema, conversion,
 * mesh import and level sets) as if it were fuzz-root/scenes/fuzz.yaml,
 * so that relative mesh paths such as ../assets/ico4.obj resolve to the
 * copies fuzz/seed.sh lays in build-fuzz/fuzz-root/assets/ (and a mutated
 * levelset.cache key writes there, never into the repository). Lines
 * "#set PATH=VALUE" (a YAML comment) are also passed as command-line
 * overrides, as `clothsim run --set` does, so the override code is fuzzed
 * too. A load must end in CS_OK or an error with a message; the
 * sanitizers and libFuzzer catch everything else. Mesh files go through
 * the normal path (cs_mesh_import in its guarded child process). */
#include "import/import.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef CS_FUZZ_ROOT
#error "CS_FUZZ_ROOT must name build-fuzz/fuzz-root (fuzz/CMakeLists.txt defines it)"
#endif

#define MAX_OVERRIDES 4

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    /* converted grids are cached beside the corpus, not in ~/.cache */
    setenv("CLOTHSIM_CACHE", CS_FUZZ_ROOT "/cache", 1);
    /* a mesh body's import in its child: seconds, not the default 30 */
    setenv("CLOTHSIM_IMPORT_SECONDS", "10", 0);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';

    /* "#set PATH=VALUE" lines, copied out (the scene keeps its text) */
    char *ovbuf[MAX_OVERRIDES];
    const char *ov[MAX_OVERRIDES];
    int nov = 0;
    for (const char *p = text; p && *p && nov < MAX_OVERRIDES; p = strchr(p, '\n'), p = p ? p + 1 : p) {
        if (strncmp(p, "#set ", 5) != 0)
            continue;
        const char *s = p + 5, *e = strchr(s, '\n');
        size_t n = e ? (size_t)(e - s) : strlen(s);
        if (!(ovbuf[nov] = malloc(n + 1)))
            break;
        memcpy(ovbuf[nov], s, n);
        ovbuf[nov][n] = '\0';
        ov[nov] = ovbuf[nov];
        nov++;
    }

    char err[1024];
    err[0] = '\0';
    cs_scene *scene = NULL;
    int rc = cs_scene_load_string(text, CS_FUZZ_ROOT "/scenes/fuzz.yaml", nov, ov, &scene, err,
                                  sizeof err);
    /* the contract of import.h: a scene, or none with a message */
    if (rc == CS_OK && !scene)
        abort();
    if (rc != CS_OK && (scene || (rc == CS_ERR_BAD_INPUT && !err[0])))
        abort();
    if (rc != CS_OK && rc != CS_ERR_BAD_INPUT && rc != CS_ERR_NOMEM)
        abort();
    cs_scene_destroy(scene);
    for (int k = 0; k < nov; k++)
        free(ovbuf[k]);
    free(text);
    return 0;
}
