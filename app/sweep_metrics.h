/* sweep_metrics.h: what `clothsim sweep` measures of one run folder: its
 * counters (from summary.json) and its error against the reference run's
 * folder, frame by frame (from the frame files).
 *
 * Errors, all in metres, per frame and overall (the maximum over frames):
 *   vertex_rms, vertex_max  RMS and largest distance between corresponding
 *                           vertices; only when every cloth has the same
 *                           vertex count in both runs (else NaN)
 *   com                     distance between the centres of mass of the
 *                           cloth surfaces (area-weighted centroids: uniform
 *                           density), no correspondence needed
 *   bbox                    largest difference of the 6 bounds of the
 *                           axis-aligned bounding boxes
 *   hausdorff               two-sided Hausdorff distance between the surfaces:
 *                           the largest distance from a vertex of one to the
 *                           triangles of the other, both ways (a grid of
 *                           triangles keeps it O(n) per frame)
 *   analytic                with --analytic incline only: distance from the
 *                           run's centre of mass (as com) to where the
 *                           analytic rigid body (common/incline.h) would be
 *                           (else NaN)
 */
#ifndef CS_APP_SWEEP_METRICS_H
#define CS_APP_SWEEP_METRICS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "app/outdir.h"
#include "common/incline.h"
#include "sim/sim.h"

/* How tight a knob's value is, for the table of sweep_cmd.c: whether key
 * matches pattern ('*' standing for a whole number), and a value's measure
 * (its number, or the product of a list's: "[40,40]" is 1600; NaN unless
 * numbers > 0). */
bool cs_sweep_key_matches(const char *pattern, const char *key);
double cs_sweep_measure(const char *value);

/* Counters of a finished run, from DIR/summary.json ("frames" summed). */
typedef struct cs_sweep_counts {
    char status[16];          /* summary's status: "ok", "unstable", ... */
    int frames_written;       /* frame files, frame 0 included */
    long steps, cg_iterations, collisions, impact_zones; /* sums over frames */
    long intersections;       /* largest over frames; -1: not counted (verify off) */
    double penetration;       /* largest body penetration, m; -1: no bodies */
    int nseconds;             /* frames simulated (1..), each its ... */
    double *seconds;          /* ... wall seconds ("seconds" of each frame's
                                 record, as in frames.jsonl); owned */
} cs_sweep_counts;

/* Reads DIR/summary.json. Returns 0, or -1 with err. */
int cs_sweep_read_counts(const char *dir, cs_sweep_counts *c, char *err, size_t errlen);

void cs_sweep_counts_free(cs_sweep_counts *c);

/* --analytic incline: the rigid body the cloth should follow. */
typedef struct cs_sweep_analytic {
    cs_incline motion;   /* the slope, mu and the initial speed along it */
    double down[3];      /* unit vector downhill along the slope */
    double fps;          /* frame f is at time f / fps */
} cs_sweep_analytic;

/* The incline of a scene: its one plane body (constant friction), gravity,
 * and the cloths' initial velocity (the same for all; its component across
 * the slope is not modelled). Returns 0, or -1 with err saying what the
 * scene lacks. */
int cs_sweep_analytic_init(const cs_sim_def *def, cs_sweep_analytic *an, char *err,
                           size_t errlen);

/* The error metrics (metres); NaN where not applicable. */
typedef struct cs_sweep_error {
    double vertex_rms, vertex_max, com, bbox, hausdorff, analytic;
} cs_sweep_error;

/* The headline error of a run (what sweep.png draws): analytic when it was
 * measured, else vertex_max when the vertices correspond, else hausdorff. */
double cs_sweep_error_headline(const cs_sweep_error *e);

/* Compares the frames of the run in dir with those of the reference run in
 * ref_dir, frame by frame over the frames both have (the layout says how a
 * frame holds its cloths), writing one line per frame to per_frame (CSV,
 * header included; NULL: none) and the maximum over frames to *overall.
 * With an (else NULL) also the analytic error, and per frame the distance
 * travelled downhill by the run's centre of mass and by the analytic body
 * (columns analytic_m, travel_m, travel_analytic_m; the run's into
 * travel[f] when travel is not NULL). Returns 0, or an exit status
 * (CS_EXIT_INPUT: a frame unreadable, CS_EXIT_OUTPUT: out of memory) with
 * err. */
int cs_sweep_compare(const cs_frame_layout *layout, const char *dir, const char *ref_dir,
                     int frames, const cs_sweep_analytic *an, FILE *per_frame, double *travel,
                     cs_sweep_error *overall, char *err, size_t errlen);

#endif
