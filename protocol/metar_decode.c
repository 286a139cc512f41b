/* METAR and SPECI decoding: the report split into groups, its sections read in the order of
 * WMO No. 306 FM 15 (ICAO Annex 3, appendix 3), and the values the sky derives from them. */
#include "metar.h"

#include "metar_groups.h"
#include "utc_time.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The sections of a report in their order; a group of an earlier section after a later one is
 * out of order. */
enum section {
    SEC_TYPE,
    SEC_STATION,
    SEC_TIME,
    SEC_MODIFIER,
    SEC_WIND,
    SEC_SECTOR,
    SEC_VISIBILITY,
    SEC_MIN_VISIBILITY,
    SEC_RUNWAY,
    SEC_WEATHER,
    SEC_SKY,
    SEC_TEMPERATURE,
    SEC_PRESSURE,
    SEC_SUPPLEMENTARY,
    SEC_TREND,
    SEC_NONE,
};

static const char *const section_names[] = {
    "report type", "station",     "observation time",   "AUTO or COR",   "wind",
    "wind sector", "visibility",  "minimum visibility", "runway",        "present weather",
    "cloud",       "temperature", "pressure",           "supplementary", "trend",
};

#define MAX_PRESSURE 2 /* QNH in hPa and in inches, as some reports give both */
#define MAX_RECENT_WEATHER 3
#define WIND_FORM "the wind group (dddff[Gfmfm]KT, MPS or KMH)"
#define VISIBILITY_FORM "the visibility (dddd, a distance in SM, or CAVOK)"
#define TEMPERATURE_FORM "the temperature and dew point (TT/TdTd)"

struct decoder {
    struct metar_group groups[PROTO_METAR_MAX_GROUPS];
    int count;         /* the groups before RMK */
    int next;          /* the group to read */
    enum section last; /* the section of the last group read */
    struct proto_metar_report report;
    struct proto_metar_error *error;
};

/* ---- splitting ----------------------------------------------------------------------------- */

static bool is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* The characters of groups before RMK; remarks may hold any printable character. */
static bool group_character(char c)
{
    return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '/' || c == '+' || c == '-';
}

static bool refuse_character(struct decoder *d, const char *text, size_t start, size_t end,
                             size_t at, int index)
{
    struct metar_group g;
    memset(&g, 0, sizeof g);
    for (size_t i = start; i < end && g.length < PROTO_METAR_MAX_GROUP_CHARS; i++) {
        unsigned char c = (unsigned char)text[i];
        g.text[g.length++] = c > 0x20 && c < 0x7f ? (char)c : '?';
    }
    g.offset = start;
    g.index = index;
    unsigned char c = (unsigned char)text[at];
    char shown[8] = "";
    if (c > 0x20 && c < 0x7f)
        snprintf(shown, sizeof shown, " '%c'", c);
    metar_fail(d->error, &g, PROTO_METAR_ERR_CHARACTER,
               "character 0x%02x%s at offset %zu is not allowed (groups hold A-Z, 0-9, /, + and "
               "-; remarks printable ASCII)",
               c, shown, at);
    return false;
}

/* Splits the text at blanks into groups up to RMK (not kept), checking every character; '='
 * ends the report and only blanks may follow it. */
static bool split(struct decoder *d, const char *text, size_t length)
{
    bool remarks = false;
    int index = 0;
    for (size_t i = 0; i < length;) {
        if (is_blank(text[i])) {
            i++;
            continue;
        }
        if (text[i] == '=') {
            for (size_t j = i + 1; j < length; j++)
                if (!is_blank(text[j])) {
                    metar_fail(d->error, NULL, PROTO_METAR_ERR_AFTER_END,
                               "offset %zu: text after the '=' that ends the report at offset "
                               "%zu",
                               j, i);
                    d->error->offset = j;
                    return false;
                }
            break;
        }
        size_t start = i;
        while (i < length && !is_blank(text[i]) && text[i] != '=')
            i++;
        index++;
        for (size_t j = start; j < i; j++) {
            unsigned char c = (unsigned char)text[j];
            if (remarks ? c <= 0x20 || c >= 0x7f : !group_character(text[j]))
                return refuse_character(d, text, start, i, j, index);
        }
        if (remarks)
            continue;
        if (i - start > PROTO_METAR_MAX_GROUP_CHARS) {
            struct metar_group cut = { .offset = start, .index = index };
            memcpy(cut.text, text + start, PROTO_METAR_MAX_GROUP_CHARS);
            metar_fail(d->error, &cut, PROTO_METAR_ERR_TOO_LONG,
                       "a group of %zu characters; none is longer than %d", i - start,
                       PROTO_METAR_MAX_GROUP_CHARS);
            return false;
        }
        if (i - start == 3 && memcmp(text + start, "RMK", 3) == 0) {
            remarks = true;
            continue;
        }
        if (d->count == PROTO_METAR_MAX_GROUPS) {
            metar_fail(d->error, NULL, PROTO_METAR_ERR_TOO_MANY,
                       "group %d (offset %zu): more than %d groups before RMK", index, start,
                       PROTO_METAR_MAX_GROUPS);
            d->error->group = index;
            d->error->offset = start;
            return false;
        }
        struct metar_group *g = &d->groups[d->count];
        memset(g, 0, sizeof *g);
        memcpy(g->text, text + start, i - start);
        g->length = i - start;
        g->offset = start;
        g->index = index;
        d->count++;
    }
    return true;
}

/* ---- reading the sections ------------------------------------------------------------------ */

static const struct metar_group *current(const struct decoder *d)
{
    return d->next < d->count ? &d->groups[d->next] : NULL;
}

static bool at(const struct decoder *d, const char *word)
{
    const struct metar_group *g = current(d);
    return g && strcmp(g->text, word) == 0;
}

static void advance(struct decoder *d, enum section section, int groups)
{
    d->next += groups;
    d->last = section;
}

/* The section a group would belong to anywhere in a report: the first whose parser takes it,
 * else the first that finds it malformed (its error in *error), else SEC_NONE. */
static enum section classify(const struct metar_group *g, struct proto_metar_error *error)
{
    struct proto_metar_report scratch;
    struct proto_metar_error ignored;
    enum section bad = SEC_NONE;
    memset(error, 0, sizeof *error);
    for (enum section s = SEC_MODIFIER; s < SEC_NONE; s++) {
        memset(&scratch, 0, sizeof scratch);
        enum metar_match m = METAR_NOT_THIS;
        int used;
        struct proto_metar_error *e = bad == SEC_NONE ? error : &ignored;
        switch (s) {
        case SEC_MODIFIER:
            m = !strcmp(g->text, "AUTO") || !strcmp(g->text, "COR") || !strcmp(g->text, "NIL")
                    ? METAR_TAKEN
                    : METAR_NOT_THIS;
            break;
        case SEC_WIND:
            m = metar_parse_wind(g, &scratch.wind, e);
            break;
        case SEC_SECTOR:
            m = metar_parse_wind_sector(g, &scratch.wind, e);
            break;
        case SEC_VISIBILITY:
            m = !strcmp(g->text, "CAVOK")
                    ? METAR_TAKEN
                    : metar_parse_visibility(g, NULL, &scratch.visibility, &used, e);
            break;
        case SEC_MIN_VISIBILITY:
            m = metar_parse_minimum_visibility(g, e);
            break;
        case SEC_RUNWAY:
            m = metar_parse_runway(g, METAR_RUNWAY_VISUAL_RANGE, e);
            break;
        case SEC_WEATHER:
            m = metar_parse_weather(g, &scratch.weather, e);
            break;
        case SEC_SKY:
            m = metar_parse_sky(g, &scratch, e);
            break;
        case SEC_TEMPERATURE:
            m = metar_parse_temperature(g, &scratch, e);
            break;
        case SEC_PRESSURE:
            m = metar_parse_pressure(g, e);
            break;
        case SEC_SUPPLEMENTARY:
            m = !strcmp(g->text, "WS") ? METAR_TAKEN : metar_parse_recent_weather(g, e);
            if (m == METAR_NOT_THIS)
                m = metar_parse_sea_state(g, e);
            if (m == METAR_NOT_THIS)
                m = metar_parse_runway(g, METAR_RUNWAY_STATE, e);
            break;
        case SEC_TREND:
            m = !strcmp(g->text, "NOSIG") || !strcmp(g->text, "BECMG") || !strcmp(g->text, "TEMPO")
                    ? METAR_TAKEN
                    : METAR_NOT_THIS;
            break;
        default:
            break;
        }
        if (m == METAR_TAKEN) {
            memset(error, 0, sizeof *error);
            return s;
        }
        if (m == METAR_BAD && bad == SEC_NONE)
            bad = s;
    }
    return bad;
}

/* The group at the cursor cannot be read where it stands. `expected` names the mandatory group
 * that should be there (NULL: none; the group is left over). A well-formed group of an earlier
 * section is out of order; otherwise the expected group is missing, or the group is refused for
 * what is wrong with it, or as no METAR group at all. */
static bool refuse(struct decoder *d, const struct metar_group *g, const char *expected)
{
    struct proto_metar_error why;
    enum section s = classify(g, &why);
    bool taken = s != SEC_NONE && why.code == PROTO_METAR_OK;
    bool cavok_excludes = s == SEC_MIN_VISIBILITY || s == SEC_RUNWAY || s == SEC_WEATHER ||
                          s == SEC_SKY;
    if (taken && d->report.cavok && cavok_excludes) {
        metar_fail(d->error, g, PROTO_METAR_ERR_UNEXPECTED,
                   "this %s group cannot come with CAVOK (which says there is none)",
                   section_names[s]);
    } else if (taken && (s <= d->last || !expected)) {
        metar_fail(d->error, g, PROTO_METAR_ERR_UNEXPECTED,
                   "this %s group cannot come after the %s group", section_names[s],
                   section_names[d->last]);
    } else if (expected) {
        metar_fail(d->error, g, taken ? PROTO_METAR_ERR_MISSING : PROTO_METAR_ERR_UNEXPECTED,
                   "%sexpected %s here", taken ? "" : "not a METAR group: ", expected);
    } else if (s != SEC_NONE) {
        *d->error = why;
    } else {
        metar_fail(d->error, g, PROTO_METAR_ERR_UNEXPECTED,
                   "not a METAR group, or not one that may follow the %s group",
                   section_names[d->last]);
    }
    return false;
}

/* A section's parser found g malformed (*d->error says why); unless g is a well-formed group
 * of another section, which makes it a group out of order. */
static bool malformed(struct decoder *d, const struct metar_group *g, enum section section)
{
    struct proto_metar_error why;
    enum section s = classify(g, &why);
    if (s != SEC_NONE && why.code == PROTO_METAR_OK && s != section)
        return refuse(d, g, NULL);
    return false;
}

/* A mandatory group is absent: at the end of the report, or something else stands there. */
static bool missing(struct decoder *d, const char *expected)
{
    const struct metar_group *g = current(d);
    if (g)
        return refuse(d, g, expected);
    metar_fail(d->error, d->count ? &d->groups[d->count - 1] : NULL, PROTO_METAR_ERR_MISSING,
               "the report ends here without %s", expected);
    return false;
}

static bool no_more_groups(struct decoder *d)
{
    const struct metar_group *g = current(d);
    return g ? refuse(d, g, NULL) : true;
}

/* The parser of a section that may repeat. */
static enum metar_match parse_repeated(struct decoder *d, enum section section,
                                       const struct metar_group *g)
{
    switch (section) {
    case SEC_RUNWAY:
        return metar_parse_runway(g, METAR_RUNWAY_VISUAL_RANGE, d->error);
    case SEC_WEATHER:
        return metar_parse_weather(g, &d->report.weather, d->error);
    case SEC_SKY:
        return metar_parse_sky(g, &d->report, d->error);
    case SEC_PRESSURE:
        return metar_parse_pressure(g, d->error);
    default:
        return METAR_NOT_THIS;
    }
}

/* Reads the groups of an optional section that may repeat, at most `limit` of them. */
static bool read_repeated(struct decoder *d, enum section section, int limit, const char *what)
{
    int taken = 0;
    for (const struct metar_group *g; (g = current(d)) != NULL;) {
        enum metar_match m = parse_repeated(d, section, g);
        if (m == METAR_BAD)
            return malformed(d, g, section);
        if (m == METAR_NOT_THIS)
            break;
        if (++taken > limit) {
            metar_fail(d->error, g, PROTO_METAR_ERR_TOO_MANY, "more than %d %s groups", limit,
                       what);
            return false;
        }
        advance(d, section, 1);
    }
    return true;
}

static bool read_identification(struct decoder *d)
{
    struct proto_metar_report *r = &d->report;
    if (at(d, "METAR") || at(d, "SPECI")) {
        r->type = at(d, "SPECI") ? PROTO_METAR_TYPE_SPECI : PROTO_METAR_TYPE_METAR;
        advance(d, SEC_TYPE, 1);
        if (at(d, "COR")) {
            r->correction = true;
            advance(d, SEC_TYPE, 1);
        }
    }
    if (!current(d))
        return missing(d, "the station (ICAO location indicator)");
    if (metar_parse_station(current(d), r, d->error) != METAR_TAKEN)
        return false;
    advance(d, SEC_STATION, 1);
    if (!at(d, "NIL")) {
        if (!current(d))
            return missing(d, "the observation time (ddhhmmZ)");
        if (metar_parse_time(current(d), r, d->error) != METAR_TAKEN)
            return false;
        advance(d, SEC_TIME, 1);
    }
    if (at(d, "NIL")) {
        r->nil = true;
        advance(d, SEC_MODIFIER, 1);
        return true;
    }
    while (at(d, "AUTO") || at(d, "COR")) {
        bool *flag = at(d, "AUTO") ? &r->automatic : &r->correction;
        if (*flag) {
            metar_fail(d->error, current(d), PROTO_METAR_ERR_UNEXPECTED, "given twice");
            return false;
        }
        *flag = true;
        advance(d, SEC_MODIFIER, 1);
    }
    return true;
}

static bool read_wind_and_visibility(struct decoder *d)
{
    struct proto_metar_report *r = &d->report;
    const struct metar_group *g = current(d);
    enum metar_match m = g ? metar_parse_wind(g, &r->wind, d->error) : METAR_NOT_THIS;
    if (m == METAR_BAD)
        return malformed(d, g, SEC_WIND);
    if (m == METAR_NOT_THIS)
        return missing(d, WIND_FORM);
    advance(d, SEC_WIND, 1);
    if ((g = current(d)) &&
        (m = metar_parse_wind_sector(g, &r->wind, d->error)) != METAR_NOT_THIS) {
        if (m == METAR_BAD)
            return malformed(d, g, SEC_SECTOR);
        advance(d, SEC_SECTOR, 1);
    }
    if (at(d, "CAVOK")) {
        r->cavok = true;
        advance(d, SEC_VISIBILITY, 1);
        return true;
    }
    int used = 1;
    g = current(d);
    const struct metar_group *next = d->next + 1 < d->count ? &d->groups[d->next + 1] : NULL;
    m = g ? metar_parse_visibility(g, next, &r->visibility, &used, d->error) : METAR_NOT_THIS;
    if (m == METAR_BAD)
        return malformed(d, g, SEC_VISIBILITY);
    if (m == METAR_NOT_THIS)
        return missing(d, VISIBILITY_FORM);
    advance(d, SEC_VISIBILITY, used);
    if ((g = current(d)) && (m = metar_parse_minimum_visibility(g, d->error)) != METAR_NOT_THIS) {
        if (m == METAR_BAD)
            return malformed(d, g, SEC_MIN_VISIBILITY);
        advance(d, SEC_MIN_VISIBILITY, 1);
    }
    return true;
}

static bool read_body(struct decoder *d)
{
    struct proto_metar_report *r = &d->report;
    if (!read_wind_and_visibility(d))
        return false;
    if (!r->cavok) {
        if (!read_repeated(d, SEC_RUNWAY, PROTO_METAR_MAX_RVR, "runway") ||
            !read_repeated(d, SEC_WEATHER, PROTO_METAR_MAX_WEATHER, "present-weather") ||
            !read_repeated(d, SEC_SKY, PROTO_METAR_MAX_LAYERS + 2, "cloud"))
            return false;
    }
    const struct metar_group *g = current(d);
    enum metar_match m = g ? metar_parse_temperature(g, r, d->error) : METAR_NOT_THIS;
    if (m == METAR_BAD)
        return malformed(d, g, SEC_TEMPERATURE);
    if (m == METAR_NOT_THIS)
        return missing(d, TEMPERATURE_FORM);
    advance(d, SEC_TEMPERATURE, 1);
    return read_repeated(d, SEC_PRESSURE, MAX_PRESSURE, "pressure");
}

/* Recent weather, wind shear, sea state and runway state, then the trend: read, not kept. */
static bool read_supplementary(struct decoder *d)
{
    int recent = 0;
    for (const struct metar_group *g; (g = current(d)) != NULL;) {
        enum metar_match m;
        if (strcmp(g->text, "WS") == 0) {
            const struct metar_group *runway = d->next + 1 < d->count ? g + 1 : NULL;
            if (!runway) {
                metar_fail(d->error, g, PROTO_METAR_ERR_SUPPLEMENTARY,
                           "wind shear (WS) must name a runway or ALL RWY");
                return false;
            }
            if (strcmp(runway->text, "ALL") == 0) {
                if (d->next + 2 >= d->count || strcmp(runway[1].text, "RWY") != 0) {
                    metar_fail(d->error, runway, PROTO_METAR_ERR_SUPPLEMENTARY,
                               "wind shear on all runways is WS ALL RWY");
                    return false;
                }
                advance(d, SEC_SUPPLEMENTARY, 3);
                continue;
            }
            if (metar_parse_wind_shear_runway(runway, d->error) != METAR_TAKEN)
                return false;
            advance(d, SEC_SUPPLEMENTARY, 2);
            continue;
        }
        if ((m = metar_parse_recent_weather(g, d->error)) == METAR_NOT_THIS &&
            (m = metar_parse_sea_state(g, d->error)) == METAR_NOT_THIS &&
            (m = metar_parse_runway(g, METAR_RUNWAY_STATE, d->error)) == METAR_NOT_THIS)
            break;
        if (m == METAR_BAD)
            return malformed(d, g, SEC_SUPPLEMENTARY);
        if (strncmp(g->text, "RE", 2) == 0 && ++recent > MAX_RECENT_WEATHER) {
            metar_fail(d->error, g, PROTO_METAR_ERR_TOO_MANY, "more than %d recent-weather groups",
                       MAX_RECENT_WEATHER);
            return false;
        }
        advance(d, SEC_SUPPLEMENTARY, 1);
    }
    /* A trend forecast runs to the remarks (or the end): read and ignored. */
    if (at(d, "NOSIG") || at(d, "BECMG") || at(d, "TEMPO"))
        advance(d, SEC_TREND, d->count - d->next);
    return true;
}

/* ---- derived values ------------------------------------------------------------------------ */

double proto_metar_relative_humidity(double temperature_c, double dew_point_c)
{
    /* Magnus: e_s(T) = 6.1094 hPa exp(a T / (b + T)), a = 17.625, b = 243.04 C (Alduchov &
     * Eskridge 1996); RH = e_s(Td) / e_s(T). */
    const double a = 17.625, b = 243.04;
    double rh = exp(a * dew_point_c / (b + dew_point_c) - a * temperature_c / (b + temperature_c));
    return rh < 1.0 ? rh : 1.0;
}

static double layer_key(const struct proto_metar_cloud_layer *layer)
{
    return layer->base_known ? layer->base_m : INFINITY;
}

static void derive(struct proto_metar_report *r)
{
    if (r->cavok) {
        r->visibility.reported = true;
        r->visibility.metres = 10000;
        r->visibility.bound = PROTO_METAR_AT_LEAST;
        r->sky = PROTO_METAR_SKY_CAVOK;
    }
    if (r->visibility.reported) {
        /* Koschmieder: V = ln(1 / 0.02) / sigma = 3.912 / sigma (2 % contrast threshold). */
        r->visibility.extinction_per_m = 3.912 / r->visibility.metres;
        r->visibility.extinction_per_km = r->visibility.extinction_per_m * 1000.0;
    }
    /* Lowest base first, unknown bases last; stable, so equal bases keep the report's order. */
    for (int i = 1; i < r->layer_count; i++) {
        struct proto_metar_cloud_layer layer = r->layers[i];
        int j = i;
        for (; j > 0 && layer_key(&r->layers[j - 1]) > layer_key(&layer); j--)
            r->layers[j] = r->layers[j - 1];
        r->layers[j] = layer;
    }
    r->relative_humidity_known = r->temperature_known && r->dew_point_known;
    if (r->relative_humidity_known)
        r->relative_humidity = proto_metar_relative_humidity(r->temperature_c, r->dew_point_c);
}

bool proto_metar_decode(const char *text, size_t length, struct proto_metar_report *report,
                        struct proto_metar_error *error)
{
    struct proto_metar_error ignored;
    struct decoder d;
    memset(&d, 0, sizeof d);
    d.error = error ? error : &ignored;
    memset(d.error, 0, sizeof *d.error);
    memset(report, 0, sizeof *report);
    if (!text)
        length = 0;
    if (length > PROTO_METAR_MAX_LENGTH) {
        metar_fail(d.error, NULL, PROTO_METAR_ERR_TOO_LONG,
                   "the report has %zu characters; at most %d are read", length,
                   PROTO_METAR_MAX_LENGTH);
        d.error->offset = PROTO_METAR_MAX_LENGTH;
        return false;
    }
    if (!split(&d, text, length))
        return false;
    if (d.count == 0) {
        metar_fail(d.error, NULL, PROTO_METAR_ERR_EMPTY, "the report holds no group");
        return false;
    }
    bool ok = read_identification(&d);
    if (ok && !d.report.nil)
        ok = read_body(&d) && read_supplementary(&d);
    if (ok)
        ok = no_more_groups(&d);
    if (!ok)
        return false;
    derive(&d.report);
    *report = d.report;
    return true;
}

bool proto_metar_observation_unix(const struct proto_metar_report *report, double reference_unix_s,
                                  double *unix_seconds)
{
    if (report->nil || report->day < 1)
        return false;
    const double latest = reference_unix_s + 3600.0;
    char text[48];
    int year, month;
    proto_time_format_iso8601(latest, text, sizeof text);
    if (sscanf(text, "%4d-%2d", &year, &month) != 2)
        return false;
    for (int back = 0; back <= 12; back++) {
        int y = year, m = month - back;
        if (m < 1) {
            m += 12;
            y--;
        }
        double t;
        snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:00Z", y, m, report->day, report->hour,
                 report->minute);
        if (y >= 0 && proto_time_parse_iso8601(text, &t, NULL, 0) && t <= latest) {
            *unix_seconds = t;
            return true;
        }
    }
    return false;
}
