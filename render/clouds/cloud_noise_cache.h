/* The cloud noise volumes kept on disk between runs: generating them takes lavapipe seconds at
 * every start (7 s of a daemon's 12 on two cores), reading them back a few milliseconds.
 *
 * A file holds the base, detail and curl images of one seed, made by one device from one
 * build of the noise shaders: its name carries a key over the seed, the image sizes, the
 * shaders' SPIR-V and the device's pipelineCacheUUID, so a file from other shaders or another
 * driver is never read. The payload is checked against a checksum; a short or damaged file is
 * ignored (and replaced by the next store). Files are written whole under a temporary name and
 * renamed into place, so daemons sharing the directory never read a half-written one; the
 * directory keeps the CLOUD_NOISE_CACHE_FILES newest. */
#ifndef SKYD_CLOUD_NOISE_CACHE_H
#define SKYD_CLOUD_NOISE_CACHE_H

#include <stdint.h>

struct vk_context;
struct cloud_noise;

#define CLOUD_NOISE_CACHE_FILES 8

/* Fills the noise's images for `seed` from dir's file when there is a whole one for this
 * device and these shaders: 0. -1 when there is none or it is damaged (said in the log at
 * warning level when damaged); the images are then untouched. */
int cloud_noise_cache_load(struct vk_context *ctx, struct cloud_noise *noise, const char *dir,
                           uint32_t seed);

/* Writes the noise's images (generated from `seed`) to dir, making dir if it does not exist,
 * and removes the oldest files past CLOUD_NOISE_CACHE_FILES. A failure is logged at warning
 * level and changes nothing else: the cache is only ever a shortcut. */
void cloud_noise_cache_store(struct vk_context *ctx, const struct cloud_noise *noise,
                             const char *dir, uint32_t seed);

#endif
