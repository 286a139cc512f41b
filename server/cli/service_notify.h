/* The service manager's side of the daemon (systemd's sd_notify protocol, Type=notify):
 * READY=1 once the daemon listens, RELOADING=1 and READY=1 around a configuration reload,
 * STOPPING=1 at shutdown, STATUS= lines, and the watchdog's WATCHDOG=1 every half of
 * WATCHDOG_USEC while the daemon is healthy. Without NOTIFY_SOCKET every call does nothing. */
#ifndef SKYD_SERVICE_NOTIFY_H
#define SKYD_SERVICE_NOTIFY_H

#include <stdbool.h>
#include <stddef.h>

struct service_notify;

/* `healthy` (called from the watchdog thread) says whether to ping, and why not in `why`.
 * NULL only when memory or the thread is out; without a watchdog no thread runs. */
struct service_notify *service_notify_create(bool (*healthy)(void *user, char *why, size_t len),
                                             void *user);
/* Stops the watchdog thread. */
void service_notify_destroy(struct service_notify **notify);

void service_notify_ready(struct service_notify *notify, const char *status);
void service_notify_reloading(struct service_notify *notify);
void service_notify_stopping(struct service_notify *notify);

/* Whether a service manager listens (NOTIFY_SOCKET is set). */
bool service_notify_active(const struct service_notify *notify);

#endif
