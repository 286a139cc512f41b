/* cJSON's parser records its last error position in a process-wide variable, so parses on
 * different threads race on it. Every cJSON parse in the daemon runs under this lock. */
#ifndef SKYD_JSON_GUARD_H
#define SKYD_JSON_GUARD_H

void json_guard_lock(void);
void json_guard_unlock(void);

#endif
