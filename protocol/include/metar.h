/* METAR and SPECI reports (WMO No. 306 Vol. I.1, FM 15 / FM 16; ICAO Annex 3, appendix 3)
 * decoded into what the sky needs: cloud layers sorted by height with their coverage and base
 * in metres, visibility and its extinction, present weather, wind in m/s, temperature, dew
 * point and relative humidity, and the observation time.
 *
 * Pure functions over (text, length): no I/O, no globals. A report is decoded completely or
 * refused with an error that names the offending group, its index and its character offset;
 * on refusal the output report is zeroed. Groups the sky does not use (RVR, QNH, recent
 * weather, wind shear, runway state, trends, remarks) are read, checked where they come before
 * the trend or RMK, and ignored. */
#ifndef SKYD_METAR_H
#define SKYD_METAR_H

#include <stdbool.h>
#include <stddef.h>

struct cJSON;

/* Limits of what a report may be: longer reports, more groups before RMK, a longer group
 * or more groups of one kind than these are refused. Real reports stay far below them (a
 * METAR is rarely over 200 characters); Annex 3 allows up to 3 present-weather groups and 4
 * RVR groups, US practice up to 6 cloud layers. */
#define PROTO_METAR_MAX_LENGTH 1024
#define PROTO_METAR_MAX_GROUPS 64
#define PROTO_METAR_MAX_GROUP_CHARS 24
#define PROTO_METAR_MAX_LAYERS 6
#define PROTO_METAR_MAX_WEATHER 3
#define PROTO_METAR_MAX_RVR 4

enum proto_metar_type {
    PROTO_METAR_TYPE_METAR = 0, /* routine (also when the report does not name its type) */
    PROTO_METAR_TYPE_SPECI = 1, /* special */
};

/* Stable error ids; tests assert these rather than the message text. */
enum proto_metar_error_code {
    PROTO_METAR_OK = 0,
    PROTO_METAR_ERR_EMPTY = 1,          /* no group at all */
    PROTO_METAR_ERR_TOO_LONG = 2,       /* over PROTO_METAR_MAX_LENGTH characters */
    PROTO_METAR_ERR_TOO_MANY = 3,       /* too many groups, or of one kind */
    PROTO_METAR_ERR_CHARACTER = 4,      /* a character no METAR group contains */
    PROTO_METAR_ERR_AFTER_END = 5,      /* text after the closing '=' */
    PROTO_METAR_ERR_MISSING = 6,        /* a mandatory group is absent (truncated report) */
    PROTO_METAR_ERR_STATION = 7,        /* not a location indicator */
    PROTO_METAR_ERR_TIME = 8,           /* not ddhhmmZ, or a day, hour or minute out of range */
    PROTO_METAR_ERR_WIND = 9,           /* wind or variable wind sector */
    PROTO_METAR_ERR_VISIBILITY = 10,    /* visibility in metres or statute miles */
    PROTO_METAR_ERR_RVR = 11,           /* runway visual range or runway state */
    PROTO_METAR_ERR_WEATHER = 12,       /* present or recent weather */
    PROTO_METAR_ERR_CLOUD = 13,         /* cloud or vertical-visibility group */
    PROTO_METAR_ERR_TEMPERATURE = 14,   /* temperature / dew point */
    PROTO_METAR_ERR_PRESSURE = 15,      /* QNH (Q hPa or A inches of mercury) */
    PROTO_METAR_ERR_SUPPLEMENTARY = 16, /* wind shear, sea state */
    PROTO_METAR_ERR_UNEXPECTED = 17,    /* not a METAR group, or one out of order */
};

struct proto_metar_error {
    enum proto_metar_error_code code;
    int group;     /* 1-based index of the offending group; 0: the report as a whole */
    size_t offset; /* character offset of that group (or of the offending character) */
    char group_text[PROTO_METAR_MAX_GROUP_CHARS + 4]; /* the group as written, cut when long */
    /* `group 5 "BKN0X0" (offset 31): cloud height must be three digits or ///` */
    char message[224];
};

/* Speeds and directions: the wind blows from direction_deg (true north, through east). */
struct proto_metar_wind {
    bool reported;        /* false for /////KT (not observed) */
    bool calm;            /* 00000 */
    bool variable;        /* VRB, or a dddVddd sector */
    bool direction_known; /* false for VRB and for an unknown direction (///) */
    double direction_deg;
    bool speed_known; /* false for ddd//KT */
    double speed_m_s; /* knots x 1852/3600, km/h / 3.6, m/s as reported */
    bool speed_above; /* P99KT, P49MPS: at least speed_m_s */
    bool gust_reported;
    double gust_m_s;
    bool gust_above; /* GP99KT: at least gust_m_s */
    bool sector;     /* the dddVddd group: the direction varies from ... to ..., clockwise */
    double sector_from_deg, sector_to_deg;
    char unit[4]; /* "KT", "MPS" or "KMH", as reported */
};

/* How a measured value relates to the reported figure. */
enum proto_metar_bound {
    PROTO_METAR_EXACT = 0,
    PROTO_METAR_AT_LEAST = 1,  /* 9999 (10 km or more), P6SM, CAVOK */
    PROTO_METAR_LESS_THAN = 2, /* 0000 (less than 50 m), M1/4SM */
};

struct proto_metar_visibility {
    bool reported; /* false for //// or when absent */
    double metres; /* prevailing visibility: 9999 reads 10000 at least, 0000 less than 50 */
    enum proto_metar_bound bound;
    bool ndv;                /* no directional variation (automatic stations) */
    double extinction_per_m; /* Koschmieder: 3.912 / metres (an upper bound when AT_LEAST) */
    double extinction_per_km;
};

enum proto_metar_cloud_amount {
    PROTO_METAR_FEW = 0,            /* 1-2 oktas */
    PROTO_METAR_SCT = 1,            /* 3-4 oktas */
    PROTO_METAR_BKN = 2,            /* 5-7 oktas */
    PROTO_METAR_OVC = 3,            /* 8 oktas */
    PROTO_METAR_AMOUNT_UNKNOWN = 4, /* /// from an automatic station */
};

/* One cloud group. Coverage is the middle of the amount's okta band as a fraction of the sky:
 * FEW 1.5/8, SCT 3.5/8, BKN 6/8, OVC 1 (unknown: 0). */
struct proto_metar_cloud_layer {
    enum proto_metar_cloud_amount amount;
    int oktas_min, oktas_max; /* the amount's band; 0, 0 when unknown */
    double coverage;          /* 0..1 */
    bool base_known;          /* false for /// */
    int base_ft;              /* hundreds of feet as reported, x 100 */
    double base_m;            /* base_ft x 0.3048 */
    bool cumulonimbus;        /* CB */
    bool towering_cumulus;    /* TCU */
    bool type_unknown;        /* /// after the height: type not observed */
};

/* What the report says about the sky as a whole. */
enum proto_metar_sky {
    PROTO_METAR_SKY_NOT_REPORTED = 0, /* no cloud group (or ////// only) */
    PROTO_METAR_SKY_LAYERS = 1,       /* one or more FEW/SCT/BKN/OVC groups */
    PROTO_METAR_SKY_CAVOK = 2,        /* no cloud below 5000 ft, no CB/TCU, visibility >= 10 km */
    PROTO_METAR_SKY_NSC = 3,          /* nil significant cloud */
    PROTO_METAR_SKY_NCD = 4,          /* no cloud detected (automatic) */
    PROTO_METAR_SKY_SKC = 5,          /* sky clear */
    PROTO_METAR_SKY_CLR = 6,          /* no cloud below 12000 ft (US automatic) */
    PROTO_METAR_SKY_OBSCURED = 7,     /* VV: the sky cannot be seen; vertical visibility given */
};

enum proto_metar_intensity {
    PROTO_METAR_NONE = 0,
    PROTO_METAR_LIGHT = 1,    /* - */
    PROTO_METAR_MODERATE = 2, /* no sign */
    PROTO_METAR_HEAVY = 3,    /* + */
};

/* Present weather at the station, the strongest of its groups for each field; phenomena in the
 * vicinity (VC, 8-16 km away) only set the *_nearby flags. */
struct proto_metar_weather {
    enum proto_metar_intensity rain;          /* RA */
    enum proto_metar_intensity snow;          /* SN */
    enum proto_metar_intensity drizzle;       /* DZ */
    enum proto_metar_intensity showers;       /* SH (of whatever precipitation) */
    enum proto_metar_intensity precipitation; /* any of DZ RA SN SG IC PL GR GS UP */
    bool fog;                                 /* FG, with any descriptor (FZFG, BCFG, ...) */
    bool fog_partial;                         /* MI, BC or PR: shallow, patches or partial */
    bool mist;                                /* BR */
    bool thunderstorm;                        /* TS */
    bool freezing;                            /* FZ */
    bool hail;                                /* GR or GS */
    bool showers_nearby, thunderstorm_nearby, fog_nearby; /* VCSH, VCTS, VCFG */
    int group_count;
    char groups[PROTO_METAR_MAX_WEATHER][12]; /* as reported, e.g. "-SHRA" */
};

struct proto_metar_report {
    enum proto_metar_type type;
    char station[5];       /* ICAO location indicator */
    int day, hour, minute; /* observation time, UTC, day of the month */
    bool nil;              /* NIL: the report is missing; nothing else is set */
    bool automatic;        /* AUTO */
    bool correction;       /* COR */
    struct proto_metar_wind wind;
    struct proto_metar_visibility visibility;
    bool cavok;
    struct proto_metar_weather weather;
    enum proto_metar_sky sky;
    int layer_count;
    struct proto_metar_cloud_layer
        layers[PROTO_METAR_MAX_LAYERS]; /* sorted by base, lowest first */
    bool vertical_visibility_known;     /* VV###; false for VV/// */
    double vertical_visibility_m;
    bool temperature_known, dew_point_known;
    double temperature_c, dew_point_c;
    bool relative_humidity_known;
    double relative_humidity; /* 0..1, Magnus formula (proto_metar_relative_humidity) */
};

/* Decodes `length` bytes of `text` (no NUL needed). Returns true with *report filled, or false
 * with *report zeroed and *error saying why (error may be NULL). */
bool proto_metar_decode(const char *text, size_t length, struct proto_metar_report *report,
                        struct proto_metar_error *error);

/* Relative humidity (0..1) from temperature and dew point in degrees Celsius, by the Magnus
 * formula over water with Alduchov & Eskridge's (1996) constants a = 17.625, b = 243.04 C;
 * capped at 1 (a dew point above the temperature is a rounding artefact). */
double proto_metar_relative_humidity(double temperature_c, double dew_point_c);

/* The observation instant in seconds since 1970 (UTC): the last time with the report's day,
 * hour and minute at or before reference_unix_s + 1 hour (reports arrive after they are made;
 * the hour allows for a clock that runs slow), searched back through 12 months. False for a
 * NIL report or when no month of that year has the day. */
bool proto_metar_observation_unix(const struct proto_metar_report *report, double reference_unix_s,
                                  double *unix_seconds);

/* The decoded report as JSON (protocol/PROTOCOL.md, "METAR decoding"); NULL when memory is out.
 * The caller deletes it. */
struct cJSON *proto_metar_to_json(const struct proto_metar_report *report);

/* One line for people, e.g. "EGLL day 28 12:50Z: wind 240 deg 7.7 m/s gusts 14.4 m/s, ...". */
void proto_metar_summary(const struct proto_metar_report *report, char *text, size_t capacity);

/* Names for JSON and summaries: "FEW", "light", "layers", ... */
const char *proto_metar_amount_name(enum proto_metar_cloud_amount amount);
const char *proto_metar_intensity_name(enum proto_metar_intensity intensity);
const char *proto_metar_sky_name(enum proto_metar_sky sky);

#endif
