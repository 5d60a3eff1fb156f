/* progress.h: the per-frame progress display of `clothsim run`.
 *
 * On a terminal it is one line redrawn with '\r':
 *   [#####...............] frame 12/48  t=0.500 s  3.2 s/frame  ETA 1m55s
 * elsewhere (a log file, a pipe) one plain line per frame. Disabled, it
 * prints nothing.
 */
#ifndef CS_APP_PROGRESS_H
#define CS_APP_PROGRESS_H

#include <stdbool.h>
#include <stdio.h>

typedef struct cs_progress {
    FILE *out;
    bool enabled;
    bool tty;           /* redraw one line instead of printing lines */
    bool line_open;     /* a redrawn line is on screen without its newline */
    int total;          /* the run's last frame */
    int first;          /* the frame this process starts after (a resume's) */
    int last_len;       /* length of the line on screen, to blank leftovers */
} cs_progress;

/* Shows progress on out unless quiet; tty decides the style. The rate and
 * the ETA count the frames after first_frame (0, or where a resume starts). */
void cs_progress_init(cs_progress *p, FILE *out, bool quiet, int first_frame, int total_frames);

/* Frame `frame` of total is done at simulated time sim_time (s); elapsed is
 * the wall time (s) spent on the frames so far, for the rate and the ETA.
 * The first frame (before any is simulated) shows the bar on a terminal only. */
void cs_progress_frame(cs_progress *p, int frame, double sim_time, double elapsed);

/* Ends a redrawn line so that other messages start on a fresh one. */
void cs_progress_finish(cs_progress *p);

/* "1m55s", "12s", "2h05m": a duration for people. */
void cs_format_duration(double seconds, char *buf, size_t len);

#endif
