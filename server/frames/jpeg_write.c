#include "jpeg_write.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <turbojpeg.h>

int jpeg_encode_rgba8(const uint8_t *rgba, uint32_t width, uint32_t height, int quality,
                      uint8_t **out, size_t *out_len)
{
    *out = NULL;
    *out_len = 0;
    if (!rgba || width == 0 || height == 0 || quality < JPEG_QUALITY_MIN ||
        quality > JPEG_QUALITY_MAX || width > (uint32_t)(INT32_MAX / 4) ||
        height > (uint32_t)INT32_MAX)
        return -1;
    tjhandle tj = tjInitCompress();
    if (!tj)
        return -1;
    unsigned char *jpeg = NULL;
    unsigned long jpeg_len = 0;
    /* TurboJPEG's own buffer, grown as needed; copied out so callers free() what they get. */
    int rc = tjCompress2(tj, rgba, (int)width, (int)width * 4, (int)height, TJPF_RGBA, &jpeg,
                         &jpeg_len, TJSAMP_420, quality, TJFLAG_FASTDCT);
    if (rc == 0) {
        *out = malloc(jpeg_len);
        if (*out) {
            memcpy(*out, jpeg, jpeg_len);
            *out_len = jpeg_len;
        } else {
            rc = -1;
        }
    }
    tjFree(jpeg);
    tjDestroy(tj);
    return rc == 0 ? 0 : -1;
}

int jpeg_write_rgba8_file(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height,
                          int quality, char *err, size_t errlen)
{
    uint8_t *jpeg;
    size_t jpeg_len;
    if (jpeg_encode_rgba8(rgba, width, height, quality, &jpeg, &jpeg_len) != 0) {
        snprintf(err, errlen, "cannot encode JPEG %s", path);
        return -1;
    }
    size_t n = strlen(path) + 32;
    char *tmp = malloc(n);
    if (!tmp) {
        free(jpeg);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    snprintf(tmp, n, "%s.tmp%ld", path, (long)getpid());
    int rc = -1;
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        snprintf(err, errlen, "cannot create %s: %s", tmp, strerror(errno));
    } else {
        bool written = fwrite(jpeg, 1, jpeg_len, f) == jpeg_len;
        if (fclose(f) != 0 || !written)
            snprintf(err, errlen, "cannot write JPEG %s: %s", tmp, strerror(errno));
        else if (rename(tmp, path) != 0)
            snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, path, strerror(errno));
        else
            rc = 0;
        if (rc != 0)
            unlink(tmp);
    }
    free(tmp);
    free(jpeg);
    return rc;
}
