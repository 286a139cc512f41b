/* METAR and SPECI decoding (protocol/metar_*.c): the examples of ICAO Annex 3 (appendix 3)
 * and reports in the WMO No. 306 FM 15 format, real-looking European and US reports, and edge
 * cases of every group; the derived numbers (coverage, base in metres, visibility and
 * Koschmieder extinction, wind in m/s, relative humidity against Buck's formula), the JSON and
 * the observation time; PROTOCOL.md's example. Refusals are in test_metar_refusals.c.
 * Usage: test_metar [PROTOCOL_MD]   (default: protocol/PROTOCOL.md of this source tree) */
#include "test_metar.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "utc_time.h"

#define FT 0.3048
#define KT (1852.0 / 3600.0)
#define MILE 1609.344

bool decode_ok(const char *text, struct proto_metar_report *report)
{
    struct proto_metar_error error;
    bool ok = proto_metar_decode(text, strlen(text), report, &error);
    CHECK_MSG(ok, "\"%s\" refused: %s", text, error.message);
    return ok;
}

/* Relative humidity by Buck's (1981) saturation vapour pressure over water, an independent
 * fit of the same curve: e_w = 6.1121 exp((18.678 - T / 234.5) (T / (257.14 + T))). */
static double buck_rh(double t, double td)
{
    double et = 6.1121 * exp((18.678 - t / 234.5) * (t / (257.14 + t)));
    double ed = 6.1121 * exp((18.678 - td / 234.5) * (td / (257.14 + td)));
    return ed / et;
}

static void check_layer(const struct proto_metar_report *r, int i,
                        enum proto_metar_cloud_amount amount, double coverage, int base_ft, bool cb,
                        bool tcu)
{
    if (i >= r->layer_count) {
        CHECK_MSG(i < r->layer_count, "layer %d of %d", i, r->layer_count);
        return;
    }
    const struct proto_metar_cloud_layer *l = &r->layers[i];
    CHECK_INT(l->amount, amount);
    CHECK_NEAR(l->coverage, coverage, 1e-12);
    CHECK(l->base_known);
    CHECK_INT(l->base_ft, base_ft);
    CHECK_NEAR(l->base_m, base_ft * FT, 1e-9);
    CHECK_INT(l->cumulonimbus, cb);
    CHECK_INT(l->towering_cumulus, tcu);
}

static void check_rh(const struct proto_metar_report *r, double t, double td)
{
    CHECK(r->temperature_known && r->dew_point_known && r->relative_humidity_known);
    CHECK_DOUBLE(r->temperature_c, t);
    CHECK_DOUBLE(r->dew_point_c, td);
    CHECK_NEAR(r->relative_humidity, buck_rh(t, td), 0.005); /* within 0.5 % */
}

static void check_visibility(const struct proto_metar_report *r, double metres,
                             enum proto_metar_bound bound)
{
    CHECK(r->visibility.reported);
    CHECK_NEAR(r->visibility.metres, metres, 1e-9);
    CHECK_INT(r->visibility.bound, bound);
    CHECK_NEAR(r->visibility.extinction_per_m, 3.912 / metres, 1e-12);
    CHECK_NEAR(r->visibility.extinction_per_km, 3912.0 / metres, 1e-9);
}

/* ICAO Annex 3, appendix 3, example A3-1 (routine report) and A3-2 (special report). */
static void test_annex3_examples(void)
{
    check_case_name = "Annex 3 A3-1";
    struct proto_metar_report r;
    if (decode_ok("METAR YUDO 221630Z 24004MPS 0600 R12/1000U DZ FG SCT010 OVC020 17/16 Q1018 "
                  "BECMG TL1700 0800 FG BECMG AT1800 9999 NSW",
                  &r)) {
        CHECK_INT(r.type, PROTO_METAR_TYPE_METAR);
        CHECK_STR(r.station, "YUDO");
        CHECK(r.day == 22 && r.hour == 16 && r.minute == 30);
        CHECK(r.wind.reported && r.wind.direction_known && !r.wind.variable);
        CHECK_DOUBLE(r.wind.direction_deg, 240);
        CHECK_DOUBLE(r.wind.speed_m_s, 4.0);
        CHECK_STR(r.wind.unit, "MPS");
        check_visibility(&r, 600, PROTO_METAR_EXACT); /* the trend's 9999 is not read */
        CHECK_INT(r.weather.drizzle, PROTO_METAR_MODERATE);
        CHECK_INT(r.weather.precipitation, PROTO_METAR_MODERATE);
        CHECK_INT(r.weather.rain, PROTO_METAR_NONE);
        CHECK(r.weather.fog && !r.weather.mist && !r.weather.fog_partial);
        CHECK_INT(r.weather.group_count, 2);
        CHECK_INT(r.sky, PROTO_METAR_SKY_LAYERS);
        CHECK_INT(r.layer_count, 2);
        check_layer(&r, 0, PROTO_METAR_SCT, 3.5 / 8, 1000, false, false);
        check_layer(&r, 1, PROTO_METAR_OVC, 1.0, 2000, false, false);
        check_rh(&r, 17, 16);
    }
    check_case_name = "Annex 3 A3-2";
    if (decode_ok("SPECI YUDO 151115Z 05025G37KT 3000 1200NE +TSRA BKN005CB 25/22 Q1008 TEMPO "
                  "TL1200 0600 BECMG AT1200 8000 NSW NSC",
                  &r)) {
        CHECK_INT(r.type, PROTO_METAR_TYPE_SPECI);
        CHECK_DOUBLE(r.wind.direction_deg, 50);
        CHECK_NEAR(r.wind.speed_m_s, 25 * KT, 1e-12);
        CHECK(r.wind.gust_reported);
        CHECK_NEAR(r.wind.gust_m_s, 37 * KT, 1e-12);
        check_visibility(&r, 3000, PROTO_METAR_EXACT);
        CHECK_INT(r.weather.rain, PROTO_METAR_HEAVY);
        CHECK_INT(r.weather.showers, PROTO_METAR_NONE);
        CHECK(r.weather.thunderstorm);
        CHECK_INT(r.layer_count, 1);
        check_layer(&r, 0, PROTO_METAR_BKN, 6.0 / 8, 500, true, false);
        check_rh(&r, 25, 22);
    }
    /* FM 15 with runway visual range in fog and the sky obscured. */
    check_case_name = "FM 15 fog, RVR, VV";
    if (decode_ok("METAR LOWW 010600Z 00000KT 0150 R29/0300N R34/0250V0400U FG VV001 M02/M02 "
                  "Q1021=",
                  &r)) {
        CHECK(r.wind.calm && r.wind.speed_known);
        CHECK_DOUBLE(r.wind.speed_m_s, 0);
        check_visibility(&r, 150, PROTO_METAR_EXACT);
        CHECK(r.weather.fog);
        CHECK_INT(r.sky, PROTO_METAR_SKY_OBSCURED);
        CHECK(r.vertical_visibility_known);
        CHECK_NEAR(r.vertical_visibility_m, 100 * FT, 1e-9);
        CHECK_INT(r.layer_count, 0);
        CHECK_NEAR(r.relative_humidity, 1.0, 1e-12);
    }
    check_case_name = "";
}

static void test_real_reports(void)
{
    struct proto_metar_report r;
    check_case_name = "EGLL";
    if (decode_ok("METAR EGLL 281250Z 24015G28KT 9999 -SHRA FEW012 BKN025CB 12/08 Q1002 NOSIG=",
                  &r)) {
        CHECK_DOUBLE(r.wind.direction_deg, 240);
        CHECK_NEAR(r.wind.speed_m_s, 7.716666666666667, 1e-12);
        CHECK_NEAR(r.wind.gust_m_s, 14.404444444444444, 1e-12);
        check_visibility(&r, 10000, PROTO_METAR_AT_LEAST);
        CHECK_NEAR(r.visibility.extinction_per_km, 0.3912, 1e-12);
        CHECK_INT(r.weather.rain, PROTO_METAR_LIGHT);
        CHECK_INT(r.weather.showers, PROTO_METAR_LIGHT);
        CHECK_INT(r.weather.precipitation, PROTO_METAR_LIGHT);
        CHECK_INT(r.layer_count, 2);
        check_layer(&r, 0, PROTO_METAR_FEW, 0.1875, 1200, false, false);
        check_layer(&r, 1, PROTO_METAR_BKN, 0.75, 2500, true, false);
        CHECK_NEAR(r.layers[0].base_m, 365.76, 1e-9);
        CHECK_NEAR(r.layers[1].base_m, 762.0, 1e-9);
        check_rh(&r, 12, 8);
        /* A psychrometric table's value for 12 C over a dew point of 8 C: 76.5 %. */
        CHECK_NEAR(r.relative_humidity, 0.765, 0.005);
    }
    check_case_name = "KJFK";
    if (decode_ok("METAR KJFK 281251Z 31012KT 10SM FEW045 SCT250 22/12 A3002 RMK AO2 SLP165 "
                  "T02170122",
                  &r)) {
        CHECK_NEAR(r.wind.speed_m_s, 12 * KT, 1e-12);
        check_visibility(&r, 10 * MILE, PROTO_METAR_EXACT);
        check_layer(&r, 0, PROTO_METAR_FEW, 1.5 / 8, 4500, false, false);
        check_layer(&r, 1, PROTO_METAR_SCT, 3.5 / 8, 25000, false, false);
        CHECK_NEAR(r.layers[1].base_m, 7620.0, 1e-9);
        check_rh(&r, 22, 12);
    }
    check_case_name = "KORD thunderstorm";
    if (decode_ok("SPECI KORD 281315Z 27015G25KT 1 1/2SM +TSRA BR BKN008 OVC020CB 18/17 A2985 "
                  "RMK AO2 PK WND 27035/1308 TSB05 PRESFR $",
                  &r)) {
        CHECK_INT(r.type, PROTO_METAR_TYPE_SPECI);
        check_visibility(&r, 1.5 * MILE, PROTO_METAR_EXACT);
        CHECK_INT(r.weather.rain, PROTO_METAR_HEAVY);
        CHECK(r.weather.thunderstorm && r.weather.mist && !r.weather.fog);
        check_layer(&r, 0, PROTO_METAR_BKN, 0.75, 800, false, false);
        check_layer(&r, 1, PROTO_METAR_OVC, 1.0, 2000, true, false);
        check_rh(&r, 18, 17);
    }
    check_case_name = "KDEN AUTO calm CLR";
    if (decode_ok("METAR KDEN 281253Z AUTO 00000KT 10SM CLR M05/M10 A3021 RMK AO2", &r)) {
        CHECK(r.automatic && r.wind.calm);
        CHECK_INT(r.sky, PROTO_METAR_SKY_CLR);
        CHECK_INT(r.layer_count, 0);
        check_rh(&r, -5, -10);
    }
    check_case_name = "KSFO fog, VV002";
    if (decode_ok("METAR KSFO 281256Z 28008KT 1/4SM FG VV002 12/12 A2995 RMK AO2", &r)) {
        check_visibility(&r, 0.25 * MILE, PROTO_METAR_EXACT);
        CHECK(r.weather.fog);
        CHECK_INT(r.sky, PROTO_METAR_SKY_OBSCURED);
        CHECK_NEAR(r.vertical_visibility_m, 60.96, 1e-9);
        CHECK_NEAR(r.relative_humidity, 1.0, 1e-12);
    }
    check_case_name = "KBOS snow, M1/4SM, VV///";
    if (decode_ok("METAR KBOS 281254Z 05010KT M1/4SM +SN FZFG VV/// M03/M03 A2990", &r)) {
        check_visibility(&r, 0.25 * MILE, PROTO_METAR_LESS_THAN);
        CHECK_INT(r.weather.snow, PROTO_METAR_HEAVY);
        CHECK(r.weather.fog && r.weather.freezing);
        CHECK_INT(r.sky, PROTO_METAR_SKY_OBSCURED);
        CHECK(!r.vertical_visibility_known);
    }
    check_case_name = "KLAX P6SM";
    if (decode_ok("METAR KLAX 281253Z 25006KT P6SM SCT020 18/14 A2992", &r))
        check_visibility(&r, 6 * MILE, PROTO_METAR_AT_LEAST);
    check_case_name = "";
}

static void test_clouds(void)
{
    struct proto_metar_report r;
    check_case_name = "every amount, TCU, sorted";
    /* Given out of order: the decoder sorts the layers by base. */
    if (decode_ok("METAR ZZZZ 010000Z 18005KT 9999 OVC030 FEW005 BKN020 SCT010TCU 10/05 Q1015",
                  &r)) {
        CHECK_INT(r.layer_count, 4);
        check_layer(&r, 0, PROTO_METAR_FEW, 1.5 / 8, 500, false, false);
        check_layer(&r, 1, PROTO_METAR_SCT, 3.5 / 8, 1000, false, true);
        check_layer(&r, 2, PROTO_METAR_BKN, 6.0 / 8, 2000, false, false);
        check_layer(&r, 3, PROTO_METAR_OVC, 1.0, 3000, false, false);
        CHECK(r.layers[0].oktas_min == 1 && r.layers[0].oktas_max == 2);
        CHECK(r.layers[2].oktas_min == 5 && r.layers[2].oktas_max == 7);
        CHECK(r.layers[3].oktas_min == 8 && r.layers[3].oktas_max == 8);
    }
    check_case_name = "automatic station: unknown heights and types";
    if (decode_ok("METAR LFPG 281230Z AUTO 24010KT 9999NDV BKN///TCU SCT030/// //////CB ////// "
                  "15/10 Q1015",
                  &r)) {
        CHECK(r.visibility.ndv);
        CHECK_INT(r.layer_count, 3); /* ////// alone says nothing and is not kept */
        CHECK_INT(r.layers[0].amount, PROTO_METAR_SCT);
        CHECK(r.layers[0].type_unknown);
        CHECK_INT(r.layers[1].amount, PROTO_METAR_BKN); /* unknown bases after the known ones */
        CHECK(!r.layers[1].base_known && r.layers[1].towering_cumulus);
        CHECK_INT(r.layers[2].amount, PROTO_METAR_AMOUNT_UNKNOWN);
        CHECK(r.layers[2].cumulonimbus && r.layers[2].coverage == 0);
    }
    static const struct {
        const char *group;
        enum proto_metar_sky sky;
    } words[] = { { "NSC", PROTO_METAR_SKY_NSC },
                  { "NCD", PROTO_METAR_SKY_NCD },
                  { "SKC", PROTO_METAR_SKY_SKC },
                  { "CLR", PROTO_METAR_SKY_CLR },
                  { "VV///", PROTO_METAR_SKY_OBSCURED } };
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++) {
        char text[128];
        snprintf(text, sizeof text, "METAR ZZZZ 010000Z 18005KT 9999 %s 10/05 Q1015",
                 words[i].group);
        check_case_name = words[i].group;
        if (decode_ok(text, &r)) {
            CHECK_INT(r.sky, words[i].sky);
            CHECK_INT(r.layer_count, 0);
        }
    }
    check_case_name = "CAVOK";
    if (decode_ok("METAR LIRF 281250Z 18010KT 150V210 CAVOK 25/15 Q1015 NOSIG", &r)) {
        CHECK(r.cavok);
        CHECK_INT(r.sky, PROTO_METAR_SKY_CAVOK);
        check_visibility(&r, 10000, PROTO_METAR_AT_LEAST);
        CHECK_INT(r.layer_count, 0);
        CHECK(r.wind.sector && r.wind.variable && r.wind.direction_known);
        CHECK(r.wind.sector_from_deg == 150 && r.wind.sector_to_deg == 210);
    }
    check_case_name = "no cloud group";
    if (decode_ok("METAR ZZZZ 010000Z 18005KT 9999 10/05", &r))
        CHECK_INT(r.sky, PROTO_METAR_SKY_NOT_REPORTED);
    check_case_name = "";
}

static void test_wind_visibility_temperature(void)
{
    struct proto_metar_report r;
    check_case_name = "VRB, km/h, 0000";
    if (decode_ok("METAR UUEE 010300Z VRB36KMH 0000 FG VV000 M12/M15 Q1030", &r)) {
        CHECK(r.wind.variable && !r.wind.direction_known && !r.wind.sector);
        CHECK_NEAR(r.wind.speed_m_s, 10.0, 1e-12);
        CHECK_STR(r.wind.unit, "KMH");
        check_visibility(&r, 50, PROTO_METAR_LESS_THAN);
        CHECK_NEAR(r.visibility.extinction_per_km, 78.24, 1e-9);
        check_rh(&r, -12, -15);
    }
    check_case_name = "wind and visibility not observed, temperatures missing";
    if (decode_ok("METAR ZZZZ 010000Z AUTO /////KT //// ///// Q////", &r)) {
        CHECK(!r.wind.reported && !r.visibility.reported);
        CHECK_DOUBLE(r.visibility.extinction_per_m, 0);
        CHECK(!r.temperature_known && !r.dew_point_known && !r.relative_humidity_known);
    }
    check_case_name = "dew point missing, gust over 99 kt";
    if (decode_ok("METAR ZZZZ 010000Z 09090GP99KT 4000 1500SW 12/// Q0990", &r)) {
        CHECK_NEAR(r.wind.speed_m_s, 90 * KT, 1e-12);
        CHECK_NEAR(r.wind.gust_m_s, 99 * KT, 1e-12);
        CHECK(r.wind.gust_above && !r.wind.speed_above);
        CHECK(r.temperature_known && !r.dew_point_known && !r.relative_humidity_known);
    }
    check_case_name = "three-digit speeds, P49MPS";
    if (decode_ok("METAR ZZZZ 010000Z 090105G130KT 4000 12/10", &r)) {
        CHECK_NEAR(r.wind.speed_m_s, 105 * KT, 1e-12);
        CHECK_NEAR(r.wind.gust_m_s, 130 * KT, 1e-12);
    }
    if (decode_ok("METAR ZZZZ 010000Z 090P49MPS 4000 12/10", &r))
        CHECK(r.wind.speed_above && r.wind.speed_m_s == 49);
    check_case_name = "M00 and direction unknown";
    if (decode_ok("METAR ZZZZ 010000Z ///05KT 9999 M00/M01 Q1000", &r)) {
        CHECK(r.wind.reported && !r.wind.direction_known && r.wind.speed_known);
        CHECK_DOUBLE(r.temperature_c, 0);
        check_rh(&r, 0, -1);
    }
    check_case_name = "";
}

static void test_weather(void)
{
    struct proto_metar_report r;
    check_case_name = "mixed precipitation, vicinity";
    if (decode_ok("METAR ZZZZ 010000Z 18005KT 3000 -RASN BR VCTS BKN010 02/01 Q1000", &r)) {
        CHECK_INT(r.weather.rain, PROTO_METAR_LIGHT);
        CHECK_INT(r.weather.snow, PROTO_METAR_LIGHT);
        CHECK(r.weather.mist && r.weather.thunderstorm_nearby && !r.weather.thunderstorm);
        CHECK_STR(r.weather.groups[2], "VCTS");
    }
    check_case_name = "showers, hail, partial fog";
    if (decode_ok("METAR ZZZZ 010000Z 18005KT 3000 +SHSN TSGR BCFG BKN010 02/01 Q1000", &r)) {
        CHECK_INT(r.weather.snow, PROTO_METAR_HEAVY);
        CHECK_INT(r.weather.showers, PROTO_METAR_HEAVY);
        CHECK_INT(r.weather.precipitation, PROTO_METAR_HEAVY);
        CHECK(r.weather.hail && r.weather.thunderstorm);
        CHECK(r.weather.fog_partial && !r.weather.fog);
    }
    check_case_name = "freezing drizzle, nearby showers and fog";
    if (decode_ok("METAR ZZZZ 010000Z 18005KT 3000 FZDZ VCSH VCFG OVC004 M01/M02 Q1000", &r)) {
        CHECK_INT(r.weather.drizzle, PROTO_METAR_MODERATE);
        CHECK(r.weather.freezing && r.weather.showers_nearby && r.weather.fog_nearby);
        CHECK_INT(r.weather.showers, PROTO_METAR_NONE);
    }
    check_case_name = "";
}

/* Identification, supplementary groups, trends, remarks, '=' and blanks. */
static void test_structure(void)
{
    struct proto_metar_report r;
    check_case_name = "COR before the station, recent weather, wind shear, sea, runway state";
    if (decode_ok("METAR COR LGAT 281250Z 36020KT 9999 FEW030 28/12 Q1012 RETSRA WS R03L "
                  "WS ALL RWY W19/S3 W12/H14 R03/290050 R21/CLRD70 R/SNOCLO NOSIG",
                  &r)) {
        CHECK(r.correction && !r.automatic);
        CHECK_STR(r.station, "LGAT");
    }
    check_case_name = "no type, COR after the time, line breaks, lone '='";
    if (decode_ok("EDDF 281250Z COR 27010KT\r\n 9999 SCT040\n 20/10 Q1015\n=\n", &r)) {
        CHECK_INT(r.type, PROTO_METAR_TYPE_METAR);
        CHECK(r.correction);
        check_layer(&r, 0, PROTO_METAR_SCT, 3.5 / 8, 4000, false, false);
    }
    check_case_name = "remarks hold anything printable";
    if (decode_ok("METAR KXYZ 281250Z 27010KT 10SM BKN040 20/10 A3000 RMK A&B (1.5) #x? $=", &r))
        check_layer(&r, 0, PROTO_METAR_BKN, 0.75, 4000, false, false);
    check_case_name = "NIL";
    if (decode_ok("METAR EGLL 281250Z NIL=", &r)) {
        CHECK(r.nil && r.day == 28);
        CHECK(!r.wind.reported && !r.visibility.reported && !r.temperature_known);
    }
    check_case_name = "a report of the longest length";
    {
        char text[PROTO_METAR_MAX_LENGTH + 1];
        int n = snprintf(text, sizeof text, "METAR EGLL 281250Z 24015KT 9999 12/08 RMK ");
        memset(text + n, 'X', sizeof text - 1 - (size_t)n);
        text[PROTO_METAR_MAX_LENGTH] = '\0';
        struct proto_metar_error error;
        CHECK(proto_metar_decode(text, PROTO_METAR_MAX_LENGTH, &r, &error));
        /* The length counts, not the NUL: a shorter length reads a shorter report. */
        CHECK(proto_metar_decode(text, 37, &r, &error));
    }
    check_case_name = "";
}

static void test_relative_humidity(void)
{
    /* Table values (Magnus over water) and Buck's formula across the range of METARs. */
    CHECK_NEAR(proto_metar_relative_humidity(20, 10), 0.525, 0.005);
    CHECK_NEAR(proto_metar_relative_humidity(30, 5), 0.206, 0.005);
    CHECK_NEAR(proto_metar_relative_humidity(10, 10), 1.0, 1e-12);
    CHECK_NEAR(proto_metar_relative_humidity(10, 11), 1.0, 1e-12); /* capped */
    for (int t = -40; t <= 45; t += 5)
        for (int spread = 0; spread <= 30; spread += 3)
            CHECK_NEAR(proto_metar_relative_humidity(t, t - spread), buck_rh(t, t - spread), 0.005);
}

static void test_json(void)
{
    struct proto_metar_report r;
    check_case_name = "JSON";
    if (!decode_ok("METAR EGLL 281250Z 24015G28KT 200V280 9999 -SHRA FEW012 BKN025CB 12/08 "
                   "Q1002 NOSIG=",
                   &r))
        return;
    cJSON *json = proto_metar_to_json(&r);
    CHECK(json != NULL);
    if (!json)
        return;
    CHECK_STR(cJSON_GetObjectItem(json, "station")->valuestring, "EGLL");
    CHECK_DOUBLE(cJSON_GetObjectItem(cJSON_GetObjectItem(json, "observed"), "minute")->valuedouble,
                 50);
    cJSON *wind = cJSON_GetObjectItem(json, "wind");
    CHECK_NEAR(cJSON_GetObjectItem(wind, "gust_m_s")->valuedouble, 28 * KT, 1e-12);
    CHECK_DOUBLE(cJSON_GetArrayItem(cJSON_GetObjectItem(wind, "sector_deg"), 1)->valuedouble, 280);
    cJSON *visibility = cJSON_GetObjectItem(json, "visibility");
    CHECK_STR(cJSON_GetObjectItem(visibility, "bound")->valuestring, "at_least");
    CHECK_NEAR(cJSON_GetObjectItem(visibility, "extinction_per_km")->valuedouble, 0.3912, 1e-12);
    cJSON *clouds = cJSON_GetObjectItem(json, "clouds");
    CHECK_INT(cJSON_GetArraySize(clouds), 2);
    cJSON *bkn = cJSON_GetArrayItem(clouds, 1);
    CHECK_STR(cJSON_GetObjectItem(bkn, "amount")->valuestring, "BKN");
    CHECK_DOUBLE(cJSON_GetObjectItem(bkn, "coverage")->valuedouble, 0.75);
    CHECK_NEAR(cJSON_GetObjectItem(bkn, "base_m")->valuedouble, 762, 1e-9);
    CHECK(cJSON_IsTrue(cJSON_GetObjectItem(bkn, "cumulonimbus")));
    CHECK(cJSON_IsNull(cJSON_GetObjectItem(json, "vertical_visibility_m")));
    cJSON *weather = cJSON_GetObjectItem(json, "weather");
    CHECK_STR(cJSON_GetObjectItem(weather, "rain")->valuestring, "light");
    CHECK_STR(cJSON_GetArrayItem(cJSON_GetObjectItem(weather, "groups"), 0)->valuestring, "-SHRA");
    CHECK_NEAR(cJSON_GetObjectItem(json, "relative_humidity")->valuedouble, buck_rh(12, 8), 0.005);
    cJSON_Delete(json);

    /* Unknowns are null. */
    if (decode_ok("METAR ZZZZ 010000Z /////KT //// ///// Q////", &r)) {
        json = proto_metar_to_json(&r);
        CHECK(json && cJSON_IsNull(cJSON_GetObjectItem(json, "wind")) &&
              cJSON_IsNull(cJSON_GetObjectItem(json, "visibility")) &&
              cJSON_IsNull(cJSON_GetObjectItem(json, "temperature_c")) &&
              cJSON_IsNull(cJSON_GetObjectItem(json, "relative_humidity")));
        cJSON_Delete(json);
    }
    char summary[512];
    if (decode_ok("METAR EGLL 281250Z 24015G28KT 9999 -SHRA FEW012 BKN025CB 12/08 Q1002", &r)) {
        proto_metar_summary(&r, summary, sizeof summary);
        CHECK_CONTAINS(summary, "EGLL day 28 12:50Z");
        CHECK_CONTAINS(summary, "BKN 762 m CB");
        CHECK_CONTAINS(summary, "RH 77 %");
        proto_metar_summary(&r, summary, 10); /* cut, still terminated */
        CHECK_INT(strlen(summary), 9);
    }
    check_case_name = "";
}

static double unix_time(const char *iso)
{
    double t = 0;
    CHECK(proto_time_parse_iso8601(iso, &t, NULL, 0));
    return t;
}

static void test_observation_time(void)
{
    struct proto_metar_report r;
    double t = 0;
    if (!decode_ok("METAR EGLL 281250Z 24015KT 9999 12/08", &r))
        return;
    CHECK(proto_metar_observation_unix(&r, unix_time("2026-03-02T00:00:00Z"), &t));
    CHECK_DOUBLE(t, unix_time("2026-02-28T12:50:00Z"));
    CHECK(proto_metar_observation_unix(&r, unix_time("2026-02-28T12:30:00Z"), &t)); /* slow clock */
    CHECK_DOUBLE(t, unix_time("2026-02-28T12:50:00Z"));
    CHECK(
        proto_metar_observation_unix(&r, unix_time("2026-02-28T11:00:00Z"), &t)); /* a month back */
    CHECK_DOUBLE(t, unix_time("2026-01-28T12:50:00Z"));
    r.day = 30; /* February has no 30th: January */
    CHECK(proto_metar_observation_unix(&r, unix_time("2026-03-02T00:00:00Z"), &t));
    CHECK_DOUBLE(t, unix_time("2026-01-30T12:50:00Z"));
    r.day = 1;
    CHECK(proto_metar_observation_unix(&r, unix_time("2026-01-01T00:00:00Z"), &t)); /* year back */
    CHECK_DOUBLE(t, unix_time("2025-12-01T12:50:00Z"));
    r.nil = true;
    CHECK(!proto_metar_observation_unix(&r, unix_time("2026-03-02T00:00:00Z"), &t));
}

/* The text of the block fenced by "```FENCE" and "```" in doc, malloc'd; NULL when absent. */
static char *fenced_block(const char *doc, const char *fence)
{
    char opening[64];
    snprintf(opening, sizeof opening, "```%s\n", fence);
    const char *start = strstr(doc, opening);
    const char *end = start ? strstr(start + strlen(opening), "```") : NULL;
    if (!end)
        return NULL;
    start += strlen(opening);
    char *text = malloc((size_t)(end - start) + 1);
    if (text) {
        memcpy(text, start, (size_t)(end - start));
        text[end - start] = '\0';
    }
    return text;
}

/* PROTOCOL.md's "METAR decoding" example: its report decodes to exactly its JSON. */
static void test_protocol_example(const char *path)
{
    check_case_name = "PROTOCOL.md example";
    FILE *file = fopen(path, "rb");
    CHECK_MSG(file != NULL, "cannot open %s", path);
    if (!file)
        return;
    static char doc[1 << 20];
    size_t n = fread(doc, 1, sizeof doc - 1, file);
    fclose(file);
    doc[n] = '\0';
    char *report_text = fenced_block(doc, "text metar-report");
    char *json_text = fenced_block(doc, "json metar");
    CHECK(report_text && json_text);
    cJSON *documented = json_text ? cJSON_Parse(json_text) : NULL;
    CHECK_MSG(documented != NULL, "the documented JSON does not parse");
    struct proto_metar_report r;
    size_t length = report_text ? strcspn(report_text, "\n") : 0;
    if (report_text && documented) {
        report_text[length] = '\0';
        if (decode_ok(report_text, &r)) {
            cJSON *decoded = proto_metar_to_json(&r);
            bool same = decoded && cJSON_Compare(documented, decoded, true);
            char *printed = decoded ? cJSON_PrintUnformatted(decoded) : NULL;
            CHECK_MSG(same, "the decoder gives %s", printed ? printed : "(nothing)");
            free(printed);
            cJSON_Delete(decoded);
        }
    }
    cJSON_Delete(documented);
    free(report_text);
    free(json_text);
    check_case_name = "";
}

int main(int argc, char **argv)
{
    test_protocol_example(argc > 1 ? argv[1] : SKYD_SOURCE_DIR "/protocol/PROTOCOL.md");
    test_annex3_examples();
    test_real_reports();
    test_clouds();
    test_wind_visibility_temperature();
    test_weather();
    test_structure();
    test_relative_humidity();
    test_json();
    test_observation_time();
    test_metar_refusals();
    return check_summary();
}
