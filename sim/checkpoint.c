/* checkpoint.c: the state a frame's end leaves for the next frames, as
 * arrays a caller stores and gives back (`clothsim run --resume`).
 *
 * What a step reads that an earlier step wrote, and so what is listed:
 * - time t (the scripts' and bodies' poses, the frame count);
 * - positions x and velocities v (everything starts from them);
 * - the CG warm starts of B.1 and B.5 (cs_cg_solve adds a blend of the
 *   last two solves' damping responses to its start, for B.5 their excess
 *   over B.1's: the iterations, and so the bits of the result, depend on
 *   them);
 * - with self-collision, the collision-free positions x_free (step A's
 *   pairs and step C's trajectories start there; equal to x at a frame
 *   end, stored anyway so nothing is inferred);
 * - with scripts, how far each script's clock is behind (step C holds a
 *   script back where an impact zone spans two of them).
 * Everything else is rewritten before it is read within a step or an outer
 * collision step, which never straddles a frame end: modes, contacts,
 * script targets, wind normals, spring directions, the preconditioner,
 * repulsion pairs, tree boxes (the tree topology comes from the initial
 * positions at creation), impact zones, the rewind copy, and the counters,
 * which frames report as differences. */
#include <stdlib.h>
#include <string.h>

#include "sim/internal.h"

int cs_sim_state_arrays(cs_sim *sim, cs_state_array *a)
{
    size_t n3 = 3 * (size_t)sim->n;
    int k = 0;
    a[k++] = (cs_state_array){"time", 1, &sim->t};
    a[k++] = (cs_state_array){"positions", n3, sim->x};
    a[k++] = (cs_state_array){"velocities", n3, sim->v};
    a[k++] = (cs_state_array){"cg/warm_half", n3, sim->cg.warm_half};
    a[k++] = (cs_state_array){"cg/warm_full_less_half", n3, sim->cg.warm_full_less_half};
    a[k++] = (cs_state_array){"cg/warm_half_before", n3, sim->cg.warm_half_before};
    a[k++] = (cs_state_array){"cg/warm_full_less_half_before", n3, sim->cg.warm_full_less_half_before};
    if (sim->selfcol)
        a[k++] = (cs_state_array){"self_collision/x_free", n3, sim->selfcol->x_free};
    if (sim->nscripts > 0)
        a[k++] = (cs_state_array){"scripts/lag", (size_t)sim->nscripts, sim->script_lag};
    return k;
}

void cs_sim_state_gather(cs_sim *sim)
{
    /* x and v reached rank 0 at the frame's end and x_free is the same on
     * every rank; the warm starts are kept where owned. Only rank 0's
     * copies of others' entries change, which it never reads. The
     * messages are the output's, so the stages' counts are kept. */
    cs_comm_stats saved[CS_STAGE_COUNT];
    memcpy(saved, sim->par->stats, sizeof saved);
    cs_par_gather_root(sim->par, sim->cg.warm_half, 3);
    cs_par_gather_root(sim->par, sim->cg.warm_full_less_half, 3);
    cs_par_gather_root(sim->par, sim->cg.warm_half_before, 3);
    cs_par_gather_root(sim->par, sim->cg.warm_full_less_half_before, 3);
    memcpy(sim->par->stats, saved, sizeof saved);
}

int cs_sim_state_scatter(cs_sim *sim)
{
    cs_par *par = sim->par;
    if (par->size == 1)
        return CS_OK;
    cs_comm_stats saved[CS_STAGE_COUNT];
    memcpy(saved, par->stats, sizeof saved);
    cs_state_array a[CS_STATE_MAX_ARRAYS];
    int na = cs_sim_state_arrays(sim, a), status = CS_OK;
    for (int k = 0; k < na; k++) {
        /* rank 0 gives its values, the others nothing: a broadcast */
        void *all = NULL;
        int nall = 0;
        int failed = cs_par_allgather_items(par, a[k].data, par->rank == 0 ? (int)a[k].count : 0,
                                            sizeof(double), &all, &nall) != 0 ||
                     (size_t)nall != a[k].count;
        if (!failed)
            memcpy(a[k].data, all, sizeof(double) * a[k].count);
        free(all);
        double bad = failed;
        cs_par_max(par, &bad, 1);
        if (bad != 0) {
            status = CS_ERR_NOMEM;
            break;
        }
    }
    memcpy(par->stats, saved, sizeof saved);
    return status;
}
