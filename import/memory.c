/* memory.c: what the machine has, and refusing what cannot fit before it
 * is allocated (level-set grids, cloth grids). */
#include "import/import.h"

#include <stdio.h>

double cs_memory_available(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    char line[256];
    double kb = 0;
    if (!f)
        return 0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1)
            break;
    fclose(f);
    return kb * 1024.0;
}

void cs_format_bytes(double b, char *buf, size_t len)
{
    if (b >= 1e12)
        snprintf(buf, len, "%.3g TB", b / 1e12);
    else if (b >= 1e9)
        snprintf(buf, len, "%.3g GB", b / 1e9);
    else if (b >= 1e6)
        snprintf(buf, len, "%.3g MB", b / 1e6);
    else
        snprintf(buf, len, "%.3g kB", b / 1e3);
}

bool cs_memory_fits(double need, char *why, size_t len)
{
    double have = cs_memory_available();
    /* three quarters: the rest of the process, the page cache, other jobs;
     * a sanity bound when /proc says nothing */
    if ((have > 0 && need > 0.75 * have) || (have <= 0 && need > 64e9)) {
        char n[32], h[32];
        cs_format_bytes(need, n, sizeof n);
        cs_format_bytes(have, h, sizeof h);
        snprintf(why, len, "would need about %s of memory, but %s is available", n,
                 have > 0 ? h : "unknown");
        return false;
    }
    return true;
}
