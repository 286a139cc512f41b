/* UTC time stamps as ISO 8601 text. Calendar arithmetic is our own (proleptic Gregorian),
 * independent of the C library and of TZ. */
#include "utc_time.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#define SECONDS_PER_DAY 86400.0

/* Days since 1970-01-01 of a proleptic Gregorian date: H. Hinnant, "chrono-Compatible Low-Level
 * Date Algorithms", days_from_civil. */
static long long days_from_civil(long long y, int m, int d)
{
    y -= m <= 2;
    long long era = (y >= 0 ? y : y - 399) / 400;
    long long yoe = y - era * 400;
    long long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
    long long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    return era * 146097 + doe - 719468;
}

/* The inverse: Hinnant, civil_from_days. */
static void civil_from_days(long long z, long long *y, int *m, int *d)
{
    z += 719468;
    long long era = (z >= 0 ? z : z - 146096) / 146097;
    long long doe = z - era * 146097;
    long long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    long long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    long long mp = (5 * doy + 2) / 153;
    *d = (int)(doy - (153 * mp + 2) / 5 + 1);
    *m = (int)(mp < 10 ? mp + 3 : mp - 9);
    *y = yoe + era * 400 + (*m <= 2);
}

static int days_in_month(int year, int month)
{
    static const int days[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
    bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    return month == 2 && leap ? 29 : days[month - 1];
}

static bool fail(char *err, size_t errlen, const char *format, ...)
{
    if (err && errlen) {
        va_list ap;
        va_start(ap, format);
        vsnprintf(err, errlen, format, ap);
        va_end(ap);
    }
    return false;
}

/* Exactly n ASCII digits at *p. */
static bool take_digits(const char **p, int n, int *value)
{
    int v = 0;
    for (int i = 0; i < n; i++) {
        if (!isdigit((unsigned char)(*p)[i]))
            return false;
        v = v * 10 + ((*p)[i] - '0');
    }
    *p += n;
    *value = v;
    return true;
}

static bool take_char(const char **p, char c)
{
    if (**p != c)
        return false;
    (*p)++;
    return true;
}

#define FORMAT_HINT "YYYY-MM-DDThh:mm[:ss[.fff]] and Z or +hh:mm"

bool proto_time_parse_iso8601(const char *text, double *unix_seconds, char *err, size_t errlen)
{
    if (!text || !*text)
        return fail(err, errlen, "empty time (expected " FORMAT_HINT ")");
    const char *p = text;
    int year, month, day, hour, minute, second = 0;
    if (!take_digits(&p, 4, &year) || !take_char(&p, '-') || !take_digits(&p, 2, &month) ||
        !take_char(&p, '-') || !take_digits(&p, 2, &day))
        return fail(err, errlen, "expected a date YYYY-MM-DD at the start (" FORMAT_HINT ")");
    if (month < 1 || month > 12)
        return fail(err, errlen, "month %02d is out of range 01..12", month);
    if (day < 1 || day > days_in_month(year, month))
        return fail(err, errlen, "day %02d is out of range for %04d-%02d", day, year, month);
    if (!take_char(&p, 'T') && !take_char(&p, 't') && !take_char(&p, ' '))
        return fail(err, errlen, "expected 'T' and a time hh:mm after the date (" FORMAT_HINT ")");
    if (!take_digits(&p, 2, &hour) || !take_char(&p, ':') || !take_digits(&p, 2, &minute))
        return fail(err, errlen, "expected a time hh:mm after the date (" FORMAT_HINT ")");
    double fraction = 0.0;
    if (take_char(&p, ':')) {
        if (!take_digits(&p, 2, &second))
            return fail(err, errlen, "expected two digits of seconds after hh:mm:");
        if (take_char(&p, '.')) {
            int digits = 0;
            for (double scale = 0.1; isdigit((unsigned char)*p); p++, digits++, scale /= 10.0)
                fraction += (*p - '0') * scale;
            if (digits == 0 || digits > 9)
                return fail(err, errlen, "expected 1 to 9 digits of fractional seconds");
        }
    }
    if (hour > 23)
        return fail(err, errlen, "hour %02d is out of range 00..23", hour);
    if (minute > 59)
        return fail(err, errlen, "minute %02d is out of range 00..59", minute);
    if (second > 59)
        return fail(err, errlen, "second %02d is out of range 00..59 (no leap seconds)", second);

    int offset_minutes = 0;
    if (*p == '+' || *p == '-') {
        int sign = *p++ == '-' ? -1 : 1, oh, om;
        if (!take_digits(&p, 2, &oh) || !take_char(&p, ':') || !take_digits(&p, 2, &om))
            return fail(err, errlen, "expected a UTC offset +hh:mm or -hh:mm");
        if (oh > 23 || om > 59)
            return fail(err, errlen, "UTC offset %02d:%02d is out of range", oh, om);
        offset_minutes = sign * (oh * 60 + om);
    } else if (!take_char(&p, 'Z') && !take_char(&p, 'z')) {
        if (!*p)
            return fail(err, errlen, "missing time zone: end with Z (UTC) or an offset +hh:mm");
        return fail(err, errlen, "unexpected \"%s\" after the time (" FORMAT_HINT ")", p);
    }
    if (*p)
        return fail(err, errlen, "unexpected \"%s\" after the time zone", p);

    double days = (double)days_from_civil(year, month, day);
    *unix_seconds = days * SECONDS_PER_DAY + hour * 3600.0 + minute * 60.0 + second + fraction -
                    offset_minutes * 60.0;
    return true;
}

static long long floor_div(long long a, long long b)
{
    long long q = a / b;
    return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

void proto_time_format_iso8601(double unix_seconds, char *out, size_t outlen)
{
    if (!out || outlen == 0)
        return;
    if (!(fabs(unix_seconds) < 1e14)) { /* also NaN; keeps llround in range */
        snprintf(out, outlen, "invalid");
        return;
    }
    long long ms = llround(unix_seconds * 1000.0);
    long long seconds = floor_div(ms, 1000), days = floor_div(seconds, 86400);
    int milli = (int)(ms - seconds * 1000), of_day = (int)(seconds - days * 86400);
    long long year;
    int month, day;
    civil_from_days(days, &year, &month, &day);
    int hh = of_day / 3600, mm = of_day / 60 % 60, ss = of_day % 60;
    if (milli)
        snprintf(out, outlen, "%04lld-%02d-%02dT%02d:%02d:%02d.%03dZ", year, month, day, hh, mm, ss,
                 milli);
    else
        snprintf(out, outlen, "%04lld-%02d-%02dT%02d:%02d:%02dZ", year, month, day, hh, mm, ss);
}
