/* render_turntable.c: `clothsim render --turntable N`: N views of one
 * frame orbiting the scene's centre, a contact sheet of them, and their
 * animation when ffmpeg is installed. */
#include "app/render_cmd_internal.h"

#include "app/exit.h"
#include "app/scene_render.h"
#include "render/render.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* view_<digits>.png of an earlier turntable would join this one's animation. */
static int remove_old_views(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int rc = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *s = e->d_name;
        if (strncmp(s, "view_", 5) != 0 || s[5] < '0' || s[5] > '9')
            continue;
        s += 5;
        while (*s >= '0' && *s <= '9')
            s++;
        if (strcmp(s, ".png") != 0)
            continue;
        char path[4400];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (unlink(path) != 0) {
            fprintf(stderr, "clothsim render: cannot remove the old view %s: %s\n", path,
                    strerror(errno));
            rc = -1;
            break;
        }
    }
    closedir(d);
    return rc;
}

int cs_render_cmd_turntable(render_job *j, int f)
{
    char err[ERRLEN];
    int n = j->o->turntable;
    if (remove_old_views(j->out_dir) != 0)
        return CS_EXIT_OUTPUT;
    int status = cs_render_cmd_get_frame(j, f, err, sizeof err);
    if (status != CS_EXIT_OK) {
        fprintf(stderr, "clothsim render: frame %d: %s\n", f, err);
        return status;
    }
    double t = f / j->fps, centre[3];
    cs_scene_render_centre(j->sr, t, &j->geom.cloths, centre);
    cs_render_camera cam = cs_scene_render_camera(j->sr, t);
    int thumb = j->image->width < 200 ? j->image->width : 200;
    cs_image **thumbs = calloc((size_t)n, sizeof *thumbs);
    char (*labels)[48] = calloc((size_t)n, sizeof *labels);
    const char **label_ptrs = calloc((size_t)n, sizeof *label_ptrs);
    if (!thumbs || !labels || !label_ptrs) {
        fprintf(stderr, "clothsim render: out of memory\n");
        status = CS_EXIT_OUTPUT;
    }
    for (int k = 0; k < n && status == CS_EXIT_OK; k++) {
        double angle = 2 * M_PI * k / n;
        cs_render_camera view =
            cs_render_camera_orbit(&cam, centre, cs_scene_render_up(j->sr), angle);
        cs_render_stats st;
        status = cs_scene_render_draw(j->sr, t, &j->geom.cloths, &view, j->image, &st, err,
                                      sizeof err);
        if (status != CS_EXIT_OK) {
            fprintf(stderr, "clothsim render: frame %d, view %d: %s\n", f, k, err);
            break;
        }
        char path[4200];
        snprintf(path, sizeof path, "%s/view_%03d.png", j->out_dir, k);
        if (cs_image_write_png(j->image, path, err, sizeof err) != CS_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            status = CS_EXIT_OUTPUT;
            break;
        }
        if (!(thumbs[k] = cs_image_shrink(j->image, thumb))) {
            fprintf(stderr, "clothsim render: out of memory\n");
            status = CS_EXIT_OUTPUT;
            break;
        }
        snprintf(labels[k], sizeof labels[k], "frame %d, %.0f\u00b0", f, angle * 180 / M_PI);
        label_ptrs[k] = labels[k];
        if (!j->o->quiet)
            printf("view %d: %s (%.2f s)\n", k, path, st.seconds);
    }
    if (status == CS_EXIT_OK) {
        char path[4200];
        snprintf(path, sizeof path, "%s/contact_sheet.png", j->out_dir);
        int cols = n <= 4 ? n : n <= 8 ? 4 : (int)ceil(sqrt((double)n));
        if (cs_render_contact_sheet(path, n, (const cs_image *const *)thumbs, label_ptrs, cols,
                                    thumb, err, sizeof err) != CS_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            status = CS_EXIT_OUTPUT;
        } else if (!j->o->quiet) {
            printf("contact sheet: %s\n", path);
        }
    }
    if (status == CS_EXIT_OK && n > 1) {
        /* Only if ffmpeg is installed; without it the sheet is the result. */
        char pattern[8800];
        bool made;
        if (cs_render_cmd_image_pattern(j->out_dir, "view_%03d.png", pattern, sizeof pattern) != 0)
            status = CS_EXIT_OUTPUT;
        else
            status = cs_render_cmd_make_animation(j, pattern, 0, n, 12.0, "turntable", &made);
    }
    for (int k = 0; thumbs && k < n; k++)
        cs_image_destroy(thumbs[k]);
    free(thumbs);
    free(labels);
    free(label_ptrs);
    return status;
}
