/* render_frames.c: the images of `clothsim render`: each frame's cloths
 * read back (or a scene's initial state) and drawn, one PNG a frame.
 *
 * A frame keeps its cloths apart (outdir.h: an object per cloth in OBJ and
 * glTF, a file per cloth in PLY), so each is read back by its name. A frame
 * without them (written before frames kept cloths apart, or the scene's
 * cloths renamed since) is drawn as one mesh in the first cloth's colour,
 * and the command says so once.
 */
#include "app/render_cmd_internal.h"

#include "app/exit.h"
#include "app/outdir.h"
#include "app/scene_render.h"
#include "import/import.h"
#include "render/render.h"

#include <stdio.h>
#include <unistd.h>

void cs_frame_geometry_clear(frame_geometry *g)
{
    cs_trimesh_destroy(g->file);
    g->file = NULL;
    for (int c = 0; g->meshes && c < g->layout.ncloths; c++) {
        cs_trimesh_destroy(g->meshes[c]);
        g->meshes[c] = NULL;
    }
}

/* Loads the geometry of frame f into j->geom: per cloth its object of the
 * frame, read by name; a file without them (an older run's, or a scene
 * changed since) is drawn as one mesh in the first cloth's colour, as the
 * command says once. */
int cs_render_cmd_get_frame(render_job *j, int f, char *err, size_t errlen)
{
    frame_geometry *g = &j->geom;
    cs_frame_geometry_clear(g);
    if (!j->run_mode) {
        for (int c = 0; c < j->scene->def.ncloths; c++)
            g->x[c] = j->scene->def.cloths[c].mesh->x;
        g->cloths = (cs_frame_cloths){.x = g->x};
        return CS_EXIT_OK;
    }
    int status = cs_frame_read(&g->layout, j->frames_dir, f, g->meshes, err, errlen);
    g->cloths = (cs_frame_cloths){.meshes = (const cs_trimesh *const *)g->meshes};
    if (status != CS_EXIT_INPUT || g->layout.format == CS_MESH_PLY)
        return status;
    char path[4096], why[ERRLEN];
    cs_frame_file_path(&g->layout, j->frames_dir, f, 0, path, sizeof path);
    snprintf(why, sizeof why, "%s", err);
    if (access(path, F_OK) != 0 || !(g->file = cs_mesh_read(path, err, errlen)))
        return CS_EXIT_INPUT;
    g->cloths = (cs_frame_cloths){.merged = g->file};
    if (!j->merged_said && !j->o->quiet)
        fprintf(stderr, "clothsim render: %s: all cloth is drawn as one mesh in the first "
                        "cloth's colour\n", why);
    j->merged_said = true;
    return CS_EXIT_OK;
}

int cs_render_cmd_frames(render_job *j, const int *frames, int nframes)
{
    char err[ERRLEN];
    for (int k = 0; k < nframes; k++) {
        int f = frames[k];
        int status = cs_render_cmd_get_frame(j, f, err, sizeof err);
        cs_render_stats st;
        if (status == CS_EXIT_OK)
            status = cs_scene_render_draw(j->sr, f / j->fps, &j->geom.cloths, NULL, j->image, &st,
                                          err, sizeof err);
        if (status != CS_EXIT_OK) {
            fprintf(stderr, "clothsim render: frame %d: %s\n", f, err);
            return status;
        }
        char path[4200];
        cs_frame_path(path, sizeof path, j->out_dir, f, NULL, "png");
        if (cs_image_write_png(j->image, path, err, sizeof err) != CS_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            return CS_EXIT_OUTPUT;
        }
        if (!j->o->quiet)
            printf("frame %d: %s (%.2f s)\n", f, path, st.seconds);
    }
    if (!j->o->quiet)
        printf("rendered %d image%s into %s\n", nframes, nframes == 1 ? "" : "s", j->out_dir);
    return CS_EXIT_OK;
}
