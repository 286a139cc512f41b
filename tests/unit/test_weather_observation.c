/* METAR to world-state patch (protocol/weather_observation.c): each report decoded, mapped and
 * the patch applied to the default world, which must take it; then the layers, fog, humidity,
 * wind and precipitation checked against what the report says. The renderer's humidity fog is
 * compared with the mapper's copy of it, so the two cannot drift apart. A forecast's rates
 * become precipitation levels on the same scale (server/forecast/forecast_patch.c). */
#include "field_errors.h"
#include "forecast.h"
#include "metar.h"
#include "weather_observation.h"
#include "world_render.h"
#include "world_state.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

/* The default world with the report's patch applied; *unmapped: how many groups were left. */
static struct proto_world_state mapped(const char *text, int *unmapped_count, cJSON **unmapped_out)
{
    struct proto_world_state state;
    proto_world_state_defaults(&state);
    struct proto_metar_report report;
    struct proto_metar_error error;
    bool decoded = proto_metar_decode(text, strlen(text), &report, &error);
    CHECK_MSG(decoded, "%s: %s", text, error.message);
    cJSON *patch = NULL, *unmapped = NULL;
    char why[160] = "";
    bool ok = decoded && proto_obs_metar_patch(&report, &patch, &unmapped, why, sizeof why);
    CHECK_MSG(ok, "%s: %s", text, why);
    if (ok) {
        struct proto_field_errors errors;
        proto_field_errors_clear(&errors);
        bool applied = proto_world_state_apply_json(&state, patch, &errors);
        char *json = cJSON_PrintUnformatted(patch);
        char reasons[512];
        proto_field_errors_format(&errors, reasons, sizeof reasons);
        CHECK_MSG(applied, "%s: the patch %s is refused: %s", text, json, reasons);
        cJSON_free(json);
        *unmapped_count = cJSON_GetArraySize(unmapped);
    }
    cJSON_Delete(patch);
    if (unmapped_out)
        *unmapped_out = unmapped;
    else
        cJSON_Delete(unmapped);
    return state;
}

static void test_fair_cumulus(void)
{
    int unmapped = -1;
    struct proto_world_state s = mapped("METAR LFLY 281200Z 18008KT 9999 FEW040 22/10 Q1018",
                                        &unmapped, NULL);
    CHECK_NEAR(s.clouds.low.coverage, 1.5 / 8.0, 1e-9); /* FEW: 1-2 oktas */
    CHECK_NEAR(s.clouds.low.bottom_km, 4000 * 0.3048 / 1000.0, 1e-9);
    CHECK_NEAR(s.clouds.low.type, 2.0 / 3.0, 1e-9); /* cumulus */
    CHECK_NEAR(s.clouds.high.coverage, 0.0, 0);
    CHECK_NEAR(s.clouds.precipitation, 0.0, 0);
    CHECK_NEAR(s.atmosphere.fog_density_per_km, 0.0, 0); /* 9999: no fog */
    CHECK_NEAR(s.weather.humidity, proto_metar_relative_humidity(22, 10), 1e-9);
    CHECK(s.weather.source == PROTO_WEATHER_SOURCE_METAR);
    CHECK(s.weather.autopilot == PROTO_SWITCH_OFF);
    /* 8 kt at 10 m is 4.1 m/s; at the 1.2 km base (1219/10)^(1/7) = 1.99 times that. */
    CHECK_NEAR(s.weather.wind.speed_m_s, 8 * 1852.0 / 3600.0 * pow(121.92, 1.0 / 7.0), 1e-6);
    CHECK_NEAR(s.weather.wind.direction_deg, 180.0, 0);
    CHECK(unmapped == 0);
}

static void test_fog(void)
{
    int unmapped = -1;
    struct proto_world_state s = mapped("METAR EGLL 280650Z 00000KT 0200 FG OVC005 08/08 Q1025",
                                        &unmapped, NULL);
    CHECK_NEAR(s.clouds.low.coverage, 1.0, 0);
    CHECK_NEAR(s.clouds.low.type, 0.0, 0); /* overcast below 600 m: stratus */
    CHECK_NEAR(s.clouds.low.bottom_km, 0.1524, 1e-9);
    CHECK_NEAR(s.weather.wind.speed_m_s, 0.0, 0);
    /* 200 m: 3.912 / 0.2 = 19.56 /km in all, the humidity fog and the fog term together. */
    double total = s.atmosphere.fog_density_per_km + world_humidity_fog_per_km(s.weather.humidity);
    CHECK_NEAR(total, 3.912 / 0.2 - PROTO_OBS_CLEAR_EXTINCTION_PER_KM, 1e-6);
    CHECK(s.atmosphere.fog_density_per_km > 15.0);
    CHECK_NEAR(s.weather.humidity, 1.0, 1e-9); /* T = Td */
    CHECK_NEAR(s.atmosphere.fog_scale_height_km, 0.2, 1e-9);
    CHECK(unmapped == 0);
}

static void test_clear(void)
{
    const char *reports[] = {
        "METAR LFPG 281230Z 27010KT CAVOK 18/12 Q1020",
        "METAR EDDF 281220Z 25006KT 9999 NSC 15/07 Q1019",
        "METAR KSFO 281256Z AUTO 28012KT 10SM CLR 17/09 A3001",
        "METAR EHAM 281225Z 24008KT 9999 SKC 14/06 Q1021",
    };
    for (size_t i = 0; i < sizeof reports / sizeof reports[0]; i++) {
        int unmapped = -1;
        struct proto_world_state s = mapped(reports[i], &unmapped, NULL);
        CHECK_MSG(s.clouds.low.coverage == 0 && s.clouds.high.coverage == 0, "%s", reports[i]);
        CHECK_MSG(s.atmosphere.fog_density_per_km == 0, "%s", reports[i]);
        /* At least 10 km: the humidity fog stays within 3.912 / 10 km. */
        CHECK_LE(world_humidity_fog_per_km(s.weather.humidity), 0.3912);
    }
    /* A humid CAVOK: the humidity held where its fog keeps 10 km. */
    int unmapped = -1;
    struct proto_world_state s = mapped("METAR LFPG 280530Z 00000KT CAVOK 10/10 Q1020", &unmapped,
                                        NULL);
    CHECK(s.weather.humidity < 0.95 && s.weather.humidity > PROTO_OBS_FOG_ONSET_HUMIDITY);
    CHECK_LE(world_humidity_fog_per_km(s.weather.humidity),
             0.3912 - PROTO_OBS_CLEAR_EXTINCTION_PER_KM + 1e-6);
}

static void test_middle_etage(void)
{
    /* The middle étage's groups go to clouds.mid: BKN and OVC altostratus sheets (type 0, 1.5 km
     * deep), FEW and SCT altocumulus (type 1, 0.5 km); the low layer is left clear. */
    int unmapped = -1;
    cJSON *list = NULL;
    struct proto_world_state s = mapped("METAR LFLY 281200Z 18008KT 9999 BKN100 12/05 Q1010",
                                        &unmapped, &list);
    CHECK(strcmp(proto_obs_etage_layer(PROTO_OBS_ETAGE_MIDDLE), "mid") == 0);
    CHECK_NEAR(s.clouds.mid.coverage, 6.0 / 8.0, 1e-9);
    CHECK_NEAR(s.clouds.mid.bottom_km, 3.048, 1e-9);
    CHECK_NEAR(s.clouds.mid.type, 0.0, 0);
    CHECK_NEAR(s.clouds.mid.thickness_km, 1.5, 1e-9);
    CHECK_NEAR(s.clouds.low.coverage, 0.0, 0);
    CHECK(unmapped == 0);
    cJSON_Delete(list);
    /* With a low group beside it, each étage keeps its own: nothing left unmapped. */
    s = mapped("METAR LFLY 281200Z 18008KT 9999 SCT030 SCT100 OVC250 12/05 Q1010", &unmapped,
               &list);
    CHECK_NEAR(s.clouds.low.coverage, 3.5 / 8.0, 1e-9);
    CHECK_NEAR(s.clouds.low.bottom_km, 0.9144, 1e-9);
    CHECK_NEAR(s.clouds.mid.coverage, 3.5 / 8.0, 1e-9);
    CHECK_NEAR(s.clouds.mid.type, 1.0, 0); /* SCT100: altocumulus */
    CHECK_NEAR(s.clouds.mid.thickness_km, 0.5, 1e-9);
    CHECK_NEAR(s.clouds.high.coverage, 1.0, 0); /* OVC250: cirrostratus */
    CHECK_NEAR(s.clouds.high.bottom_km, 7.62, 1e-9);
    CHECK(unmapped == 0);
    cJSON_Delete(list);
    /* CAVOK clears the middle layer too. */
    s = mapped("METAR LFLY 281200Z 18008KT CAVOK 12/05 Q1010", &unmapped, NULL);
    CHECK_NEAR(s.clouds.mid.coverage, 0.0, 0);
}

static void test_convection(void)
{
    int unmapped = -1;
    struct proto_world_state s = mapped(
        "METAR LIMC 281450Z 22015G30KT 3000 +TSRA SCT025CB BKN080 25/20 Q1008", &unmapped, NULL);
    CHECK_NEAR(s.clouds.low.type, 1.0, 0); /* cumulonimbus */
    CHECK_NEAR(s.clouds.low.coverage, 3.5 / 8.0, 1e-9);
    CHECK_NEAR(s.clouds.low.thickness_km, 8.0, 0);
    CHECK_NEAR(s.clouds.precipitation, 0.9, 1e-9); /* heavy */
    CHECK(s.atmosphere.fog_density_per_km > 0.5);  /* 3 km in the rain */
    CHECK(unmapped == 0);                          /* BKN080: the middle layer's */
    CHECK_NEAR(s.clouds.mid.coverage, 0.75, 1e-9);
    CHECK_NEAR(s.clouds.mid.type, 0.0, 0); /* altostratus */
    s = mapped("METAR LIMC 281450Z 22010KT 9999 SCT040TCU 25/15 Q1012", &unmapped, NULL);
    CHECK_NEAR(s.clouds.low.type, 0.85, 1e-9);
    /* TS with only a FEW group: the storm's cumulonimbus takes the low layer. */
    s = mapped("METAR LIMC 281450Z 22010KT 9999 TS FEW030 25/15 Q1012", &unmapped, NULL);
    CHECK_NEAR(s.clouds.low.type, 1.0, 0);
    /* TS without any cloud group: a cumulonimbus of SCT amount all the same. */
    s = mapped("METAR LIMC 281450Z 22010KT 9999 TS 25/15 Q1012", &unmapped, NULL);
    CHECK_NEAR(s.clouds.low.type, 1.0, 0);
    CHECK_NEAR(s.clouds.low.coverage, 3.5 / 8.0, 1e-9);
    /* Drizzle is light whatever its sign; light rain 0.3; showers in the vicinity unmapped. */
    s = mapped("METAR EGLL 281150Z 24010KT 5000 DZ VCSH BKN008 12/11 Q1005", &unmapped, NULL);
    CHECK_NEAR(s.clouds.precipitation, 0.3, 1e-9);
    CHECK_NEAR(s.clouds.low.type, 1.0 / 3.0, 1e-9); /* BKN: stratocumulus */
    CHECK(unmapped == 1);
    s = mapped("METAR EGLL 281150Z 24010KT 8000 -RA OVC012 12/09 Q1005", &unmapped, NULL);
    CHECK_NEAR(s.clouds.precipitation, 0.3, 1e-9);
    CHECK_NEAR(s.clouds.low.type, 0.0, 0); /* OVC at 366 m: stratus */
    s = mapped("METAR EGLL 281150Z 24010KT 8000 RA OVC025 12/09 Q1005", &unmapped, NULL);
    CHECK_NEAR(s.clouds.precipitation, 0.6, 1e-9);
    CHECK_NEAR(s.clouds.low.type, 1.0 / 3.0, 1e-9); /* OVC at 762 m: stratocumulus */
}

static void test_vertical_visibility(void)
{
    int unmapped = -1;
    struct proto_world_state s = mapped("METAR EDDM 280620Z 00000KT 0050 FG VV001 02/02 Q1030",
                                        &unmapped, NULL);
    CHECK_NEAR(s.clouds.low.coverage, 1.0, 0);
    CHECK_NEAR(s.clouds.low.type, 0.0, 0);
    CHECK_NEAR(s.clouds.low.bottom_km, 0.03048, 1e-9);
    CHECK(s.atmosphere.fog_density_per_km > 60.0); /* 50 m: 78 /km */
    CHECK_NEAR(s.atmosphere.fog_scale_height_km, 0.05, 1e-9);
}

static void test_refusals(void)
{
    struct proto_metar_report report;
    struct proto_metar_error error;
    const char *nil = "METAR EGLL 281150Z NIL";
    CHECK(proto_metar_decode(nil, strlen(nil), &report, &error));
    cJSON *patch = NULL, *unmapped = NULL;
    char why[160] = "";
    CHECK(!proto_obs_metar_patch(&report, &patch, &unmapped, why, sizeof why));
    CHECK(patch == NULL && unmapped == NULL && strstr(why, "NIL") != NULL);
    /* No cloud group at all: the clouds are left as they are. */
    int count = -1;
    struct proto_world_state s = mapped("METAR EGLL 281150Z 24010KT 9999 12/09 Q1005", &count,
                                        NULL);
    struct proto_world_state d;
    proto_world_state_defaults(&d);
    CHECK_NEAR(s.clouds.low.coverage, d.clouds.low.coverage, 0);
    CHECK_NEAR(s.clouds.low.bottom_km, d.clouds.low.bottom_km, 0);
}

static void test_humidity_fog_matches(void)
{
    for (double h = 0.0; h <= 1.0; h += 0.01)
        CHECK_NEAR(proto_obs_humidity_fog_per_km(h), world_humidity_fog_per_km(h), 1e-12);
    CHECK_NEAR(PROTO_OBS_FOG_ONSET_HUMIDITY, WORLD_FOG_ONSET_HUMIDITY, 0);
}

/* A forecast's rate to clouds.precipitation: the METAR intensities at the AMS rates. */
static void test_forecast_precipitation(void)
{
    CHECK_NEAR(forecast_precipitation_level(0.0), 0.0, 0);
    CHECK_NEAR(forecast_precipitation_level(-1.0), 0.0, 0);
    CHECK_NEAR(forecast_precipitation_level(0.25), 0.15, 1e-12);
    CHECK_NEAR(forecast_precipitation_level(0.5), 0.3, 1e-12);
    CHECK_NEAR(forecast_precipitation_level(4.0), 0.6, 1e-12);
    CHECK_NEAR(forecast_precipitation_level(7.0), 0.75, 1e-12);
    CHECK_NEAR(forecast_precipitation_level(10.0), 0.9, 1e-12);
    CHECK_NEAR(forecast_precipitation_level(20.0), 1.0, 0);
    CHECK_NEAR(forecast_precipitation_level(300.0), 1.0, 0);
}

int main(void)
{
    test_forecast_precipitation();
    test_fair_cumulus();
    test_fog();
    test_clear();
    test_middle_etage();
    test_convection();
    test_vertical_visibility();
    test_refusals();
    test_humidity_fog_matches();
    return check_summary();
}
