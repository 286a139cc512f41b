#include "cache_dir.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool fits(int n, size_t outlen)
{
    return n > 0 && (size_t)n < outlen;
}

bool skyd_cache_dir(char *out, size_t outlen)
{
    if (outlen == 0)
        return false;
    out[0] = '\0';
    const char *own = getenv("SKYD_CACHE_DIR");
    const char *systemd = getenv("CACHE_DIRECTORY");
    const char *xdg = getenv("XDG_CACHE_HOME");
    const char *home = getenv("HOME");
    int n = 0;
    if (own)
        n = own[0] ? snprintf(out, outlen, "%s", own) : 0;
    else if (systemd && systemd[0])
        n = snprintf(out, outlen, "%.*s", (int)strcspn(systemd, ":"), systemd);
    else if (xdg && xdg[0] == '/')
        n = snprintf(out, outlen, "%s/skyd", xdg);
    else if (home && home[0] == '/')
        n = snprintf(out, outlen, "%s/.cache/skyd", home);
    if (!fits(n, outlen)) {
        out[0] = '\0';
        return false;
    }
    return true;
}
