/* render_animation.c: numbered PNGs made into DIR/NAME.mp4 and NAME.gif
 * with the ffmpeg program, for --animation and for turntables. */
#include "app/render_cmd_internal.h"

#include "app/outdir.h"
#include "app/exit.h"
#include "render/render.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* dir/leaf as an ffmpeg image pattern: a '%' of dir doubled, leaf (which
 * holds the number's conversion) as it is. 0, or -1 when it does not fit. */
int cs_render_cmd_image_pattern(const char *dir, const char *leaf, char *out, size_t len)
{
    size_t k = 0;
    bool fits = true;
    for (const char *s = dir; *s && fits; s++) {
        fits = k + 3 < len;
        if (fits && *s == '%')
            out[k++] = '%';
        if (fits)
            out[k++] = *s;
    }
    int n = fits ? snprintf(out + k, len - k, "/%s", leaf) : -1;
    if (n < 0 || (size_t)n >= len - k) {
        fprintf(stderr, "clothsim render: the folder name %s is too long for ffmpeg\n", dir);
        return -1;
    }
    return 0;
}

/* The one way turntables and --animation make an animation: the PNGs that
 * pattern numbers first .. first + count - 1, at fps, become DIR/BASE.mp4
 * and DIR/BASE.gif through the ffmpeg program (cs_render_animation); the
 * files of an earlier animation of that name go first. *made is false when
 * ffmpeg is not installed. Returns 0, or CS_EXIT_OUTPUT when ffmpeg failed
 * (its message and ours said; the PNGs stay). */
int cs_render_cmd_make_animation(const render_job *j, const char *pattern, int first, int count,
                                 double fps, const char *base, bool *made)
{
    static const char *const exts[] = {"mp4", "gif"};
    *made = false;
    for (int e = 0; e < 2; e++) {
        char path[4300];
        snprintf(path, sizeof path, "%s/%s.%s", j->out_dir, base, exts[e]);
        if (unlink(path) != 0 && errno != ENOENT) {
            fprintf(stderr, "clothsim render: cannot remove the old %s: %s\n", path,
                    strerror(errno));
            return CS_EXIT_OUTPUT;
        }
    }
    for (int e = 0; e < 2; e++) {
        char path[4300], err[ERRLEN];
        snprintf(path, sizeof path, "%s/%s.%s", j->out_dir, base, exts[e]);
        int rc = cs_render_animation(pattern, first, count, fps, path, err, sizeof err);
        if (rc == 0)
            return CS_EXIT_OK;
        if (rc < 0) {
            fprintf(stderr, "clothsim render: %s; the images are kept in %s\n", err,
                    j->out_dir);
            return CS_EXIT_OUTPUT;
        }
        *made = true;
        if (!j->o->quiet)
            printf("animation: %s\n", path);
    }
    return CS_EXIT_OK;
}

/* Links DIR/frame_NNNN.png of the listed frames as TMPDIR/000000.png, ... in
 * their order (a hard link, else a symbolic one): what ffmpeg's numbered
 * input needs when the frames are not consecutive. Returns how many were
 * linked (all on success); the caller removes them. */
static int link_frames(const char *dir, const char *tmpdir, const int *frames, int nframes)
{
    for (int k = 0; k < nframes; k++) {
        char from[4200], to[4200], rel[64];
        cs_frame_path(from, sizeof from, dir, frames[k], NULL, "png");
        snprintf(to, sizeof to, "%s/%06d.png", tmpdir, k);
        cs_frame_path(rel, sizeof rel, "..", frames[k], NULL, "png");
        if (link(from, to) != 0 && symlink(rel, to) != 0) {
            fprintf(stderr, "clothsim render: cannot link %s as %s: %s\n", from, to,
                    strerror(errno));
            return k;
        }
    }
    return nframes;
}

/* --animation: the frames just rendered, in the order listed, at the run's
 * frames per second. */
int cs_render_cmd_animation(render_job *j, const int *frames, int nframes)
{
    bool consecutive = true;
    for (int k = 1; k < nframes; k++)
        consecutive = consecutive && frames[k] == frames[0] + k;
    char pattern[8800], tmpdir[4300] = "";
    int status = CS_EXIT_OK, linked = 0;
    bool made = false;
    if (consecutive) {
        if (cs_render_cmd_image_pattern(j->out_dir, "frame_%04d.png", pattern, sizeof pattern) != 0)
            status = CS_EXIT_OUTPUT;
        else
            status = cs_render_cmd_make_animation(j, pattern, frames[0], nframes, j->fps,
                                                  "animation", &made);
    } else {
        snprintf(tmpdir, sizeof tmpdir, "%s/.animation.XXXXXX", j->out_dir);
        if (!mkdtemp(tmpdir)) {
            fprintf(stderr, "clothsim render: cannot create %s: %s\n", tmpdir, strerror(errno));
            return CS_EXIT_OUTPUT;
        }
        linked = link_frames(j->out_dir, tmpdir, frames, nframes);
        if (linked < nframes)
            status = CS_EXIT_OUTPUT;
        else if (cs_render_cmd_image_pattern(tmpdir, "%06d.png", pattern, sizeof pattern) != 0)
            status = CS_EXIT_OUTPUT;
        else
            status = cs_render_cmd_make_animation(j, pattern, 0, nframes, j->fps, "animation",
                                                  &made);
        for (int k = 0; k < linked; k++) {
            char path[4400];
            snprintf(path, sizeof path, "%s/%06d.png", tmpdir, k);
            unlink(path);
        }
        rmdir(tmpdir);
    }
    if (status == CS_EXIT_OK && !made)
        fprintf(stderr, "clothsim render: no animation: ffmpeg is not installed (not on the "
                        "PATH); the %d PNG frame%s %s in %s\n", nframes,
                nframes == 1 ? "" : "s", nframes == 1 ? "is" : "are", j->out_dir);
    return status;
}
