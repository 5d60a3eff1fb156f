/* info_cmd.h: `clothsim info DIR`: a run folder's frames as a table
 * (time, status, intersecting pairs, energy, speed) and DIR/info.png. */
#ifndef CS_APP_INFO_CMD_H
#define CS_APP_INFO_CMD_H

#include <stdio.h>

#include <stddef.h>

int cs_info_main(int argc, char **argv);
void cs_info_help(FILE *out);

/* What DIR/info.png shows: n values of each series at times t (NaN where
 * there is none). */
typedef struct cs_info_figure {
    const char *title;
    int n;
    const double *t, *pairs, *kinetic, *potential, *total, *max_speed, *fd_speed;
} cs_info_figure;

/* Draws the figure into path with PLplot (pngcairo, 900 x 1100: pairs,
 * energies, speeds), written atomically. Returns 0, or -1 with err
 * (info_plot.c). */
int cs_info_plot(const char *path, const cs_info_figure *figure, char *err, size_t errlen);

#endif
