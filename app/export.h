/* export.h: a run folder's frames as files other programs open as one
 * animation: DIR/cloth.usda (USD, for Blender, Houdini, usdview) and
 * Blender point caches, DIR/pc2/NAME.pc2 beside their rest pose
 * DIR/pc2/NAME.obj. Written at the end of `clothsim run` (output.usd,
 * output.pc2) and by `clothsim export DIR`.
 *
 * Both are made from the frame files on disk, read one frame at a time
 * (cs_frame_read, as `render` and `info` read them), so they hold exactly
 * the frames' float32 values and memory holds one frame whatever the run's
 * length. cloth.usda keeps each cloth's time samples in one block, so
 * they are gathered in a temporary file per cloth and joined at the end;
 * every file appears atomically (NAME.tmp, then renamed). */
#ifndef CS_APP_EXPORT_H
#define CS_APP_EXPORT_H

#include <stdbool.h>
#include <stdio.h>

#include "import/import.h"

typedef struct cs_export_what {
    bool usd;   /* DIR/cloth.usda */
    bool pc2;   /* DIR/pc2/NAME.pc2 and NAME.obj per cloth */
} cs_export_what;

/* Writes what from frames 0 .. nframes-1 of the run folder dir, whose
 * frames are files of format made from scene (its cloths, bodies, colours
 * and motions) at fps. Names each file written on out (NULL: silent).
 * Returns an exit status (CS_EXIT_INPUT: a frame missing, unreadable or not
 * the scene's; CS_EXIT_OUTPUT: a file could not be written) with err. */
int cs_export_run(const cs_scene *scene, cs_mesh_format format, const char *dir, int nframes,
                  double fps, cs_export_what what, FILE *out, char *err, size_t errlen);

/* The USD file's up axis for scene: "Z" when the scene's camera up (or,
 * without a camera, the direction against gravity) lies mostly along z,
 * else "Y". */
const char *cs_export_up_axis(const cs_scene *scene);

#endif
