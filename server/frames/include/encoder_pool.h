/* PNG and JPEG encoder workers: turn rendered frames into encoded frames off the render thread
 * and hand each to the sessions that asked for it (subscription slots and snapshots). */
#ifndef SKYD_ENCODER_POOL_H
#define SKYD_ENCODER_POOL_H

#include <stddef.h>
#include <stdint.h>

#include "encoded_frame.h"
#include "messages.h"
#include "session.h"

struct encode_target {
    struct session *session; /* a reference, released by the pool */
    uint64_t subscription;   /* >= 1; 0 for a snapshot */
    struct proto_msg_id snapshot_id;
};

struct encode_job {
    /* width x height texels owned by the job: RGBA8 (4 bytes) for meta.format PNG and JPEG, the
     * renderer's LINEAR RGBA floats (16 bytes) for PNG16 */
    void *pixels;
    struct encoded_frame_meta meta;
    double full_scale_cd_m2;       /* PNG16: the luminance of the largest sample */
    int quality;                   /* JPEG: 1..100 */
    struct encode_target *targets; /* owned by the job */
    size_t target_count;
};

struct encoder_pool;

/* What the pool tells its owner. done(done_user) is called from a worker after each job (the
 * render thread waits on it to start the next frame of a busy subscription). failed(failed_user)
 * is called for each snapshot answered with an `internal` error instead of its frame, from a
 * worker or, for a job that never ran, from encoder_pool_submit or encoder_pool_destroy. */
struct encoder_pool_callbacks {
    void (*done)(void *user);
    void *done_user;
    void (*failed)(void *user);
    void *failed_user;
};

struct encoder_pool *encoder_pool_create(int threads, struct session_hub *hub,
                                         const struct encoder_pool_callbacks *callbacks);
/* Stops the workers; jobs not started are delivered as failures. */
void encoder_pool_destroy(struct encoder_pool **pool);

/* Takes ownership of the job's buffers (and releases them even when it fails). */
void encoder_pool_submit(struct encoder_pool *pool, struct encode_job *job);
/* Jobs queued or being encoded. */
int encoder_pool_backlog(struct encoder_pool *pool);

#endif
