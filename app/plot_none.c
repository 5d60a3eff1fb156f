/* plot_none.c: the pictures of `clothsim sweep` and `clothsim info` in a
 * build without PLplot (-DCLOTHSIM_WITH_PLPLOT=OFF), in place of
 * sweep_plot.c and info_plot.c: sweep refuses before it runs anything,
 * info draws nothing but its table with --no-plot, each with this sentence
 * and exit status 4. */
#include "app/info_cmd.h"
#include "app/sweep_cmd.h"

#include "common/error.h"
#include "common/util.h"

#define NO_PLPLOT \
    CS_MISSING_PART("PLplot", "the pictures of sweep and info need it", "CLOTHSIM_WITH_PLPLOT")

int cs_plot_available(char *why, size_t whylen)
{
    cs_errorf(why, whylen, "%s", NO_PLPLOT);
    return -1;
}

bool cs_plot_has_pngcairo(void) { return false; }

int cs_plot_open(const char *tmp, int width, int height, char *why, size_t whylen)
{
    (void)tmp, (void)width, (void)height;
    return cs_plot_available(why, whylen);
}

int cs_sweep_plot(const char *path, const cs_sweep_figure *figure, char *err, size_t errlen)
{
    (void)path, (void)figure;
    return cs_plot_available(err, errlen);
}

int cs_info_plot(const char *path, const cs_info_figure *figure, char *err, size_t errlen)
{
    (void)path, (void)figure;
    return cs_plot_available(err, errlen);
}
