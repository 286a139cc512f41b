#include "json_guard.h"

#include <pthread.h>

static pthread_mutex_t json_parse_lock = PTHREAD_MUTEX_INITIALIZER;

void json_guard_lock(void)
{
    pthread_mutex_lock(&json_parse_lock);
}

void json_guard_unlock(void)
{
    pthread_mutex_unlock(&json_parse_lock);
}
