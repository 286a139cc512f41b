/* UTC time stamps: ISO 8601 text to and from seconds since 1970-01-01T00:00:00Z (POSIX, no
 * leap seconds). Pure functions. */
#ifndef SKYD_UTC_TIME_H
#define SKYD_UTC_TIME_H

#include <stdbool.h>
#include <stddef.h>

/* "YYYY-MM-DDThh:mm[:ss[.f...]](Z|+hh:mm|-hh:mm)", with a space allowed instead of the T.
 * On failure returns false and writes the reason to err. */
bool proto_time_parse_iso8601(const char *text, double *unix_seconds, char *err, size_t errlen);
/* "2026-06-21T12:00:00Z", with ".mmm" before the Z when the milliseconds are not zero. */
void proto_time_format_iso8601(double unix_seconds, char *out, size_t outlen);

#endif
