/* METAR groups of the identification, wind, visibility, runway, temperature and pressure
 * sections (WMO No. 306 FM 15, ICAO Annex 3 appendix 3), one group at a time. */
#include "metar_groups.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define KNOT_M_S (1852.0 / 3600.0) /* the international knot: 1852 m per hour */
#define STATUTE_MILE_M 1609.344

enum metar_match metar_fail(struct proto_metar_error *error, const struct metar_group *group,
                            enum proto_metar_error_code code, const char *format, ...)
{
    char reason[160];
    va_list args;
    va_start(args, format);
    vsnprintf(reason, sizeof reason, format, args);
    va_end(args);
    memset(error, 0, sizeof *error);
    error->code = code;
    if (group) {
        error->group = group->index;
        error->offset = group->offset;
        snprintf(error->group_text, sizeof error->group_text, "%s", group->text);
        snprintf(error->message, sizeof error->message, "group %d \"%s\" (offset %zu): %s",
                 group->index, group->text, group->offset, reason);
    } else {
        snprintf(error->message, sizeof error->message, "%s", reason);
    }
    return METAR_BAD;
}

bool metar_digits(const char *text, int n, int *value)
{
    int v = 0;
    for (int i = 0; i < n; i++) {
        if (text[i] < '0' || text[i] > '9')
            return false;
        v = v * 10 + (text[i] - '0');
    }
    *value = v;
    return true;
}

static bool is_upper(char c)
{
    return c >= 'A' && c <= 'Z';
}

static bool is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static bool all_slashes(const char *text, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (text[i] != '/')
            return false;
    return true;
}

static bool ends_with(const struct metar_group *g, const char *suffix)
{
    size_t n = strlen(suffix);
    return g->length >= n && strcmp(g->text + g->length - n, suffix) == 0;
}

/* ---- identification ---------------------------------------------------------------------- */

enum metar_match metar_parse_station(const struct metar_group *g, struct proto_metar_report *r,
                                     struct proto_metar_error *error)
{
    /* ICAO Doc 7910 indicators are four letters; national ones (US "K1V4") may hold digits. */
    bool ok = g->length == 4 && is_upper(g->text[0]);
    for (size_t i = 1; ok && i < 4; i++)
        ok = is_upper(g->text[i]) || is_digit(g->text[i]);
    if (!ok)
        return metar_fail(error, g, PROTO_METAR_ERR_STATION,
                          "the station must be a four-character ICAO location indicator");
    memcpy(r->station, g->text, 5);
    return METAR_TAKEN;
}

enum metar_match metar_parse_time(const struct metar_group *g, struct proto_metar_report *r,
                                  struct proto_metar_error *error)
{
    int day, hour, minute;
    if (g->length != 7 || g->text[6] != 'Z' || !metar_digits(g->text, 2, &day) ||
        !metar_digits(g->text + 2, 2, &hour) || !metar_digits(g->text + 4, 2, &minute))
        return metar_fail(error, g, PROTO_METAR_ERR_TIME,
                          "the observation time must be ddhhmmZ (day, hour, minute UTC)");
    if (day < 1 || day > 31)
        return metar_fail(error, g, PROTO_METAR_ERR_TIME, "day %d is not 01 to 31", day);
    if (hour > 23)
        return metar_fail(error, g, PROTO_METAR_ERR_TIME, "hour %d is not 00 to 23", hour);
    if (minute > 59)
        return metar_fail(error, g, PROTO_METAR_ERR_TIME, "minute %d is not 00 to 59", minute);
    r->day = day;
    r->hour = hour;
    r->minute = minute;
    return METAR_TAKEN;
}

/* ---- wind -------------------------------------------------------------------------------- */

/* A speed at *p: P (above) then two or three digits, or "//". */
static bool take_speed(const char **p, bool *known, bool *above, int *value)
{
    const char *s = *p;
    *above = *s == 'P';
    if (*above)
        s++;
    if (!*above && s[0] == '/' && s[1] == '/') {
        *known = false;
        *p = s + 2;
        return true;
    }
    int n = 0;
    while (n < 3 && is_digit(s[n]))
        n++;
    if (n < 2)
        return false;
    metar_digits(s, n, value);
    *known = true;
    *p = s + n;
    return true;
}

enum metar_match metar_parse_wind(const struct metar_group *g, struct proto_metar_wind *wind,
                                  struct proto_metar_error *error)
{
    static const struct {
        const char *unit;
        double to_m_s;
    } units[] = { { "KT", KNOT_M_S }, { "MPS", 1.0 }, { "KMH", 1.0 / 3.6 } };
    size_t u = 0;
    while (u < 3 && !ends_with(g, units[u].unit))
        u++;
    if (u == 3)
        return METAR_NOT_THIS;
    const char *usage = "the wind must be dddff[Gfmfm] (VRB or /// for ddd) then KT, MPS or KMH";
    size_t body = g->length - strlen(units[u].unit);
    struct proto_metar_wind w;
    memset(&w, 0, sizeof w);
    snprintf(w.unit, sizeof w.unit, "%s", units[u].unit);
    if (body == 5 && all_slashes(g->text, 5)) { /* not observed */
        *wind = w;
        return METAR_TAKEN;
    }
    if (body < 5)
        return metar_fail(error, g, PROTO_METAR_ERR_WIND, "%s", usage);
    w.reported = true;
    int direction = 0;
    if (strncmp(g->text, "VRB", 3) == 0) {
        w.variable = true;
    } else if (metar_digits(g->text, 3, &direction)) {
        if (direction > 360)
            return metar_fail(error, g, PROTO_METAR_ERR_WIND,
                              "wind direction %d is not 000 to 360 degrees", direction);
        w.direction_known = true;
        w.direction_deg = direction;
    } else if (!all_slashes(g->text, 3)) {
        return metar_fail(error, g, PROTO_METAR_ERR_WIND, "%s", usage);
    }
    const char *p = g->text + 3, *end = g->text + body;
    int speed = 0, gust = 0;
    bool gust_known = false;
    if (!take_speed(&p, &w.speed_known, &w.speed_above, &speed))
        return metar_fail(error, g, PROTO_METAR_ERR_WIND, "wind speed must be two or three digits");
    if (p < end && *p == 'G') {
        p++;
        if (!take_speed(&p, &gust_known, &w.gust_above, &gust) || !gust_known)
            return metar_fail(error, g, PROTO_METAR_ERR_WIND,
                              "a gust must be G and two or three digits");
        w.gust_reported = true;
    }
    if (p != end)
        return metar_fail(error, g, PROTO_METAR_ERR_WIND, "%s", usage);
    if (w.gust_reported && w.speed_known && gust <= speed)
        return metar_fail(error, g, PROTO_METAR_ERR_WIND, "gust %d is not above the mean speed %d",
                          gust, speed);
    w.calm = w.direction_known && direction == 0 && w.speed_known && speed == 0;
    if (w.calm && w.gust_reported)
        return metar_fail(error, g, PROTO_METAR_ERR_WIND, "a calm wind (00000) has no gust");
    w.speed_m_s = speed * units[u].to_m_s;
    w.gust_m_s = gust * units[u].to_m_s;
    *wind = w;
    return METAR_TAKEN;
}

enum metar_match metar_parse_wind_sector(const struct metar_group *g, struct proto_metar_wind *wind,
                                         struct proto_metar_error *error)
{
    int from, to;
    if (g->length != 7 || g->text[3] != 'V' || !metar_digits(g->text, 3, &from))
        return METAR_NOT_THIS;
    if (!metar_digits(g->text + 4, 3, &to))
        return metar_fail(error, g, PROTO_METAR_ERR_WIND,
                          "a variable wind sector must be dddVddd (degrees)");
    if (from > 360 || to > 360)
        return metar_fail(error, g, PROTO_METAR_ERR_WIND, "sector directions must be 000 to 360");
    if (from == to)
        return metar_fail(error, g, PROTO_METAR_ERR_WIND, "the sector's two directions are equal");
    wind->sector = true;
    wind->variable = true;
    wind->sector_from_deg = from;
    wind->sector_to_deg = to;
    return METAR_TAKEN;
}

/* ---- visibility -------------------------------------------------------------------------- */

/* "n/d" with d 2, 4, 8 or 16 and 0 < n < d, or a whole number of one or two digits. */
static bool take_miles(const char *text, size_t n, double *miles, bool *fraction)
{
    const char *slash = memchr(text, '/', n);
    int whole, numerator, denominator;
    if (!slash) {
        *fraction = false;
        if (n < 1 || n > 2 || !metar_digits(text, (int)n, &whole) || whole == 0)
            return false;
        *miles = whole;
        return true;
    }
    size_t a = (size_t)(slash - text), b = n - a - 1;
    if (a != 1 || b < 1 || b > 2 || !metar_digits(text, 1, &numerator) ||
        !metar_digits(slash + 1, (int)b, &denominator))
        return false;
    if ((denominator != 2 && denominator != 4 && denominator != 8 && denominator != 16) ||
        numerator < 1 || numerator >= denominator)
        return false;
    *fraction = true;
    *miles = (double)numerator / denominator;
    return true;
}

static enum metar_match statute_miles(const struct metar_group *g, const struct metar_group *next,
                                      struct proto_metar_visibility *v, int *used,
                                      struct proto_metar_error *error)
{
    /* A whole number of miles followed by a fraction: "1 1/2SM". */
    int whole = 0;
    const struct metar_group *miles_group = g;
    if (g->length == 1 && metar_digits(g->text, 1, &whole) && next && ends_with(next, "SM") &&
        strchr(next->text, '/')) {
        miles_group = next;
        *used = 2;
    } else if (!ends_with(g, "SM")) {
        return METAR_NOT_THIS;
    }
    const char *text = miles_group->text;
    size_t n = miles_group->length - 2;
    enum proto_metar_bound bound = PROTO_METAR_EXACT;
    if (n > 0 && (text[0] == 'M' || text[0] == 'P')) {
        bound = text[0] == 'M' ? PROTO_METAR_LESS_THAN : PROTO_METAR_AT_LEAST;
        text++;
        n--;
    }
    double miles;
    bool fraction;
    if (!take_miles(text, n, &miles, &fraction) || (*used == 2 && (!fraction || bound)))
        return metar_fail(error, miles_group, PROTO_METAR_ERR_VISIBILITY,
                          "visibility in statute miles must be like 10SM, 1/2SM, 1 1/2SM, "
                          "M1/4SM or P6SM");
    v->reported = true;
    v->metres = (whole + miles) * STATUTE_MILE_M;
    v->bound = bound;
    return METAR_TAKEN;
}

enum metar_match metar_parse_visibility(const struct metar_group *g, const struct metar_group *next,
                                        struct proto_metar_visibility *visibility, int *used,
                                        struct proto_metar_error *error)
{
    struct proto_metar_visibility v;
    memset(&v, 0, sizeof v);
    *used = 1;
    int metres;
    if (g->length == 4 && all_slashes(g->text, 4)) {
        *visibility = v; /* not observed */
        return METAR_TAKEN;
    }
    if (!metar_digits(g->text, 4, &metres)) {
        enum metar_match m = statute_miles(g, next, &v, used, error);
        if (m == METAR_TAKEN)
            *visibility = v;
        return m;
    }
    if (g->length == 7 && strcmp(g->text + 4, "NDV") == 0)
        v.ndv = true;
    else if (g->length != 4)
        return METAR_NOT_THIS; /* a minimum visibility with its direction, or another group */
    v.reported = true;
    v.metres = metres;
    if (metres == 9999) { /* 10 km or more */
        v.metres = 10000;
        v.bound = PROTO_METAR_AT_LEAST;
    } else if (metres == 0) { /* less than 50 m */
        v.metres = 50;
        v.bound = PROTO_METAR_LESS_THAN;
    }
    *visibility = v;
    return METAR_TAKEN;
}

enum metar_match metar_parse_minimum_visibility(const struct metar_group *g,
                                                struct proto_metar_error *error)
{
    static const char *const directions[] = { "N", "NE", "E", "SE", "S", "SW", "W", "NW" };
    int metres;
    if (g->length < 5 || g->length > 6 || !metar_digits(g->text, 4, &metres) ||
        !is_upper(g->text[4]))
        return METAR_NOT_THIS;
    for (size_t i = 0; i < sizeof directions / sizeof directions[0]; i++)
        if (strcmp(g->text + 4, directions[i]) == 0)
            return METAR_TAKEN;
    return metar_fail(error, g, PROTO_METAR_ERR_VISIBILITY,
                      "a minimum visibility's direction must be N, NE, E, SE, S, SW, W or NW");
}

/* ---- runway visual range and runway state ------------------------------------------------ */

/* One RVR value at *p: P or M, then four digits; or "////". */
static bool take_rvr_value(const char **p)
{
    const char *s = *p;
    if (strlen(s) >= 4 && all_slashes(s, 4)) {
        *p = s + 4;
        return true;
    }
    if (*s == 'P' || *s == 'M')
        s++;
    int value;
    if (!metar_digits(s, 4, &value))
        return false;
    *p = s + 4;
    return true;
}

enum metar_match metar_parse_runway(const struct metar_group *g, enum metar_runway_group kind,
                                    struct proto_metar_error *error)
{
    if (g->text[0] != 'R' || (!is_digit(g->text[1]) && g->text[1] != '/'))
        return METAR_NOT_THIS;
    const char *p = g->text + 3;
    int runway;
    bool designator = metar_digits(g->text + 1, 2, &runway);
    if (designator && (*p == 'L' || *p == 'C' || *p == 'R'))
        p++;
    designator = designator && *p++ == '/';
    if (kind == METAR_RUNWAY_STATE) {
        /* Six digits or slashes (deposit, extent, depth, friction), CLRD and the friction, or
         * the aerodrome closed by snow. */
        bool cleared = strncmp(p, "CLRD", 4) == 0;
        bool state = designator && strlen(p) == 6;
        for (size_t i = cleared ? 4 : 0; state && i < 6; i++)
            state = is_digit(p[i]) || p[i] == '/';
        if (state || strcmp(g->text, "R/SNOCLO") == 0)
            return METAR_TAKEN;
        return metar_fail(error, g, PROTO_METAR_ERR_RVR,
                          "a runway state must be like R24/290050, R24/CLRD70 or R/SNOCLO");
    }
    const char *usage = "runway visual range must be like R24/P2000N or R06L/0600V1000U";
    if (!designator || !take_rvr_value(&p))
        return metar_fail(error, g, PROTO_METAR_ERR_RVR, "%s", usage);
    if (*p == 'V') {
        p++;
        if (!take_rvr_value(&p))
            return metar_fail(error, g, PROTO_METAR_ERR_RVR, "%s", usage);
    }
    if (strncmp(p, "FT", 2) == 0)
        p += 2;
    if (*p == 'U' || *p == 'D' || *p == 'N' || *p == '/')
        p++;
    if (*p)
        return metar_fail(error, g, PROTO_METAR_ERR_RVR, "%s", usage);
    return METAR_TAKEN;
}

/* ---- temperature and dew point, pressure ------------------------------------------------- */

/* "dd", "Mdd" (below zero) or "//" (missing), the whole of text. */
static bool take_celsius(const char *text, size_t n, bool *known, double *celsius)
{
    int value;
    if (n == 2 && all_slashes(text, 2)) {
        *known = false;
        return true;
    }
    bool minus = n == 3 && text[0] == 'M';
    if (n != 2 + (size_t)minus || !metar_digits(text + minus, 2, &value))
        return false;
    *known = true;
    *celsius = minus ? -value : value;
    return true;
}

enum metar_match metar_parse_temperature(const struct metar_group *g, struct proto_metar_report *r,
                                         struct proto_metar_error *error)
{
    if (!is_digit(g->text[0]) && g->text[0] != 'M' && g->text[0] != '/')
        return METAR_NOT_THIS;
    for (size_t i = 0; i < g->length; i++)
        if (!is_digit(g->text[i]) && g->text[i] != 'M' && g->text[i] != '/')
            return METAR_NOT_THIS;
    /* The separator follows "dd", "Mdd" or "//". */
    size_t split = g->text[0] == 'M' ? 3 : 2;
    bool t_known = false, d_known = false;
    double t = 0, d = 0;
    if (g->length <= split || g->text[split] != '/' ||
        !take_celsius(g->text, split, &t_known, &t) ||
        !take_celsius(g->text + split + 1, g->length - split - 1, &d_known, &d))
        return metar_fail(error, g, PROTO_METAR_ERR_TEMPERATURE,
                          "temperature and dew point must be TT/TdTd: two digits each, M before "
                          "them below zero, // when missing");
    r->temperature_known = t_known;
    r->temperature_c = t;
    r->dew_point_known = d_known;
    r->dew_point_c = d;
    return METAR_TAKEN;
}

enum metar_match metar_parse_pressure(const struct metar_group *g, struct proto_metar_error *error)
{
    if ((g->text[0] != 'Q' && g->text[0] != 'A') || g->length != 5 ||
        (!is_digit(g->text[1]) && g->text[1] != '/'))
        return METAR_NOT_THIS;
    if (all_slashes(g->text + 1, 4))
        return METAR_TAKEN;
    int value;
    if (!metar_digits(g->text + 1, 4, &value))
        return metar_fail(error, g, PROTO_METAR_ERR_PRESSURE,
                          "QNH must be Q and four digits (hPa) or A and four digits (0.01 inHg)");
    /* Beyond every sea-level pressure observed (870 to 1084 hPa), with a margin. */
    if (g->text[0] == 'Q' && (value < 850 || value > 1100))
        return metar_fail(error, g, PROTO_METAR_ERR_PRESSURE, "QNH %d hPa is not 0850 to 1100",
                          value);
    if (g->text[0] == 'A' && (value < 2500 || value > 3250))
        return metar_fail(error, g, PROTO_METAR_ERR_PRESSURE,
                          "altimeter %d (0.01 inHg) is not 2500 to 3250", value);
    return METAR_TAKEN;
}
