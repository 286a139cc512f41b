#include "encoder_pool.h"

#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>
#include <time.h>

#include "jpeg_write.h"
#include "png_write.h"

struct queued_job {
    struct queued_job *next;
    struct encode_job job;
};

struct encoder_pool {
    pthread_mutex_t lock;
    pthread_cond_t work;
    struct queued_job *head, *tail;
    int queued, running;
    bool stopping;
    struct session_hub *hub;
    struct encoder_pool_callbacks callbacks;
    int thread_count;
    pthread_t threads[];
};

static void deliver(struct encoder_pool *pool, struct encode_job *job, struct encoded_frame *frame)
{
    for (size_t i = 0; i < job->target_count; i++) {
        struct encode_target *t = &job->targets[i];
        if (t->subscription)
            session_slot_deliver(t->session, t->subscription, frame);
        else if (frame)
            session_snapshot_deliver(t->session, &t->snapshot_id, frame);
        else if (session_snapshot_fail(t->session, &t->snapshot_id,
                                       "encoding the frame failed (out of memory, or the "
                                       "daemon is stopping)"))
            pool->callbacks.failed(pool->callbacks.failed_user);
        session_unref(&t->session);
    }
    free(job->targets);
    free(job->pixels);
    job->targets = NULL;
    job->pixels = NULL;
}

static void run_job(struct encoder_pool *pool, struct encode_job *job)
{
    uint8_t *encoded_bytes = NULL;
    size_t length = 0;
    struct encoded_frame *frame = NULL;
    uint32_t width = job->meta.width, height = job->meta.height;
    int encoded = -1;
    if (job->meta.format == PROTO_FRAME_FORMAT_PNG16) {
        uint16_t *rgb = malloc((size_t)width * height * 3 * sizeof *rgb);
        if (rgb) {
            png_linear16_quantize(job->pixels, (size_t)width * height, job->full_scale_cd_m2, rgb);
            encoded = png_encode_linear16(rgb, width, height, job->full_scale_cd_m2,
                                          PNG_EFFORT_STREAM, &encoded_bytes, &length);
        }
        free(rgb);
    } else if (job->meta.format == PROTO_FRAME_FORMAT_JPEG) {
        encoded = jpeg_encode_rgba8(job->pixels, width, height, job->quality, &encoded_bytes,
                                    &length);
    } else {
        encoded = png_encode_rgba8(job->pixels, width, height, PNG_EFFORT_STREAM, &encoded_bytes,
                                   &length);
    }
    if (encoded == 0)
        frame = encoded_frame_create(&job->meta, encoded_bytes, length);
    free(encoded_bytes);
    deliver(pool, job, frame);
    encoded_frame_unref(&frame);
}

static void *worker(void *arg)
{
    struct encoder_pool *pool = arg;
    pthread_mutex_lock(&pool->lock);
    for (;;) {
        while (!pool->head && !pool->stopping)
            pthread_cond_wait(&pool->work, &pool->lock);
        if (pool->stopping)
            break;
        struct queued_job *q = pool->head;
        pool->head = q->next;
        if (!pool->head)
            pool->tail = NULL;
        pool->queued--;
        pool->running++;
        pthread_mutex_unlock(&pool->lock);
        run_job(pool, &q->job);
        free(q);
        session_hub_wake(pool->hub);
        pthread_mutex_lock(&pool->lock);
        pool->running--;
        pthread_mutex_unlock(&pool->lock);
        pool->callbacks.done(pool->callbacks.done_user);
        pthread_mutex_lock(&pool->lock);
    }
    pthread_mutex_unlock(&pool->lock);
    return NULL;
}

struct encoder_pool *encoder_pool_create(int threads, struct session_hub *hub,
                                         const struct encoder_pool_callbacks *callbacks)
{
    struct encoder_pool *pool = calloc(1, sizeof *pool + sizeof(pthread_t) * (size_t)threads);
    if (!pool)
        return NULL;
    pthread_mutex_init(&pool->lock, NULL);
    pthread_cond_init(&pool->work, NULL);
    pool->hub = hub;
    pool->callbacks = *callbacks;
    for (int i = 0; i < threads; i++) {
        if (pthread_create(&pool->threads[i], NULL, worker, pool) != 0)
            break;
        pool->thread_count++;
    }
    if (pool->thread_count == 0) {
        encoder_pool_destroy(&pool);
        return NULL;
    }
    return pool;
}

void encoder_pool_destroy(struct encoder_pool **pool_ptr)
{
    struct encoder_pool *pool = *pool_ptr;
    *pool_ptr = NULL;
    if (!pool)
        return;
    pthread_mutex_lock(&pool->lock);
    pool->stopping = true;
    pthread_cond_broadcast(&pool->work);
    pthread_mutex_unlock(&pool->lock);
    for (int i = 0; i < pool->thread_count; i++)
        pthread_join(pool->threads[i], NULL);
    while (pool->head) {
        struct queued_job *q = pool->head;
        pool->head = q->next;
        deliver(pool, &q->job, NULL);
        free(q);
    }
    pthread_cond_destroy(&pool->work);
    pthread_mutex_destroy(&pool->lock);
    free(pool);
}

void encoder_pool_submit(struct encoder_pool *pool, struct encode_job *job)
{
    struct queued_job *q = calloc(1, sizeof *q);
    if (!q) {
        deliver(pool, job, NULL);
        return;
    }
    q->job = *job;
    pthread_mutex_lock(&pool->lock);
    if (pool->tail)
        pool->tail->next = q;
    else
        pool->head = q;
    pool->tail = q;
    pool->queued++;
    pthread_cond_signal(&pool->work);
    pthread_mutex_unlock(&pool->lock);
}

int encoder_pool_backlog(struct encoder_pool *pool)
{
    pthread_mutex_lock(&pool->lock);
    int n = pool->queued + pool->running;
    pthread_mutex_unlock(&pool->lock);
    return n;
}
