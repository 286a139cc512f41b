/* The METAR decoder's parts, internal to metar_*.c: one group of a report, and a parser per
 * kind of group. Each parser looks at one group and answers whether it is of its kind: no
 * (nothing written), yes (decoded into the report) or yes but malformed (the error filled,
 * naming the group). The order of the sections is metar_decode.c's business. */
#ifndef SKYD_METAR_GROUPS_H
#define SKYD_METAR_GROUPS_H

#include <stdbool.h>
#include <stddef.h>

#include "metar.h"

/* One blank-separated group, NUL-terminated (the decoder refuses longer ones before RMK). */
struct metar_group {
    char text[PROTO_METAR_MAX_GROUP_CHARS + 1];
    size_t length;
    size_t offset; /* of its first character in the report */
    int index;     /* 1-based */
};

enum metar_match {
    METAR_NOT_THIS = 0, /* not a group of this kind */
    METAR_TAKEN = 1,    /* decoded */
    METAR_BAD = 2,      /* of this kind, malformed: the error names why */
};

/* Fills *error for `group` (NULL: the report as a whole) with a printf-style reason; returns
 * METAR_BAD so parsers can `return metar_fail(...)`. */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
enum metar_match
metar_fail(struct proto_metar_error *error, const struct metar_group *group,
           enum proto_metar_error_code code, const char *format, ...);

/* Exactly n ASCII digits at text (n <= 4), their value in *value. */
bool metar_digits(const char *text, int n, int *value);

/* ---- metar_groups.c: identification, time, wind, visibility, RVR, temperature, QNH ---- */

enum metar_match metar_parse_station(const struct metar_group *g, struct proto_metar_report *r,
                                     struct proto_metar_error *error);
enum metar_match metar_parse_time(const struct metar_group *g, struct proto_metar_report *r,
                                  struct proto_metar_error *error);
enum metar_match metar_parse_wind(const struct metar_group *g, struct proto_metar_wind *wind,
                                  struct proto_metar_error *error);
enum metar_match metar_parse_wind_sector(const struct metar_group *g, struct proto_metar_wind *wind,
                                         struct proto_metar_error *error);
/* Metres (dddd, dddd NDV), statute miles (10SM, P6SM, 1/2SM, M1/4SM) or ////. `next` is the
 * group after g (NULL at the end): a whole number followed by a fraction ("1 1/2SM") takes
 * both, and *used says how many groups were read. */
enum metar_match metar_parse_visibility(const struct metar_group *g, const struct metar_group *next,
                                        struct proto_metar_visibility *visibility, int *used,
                                        struct proto_metar_error *error);
/* The minimum visibility and its direction (dddd plus N, NE, ... NW), read and ignored. */
enum metar_match metar_parse_minimum_visibility(const struct metar_group *g,
                                                struct proto_metar_error *error);
/* Runway visual range (R24/P2000N, R06L/0600V1000U) in the body, or runway state (R24/290050,
 * R24/CLRD70, R/SNOCLO) among the supplementary groups; read and ignored. */
enum metar_runway_group {
    METAR_RUNWAY_VISUAL_RANGE,
    METAR_RUNWAY_STATE,
};
enum metar_match metar_parse_runway(const struct metar_group *g, enum metar_runway_group kind,
                                    struct proto_metar_error *error);
enum metar_match metar_parse_temperature(const struct metar_group *g, struct proto_metar_report *r,
                                         struct proto_metar_error *error);
/* Q1013, A2992 or their //// forms, read and ignored. */
enum metar_match metar_parse_pressure(const struct metar_group *g, struct proto_metar_error *error);

/* ---- metar_sky.c: clouds, vertical visibility, present and recent weather, supplementary ---- */

/* FEW/SCT/BKN/OVC////, a height of three digits or ///, CB, TCU or ///; VV### and VV///;
 * NSC, NCD, SKC, CLR. */
enum metar_match metar_parse_sky(const struct metar_group *g, struct proto_metar_report *r,
                                 struct proto_metar_error *error);
enum metar_match metar_parse_weather(const struct metar_group *g,
                                     struct proto_metar_weather *weather,
                                     struct proto_metar_error *error);
/* RE followed by a weather code without intensity (RERA, RETSRA), ignored. */
enum metar_match metar_parse_recent_weather(const struct metar_group *g,
                                            struct proto_metar_error *error);
/* Sea-surface temperature and state (W15/S2, W12/H14), ignored. */
enum metar_match metar_parse_sea_state(const struct metar_group *g,
                                       struct proto_metar_error *error);
/* The runway a WS group names: R27, R27L, RWY27 (older reports); ALL RWY is the decoder's. */
enum metar_match metar_parse_wind_shear_runway(const struct metar_group *g,
                                               struct proto_metar_error *error);

#endif
