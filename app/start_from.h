/* start_from.h: `clothsim run SCENE --start-from RUN`: a run that begins
 * where another run ended, its cloth carried onto this scene's cloth of
 * the same rest shape (the same sheet at another resolution, most often).
 *
 * The state at RUN's last frame N (positions, velocities, the scripts'
 * lags, the time) is mapped onto this scene's cloths through their rest
 * shapes (cs_surface_map); frames 1 to N of the new folder are RUN's
 * frames carried over the same way, so the folder renders, exports and
 * resumes like any other, every frame at its own time; their records say
 * "resampled_from" and were not simulated. The run then simulates frames
 * N + 1 to time.frames. */
#ifndef CS_APP_START_FROM_H
#define CS_APP_START_FROM_H

#include <stddef.h>

#include "import/import.h"
#include "sim/sim.h"

typedef struct cs_start_from cs_start_from;

/* Rank 0: reads the run folder dir (its scene.yaml, summary.json, state.h5
 * and frames) for a run of scene and maps its cloths onto scene's.
 * Refused with err (CS_EXIT_INPUT) when dir is no run folder, its frame
 * rate or cloths differ, a cloth's rest shape is not the same, or its last
 * frame is after scene->frames; CS_EXIT_OUTPUT when unreadable. */
int cs_start_from_open(const char *dir, const cs_scene *scene, cs_start_from **out, char *err,
                       size_t errlen);
void cs_start_from_close(cs_start_from *s);

/* The run's last frame, N */
int cs_start_from_frame(const cs_start_from *s);

/* Rank 0: sim's state arrays hold frame f (1 <= f < N) of the run, its
 * positions read from the frame files and carried over, velocities zero
 * (a frame file has none); at f = N the state itself: positions,
 * velocities, the collision-free positions, the scripts' lags and the time.
 * Returns 0, or an exit status with err. */
int cs_start_from_load_frame(const cs_start_from *s, int f, cs_sim *sim, char *err,
                             size_t errlen);

#endif
