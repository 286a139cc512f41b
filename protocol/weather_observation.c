/* METAR to world-state patch (weather_observation.h). Each cloud group goes to its étage by its
 * base (CB and TCU are low-étage clouds whatever their base: their bases form in the boundary
 * layer and they grow through the others); an étage's layer takes the most covering group's
 * amount (the lowest of equals) and the lowest base, the type from what the groups name. */
#include "weather_observation.h"
#include "metar.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define ETAGE_COUNT 3
/* Where each étage's groups go: the world's low, middle and high layers. */
static const struct {
    const char *name;
    const char *layer;
} etages[ETAGE_COUNT] = {
    [PROTO_OBS_ETAGE_LOW] = { "low", "low" },
    [PROTO_OBS_ETAGE_MIDDLE] = { "middle", "mid" },
    [PROTO_OBS_ETAGE_HIGH] = { "high", "high" },
};

/* Low types (world_state.h) and depths of the clouds they stand for, km: fair-weather cumulus
 * about 1.5 km deep, stratocumulus and stratus sheets a few hundred metres, towering cumulus
 * 4 km, cumulonimbus through the troposphere (8 km in mid-latitudes). */
#define TYPE_STRATUS 0.0
#define TYPE_STRATOCUMULUS (1.0 / 3.0)
#define TYPE_CUMULUS (2.0 / 3.0)
#define TYPE_TOWERING 0.85
#define TYPE_CUMULONIMBUS 1.0
/* An overcast deck (stratus, stratocumulus) 800 m deep: optical depth 10 to 40 in nature; the
 * renderer's sheets need that depth to hide the sun's disc (400 m still shows it). */
#define OVERCAST_DEPTH_KM 0.8
#define STRATUS_BELOW_M 600.0 /* an overcast this low is stratus (Sc bases: 600 m and up) */
/* A thunderstorm with no cloud group places a cumulonimbus of SCT amount at a typical base. */
#define STORM_BASE_KM 1.0
/* The wind at the clouds from the 10 m wind: the neutral power law u(z) = u10 (z / 10 m)^(1/7),
 * at the low layer's base (1 km when there is none). */
#define WIND_POWER_EXPONENT (1.0 / 7.0)
#define WIND_REFERENCE_M 10.0
/* Precipitation 0..1 by intensity; drizzle is light by nature (tiny drops from stratus). */
static const double precipitation_levels[] = { 0.0, 0.3, 0.6, 0.9 };
#define DRIZZLE_MAX 0.3

const char *proto_obs_etage_layer(enum proto_obs_etage etage)
{
    return (unsigned)etage < ETAGE_COUNT ? etages[etage].layer : NULL;
}

const char *proto_obs_etage_name(enum proto_obs_etage etage)
{
    return (unsigned)etage < ETAGE_COUNT ? etages[etage].name : "?";
}

double proto_obs_low_type(double coverage, double base_m)
{
    if (coverage >= 0.95)
        return base_m < STRATUS_BELOW_M ? TYPE_STRATUS : TYPE_STRATOCUMULUS;
    if (coverage > 0.5)
        return TYPE_STRATOCUMULUS;
    return TYPE_CUMULUS;
}

double proto_obs_humidity_fog_per_km(double humidity)
{
    double t = (humidity - PROTO_OBS_FOG_ONSET_HUMIDITY) / (1.0 - PROTO_OBS_FOG_ONSET_HUMIDITY);
    t = fmin(fmax(t, 0.0), 1.0);
    return PROTO_OBS_KOSCHMIEDER * t * t * (3.0 - 2.0 * t);
}

/* The highest humidity at or below `humidity` whose fog stays within `fog_per_km`. */
static double humidity_within_fog(double humidity, double fog_per_km)
{
    if (proto_obs_humidity_fog_per_km(humidity) <= fog_per_km)
        return humidity;
    double lo = PROTO_OBS_FOG_ONSET_HUMIDITY, hi = humidity;
    for (int i = 0; i < 40; i++) {
        double mid = 0.5 * (lo + hi);
        if (proto_obs_humidity_fog_per_km(mid) <= fog_per_km)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

static enum proto_obs_etage etage_of(const struct proto_metar_cloud_layer *layer)
{
    if (layer->cumulonimbus || layer->towering_cumulus || layer->base_m < PROTO_OBS_MIDDLE_BASE_M)
        return PROTO_OBS_ETAGE_LOW;
    return layer->base_m < PROTO_OBS_HIGH_BASE_M ? PROTO_OBS_ETAGE_MIDDLE : PROTO_OBS_ETAGE_HIGH;
}

static void group_text(const struct proto_metar_cloud_layer *layer, char *text, size_t size)
{
    char base[16] = "///";
    if (layer->base_known)
        snprintf(base, sizeof base, "%03d", (layer->base_ft / 100) % 1000);
    snprintf(text, size, "%s%s%s",
             layer->amount == PROTO_METAR_AMOUNT_UNKNOWN ? "///"
                                                         : proto_metar_amount_name(layer->amount),
             base,
             layer->cumulonimbus       ? "CB"
             : layer->towering_cumulus ? "TCU"
                                       : "");
}

static bool add_unmapped(cJSON *unmapped, const char *group, const char *etage, const char *reason)
{
    cJSON *item = cJSON_CreateObject();
    if (!item || !cJSON_AddStringToObject(item, "group", group) ||
        (etage && !cJSON_AddStringToObject(item, "etage", etage)) ||
        !cJSON_AddStringToObject(item, "reason", reason) || !cJSON_AddItemToArray(unmapped, item)) {
        cJSON_Delete(item);
        return false;
    }
    return true;
}

/* One layer as the patch sets it. */
struct layer {
    bool present;
    double coverage, type, bottom_km, thickness_km;
};

static bool put_layer(cJSON *clouds, const char *name, const struct layer *layer)
{
    cJSON *json = cJSON_AddObjectToObject(clouds, name);
    if (!json || !cJSON_AddNumberToObject(json, "coverage", layer->present ? layer->coverage : 0))
        return false;
    if (!layer->present)
        return true;
    return cJSON_AddNumberToObject(json, "type", layer->type) &&
           cJSON_AddNumberToObject(json, "bottom_km", layer->bottom_km) &&
           cJSON_AddNumberToObject(json, "thickness_km", layer->thickness_km);
}

/* The groups of one étage merged: most covering amount, lowest base, named types. */
struct etage_groups {
    int count;
    double coverage, base_m;
    enum proto_metar_cloud_amount amount;
    bool cumulonimbus, towering;
};

static void low_layer_from(const struct etage_groups *g, struct layer *out)
{
    out->present = true;
    out->coverage = g->coverage;
    out->bottom_km = g->base_m / 1000.0;
    if (g->cumulonimbus) {
        out->type = TYPE_CUMULONIMBUS;
        out->thickness_km = 8.0;
    } else if (g->towering) {
        out->type = TYPE_TOWERING;
        out->thickness_km = 4.0;
    } else {
        out->type = proto_obs_low_type(g->coverage, g->base_m);
        out->thickness_km = out->type == TYPE_CUMULUS ? 1.5
                            : g->coverage >= 0.95     ? OVERCAST_DEPTH_KM
                                                      : 0.6;
    }
}

/* Middle étage (clouds.mid, world_state.h): altostratus sheets (BKN, OVC; type 0) about 1.5 km
 * deep, altocumulus patches (FEW, SCT; type 1) about 0.5 km. */
#define TYPE_ALTOSTRATUS 0.0
#define TYPE_ALTOCUMULUS 1.0
static void mid_layer_from(const struct etage_groups *g, struct layer *out)
{
    bool sheet = g->amount >= PROTO_METAR_BKN;
    out->present = true;
    out->coverage = g->coverage;
    out->bottom_km = g->base_m / 1000.0;
    out->type = sheet ? TYPE_ALTOSTRATUS : TYPE_ALTOCUMULUS;
    out->thickness_km = sheet ? 1.5 : 0.5;
}

/* Cirrus, cirrostratus: sheets and streaks (type 0) at the default depth. */
static void high_layer_from(const struct etage_groups *g, struct layer *out)
{
    out->present = true;
    out->coverage = g->coverage;
    out->type = 0.0;
    out->bottom_km = g->base_m / 1000.0;
    out->thickness_km = 0.6;
}

static bool map_clouds(const struct proto_metar_report *r, cJSON *patch, cJSON *unmapped,
                       double *low_base_km)
{
    struct layer low = { 0 }, mid = { 0 }, high = { 0 };
    *low_base_km = -1;
    bool clear = r->sky == PROTO_METAR_SKY_CAVOK || r->sky == PROTO_METAR_SKY_NSC ||
                 r->sky == PROTO_METAR_SKY_NCD || r->sky == PROTO_METAR_SKY_SKC ||
                 r->sky == PROTO_METAR_SKY_CLR;
    if (r->sky == PROTO_METAR_SKY_OBSCURED) {
        /* VV: fog or a stratus so low that the sky cannot be seen; the ceiling at the vertical
         * visibility (the ground when not given). */
        low = (struct layer){ true, 1.0, TYPE_STRATUS,
                              r->vertical_visibility_known ? r->vertical_visibility_m / 1000.0 : 0,
                              OVERCAST_DEPTH_KM };
    } else if (r->sky == PROTO_METAR_SKY_LAYERS) {
        struct etage_groups groups[ETAGE_COUNT] = { 0 };
        for (int i = 0; i < r->layer_count; i++) {
            const struct proto_metar_cloud_layer *layer = &r->layers[i];
            char text[32];
            group_text(layer, text, sizeof text);
            if (layer->amount == PROTO_METAR_AMOUNT_UNKNOWN || !layer->base_known) {
                if (!add_unmapped(unmapped, text, NULL,
                                  layer->base_known ? "amount not observed" : "base not observed"))
                    return false;
                continue;
            }
            struct etage_groups *g = &groups[etage_of(layer)];
            if (g->count == 0 || layer->coverage > g->coverage) {
                g->coverage = layer->coverage;
                g->amount = layer->amount;
            }
            if (g->count == 0 || layer->base_m < g->base_m)
                g->base_m = layer->base_m;
            g->cumulonimbus |= layer->cumulonimbus;
            g->towering |= layer->towering_cumulus;
            g->count++;
        }
        if (groups[PROTO_OBS_ETAGE_LOW].count)
            low_layer_from(&groups[PROTO_OBS_ETAGE_LOW], &low);
        if (groups[PROTO_OBS_ETAGE_HIGH].count)
            high_layer_from(&groups[PROTO_OBS_ETAGE_HIGH], &high);
        if (groups[PROTO_OBS_ETAGE_MIDDLE].count)
            mid_layer_from(&groups[PROTO_OBS_ETAGE_MIDDLE], &mid);
    } else if (!clear && !r->weather.thunderstorm) {
        return true; /* no cloud group: the clouds stay as they are */
    }
    /* No cloud group but a thunderstorm: its cumulonimbus, the layers above left as they are. */
    bool keep_high = !clear && r->sky == PROTO_METAR_SKY_NOT_REPORTED;
    if (r->weather.thunderstorm && !(low.present && low.type == TYPE_CUMULONIMBUS)) {
        /* TS: a cumulonimbus overhead, reported or not. */
        if (!low.present || low.coverage <= 0)
            low = (struct layer){ true, 3.5 / 8.0, 0, STORM_BASE_KM, 0 };
        low.type = TYPE_CUMULONIMBUS;
        low.thickness_km = 8.0;
    }
    cJSON *clouds = cJSON_AddObjectToObject(patch, "clouds");
    if (!clouds || !put_layer(clouds, "low", &low) ||
        (!keep_high && (!put_layer(clouds, "mid", &mid) || !put_layer(clouds, "high", &high))))
        return false;
    if (low.present)
        *low_base_km = low.bottom_km;
    return true;
}

static bool map_precipitation(const struct proto_metar_report *r, cJSON *patch, cJSON *unmapped)
{
    const struct proto_metar_weather *w = &r->weather;
    double level = precipitation_levels[w->precipitation];
    if (w->drizzle && !w->rain && !w->snow && !w->showers)
        level = fmin(level, DRIZZLE_MAX);
    cJSON *clouds = cJSON_GetObjectItemCaseSensitive(patch, "clouds");
    if (!clouds && !(clouds = cJSON_AddObjectToObject(patch, "clouds")))
        return false;
    if (!cJSON_AddNumberToObject(clouds, "precipitation", level))
        return false;
    for (int i = 0; i < w->group_count; i++)
        if (strncmp(w->groups[i], "VC", 2) == 0 &&
            !add_unmapped(unmapped, w->groups[i], NULL,
                          "in the vicinity (8-16 km), not at the station"))
            return false;
    return true;
}

/* Visibility to fog, temperature and dew point to humidity: the fog term is the observed
 * extinction less the clear air's and less the renderer's humidity fog, and the humidity is
 * held where its own fog stays within the observed extinction. */
static bool map_air(const struct proto_metar_report *r, cJSON *patch)
{
    const struct proto_metar_visibility *v = &r->visibility;
    bool visibility = v->reported && v->metres > 0;
    double fog_per_km = 0;
    if (visibility)
        fog_per_km = fmin(
            fmax(PROTO_OBS_KOSCHMIEDER / (v->metres / 1000.0) - PROTO_OBS_CLEAR_EXTINCTION_PER_KM,
                 0.0),
            100.0);
    cJSON *weather = cJSON_GetObjectItemCaseSensitive(patch, "weather");
    double humidity = 0;
    if (r->relative_humidity_known) {
        humidity = fmin(fmax(r->relative_humidity, 0.0), 1.0);
        if (visibility)
            humidity = humidity_within_fog(humidity, fog_per_km);
        if (!cJSON_AddNumberToObject(weather, "humidity", humidity))
            return false;
    }
    if (!visibility)
        return true;
    cJSON *atmosphere = cJSON_AddObjectToObject(patch, "atmosphere");
    cJSON *fog = atmosphere ? cJSON_AddObjectToObject(atmosphere, "fog") : NULL;
    /* 9999, 10SM and more, CAVOK bound the extinction from above: no fog beyond the clear
     * air's (10 km is the top of the reporting scale). */
    double density = v->bound == PROTO_METAR_AT_LEAST || v->metres >= 9999
                         ? 0.0
                         : fmax(fog_per_km - proto_obs_humidity_fog_per_km(humidity), 0.0);
    if (!fog || !cJSON_AddNumberToObject(fog, "density_per_km", density))
        return false;
    /* Fog lies in the lowest few hundred metres (radiation fog 100-300 m); mist and haze
     * reach higher. The vertical visibility, when given, is that depth. */
    double scale_km = r->weather.fog ? 0.2 : 0.5;
    if (r->vertical_visibility_known)
        scale_km = fmin(fmax(r->vertical_visibility_m / 1000.0, 0.05), 1.0);
    return cJSON_AddNumberToObject(fog, "scale_height_km", scale_km) != NULL;
}

static bool map_wind(const struct proto_metar_report *r, cJSON *weather, double low_base_km)
{
    const struct proto_metar_wind *w = &r->wind;
    if (!w->reported || (!w->calm && !w->speed_known))
        return true;
    double height_m = low_base_km > 0.01 ? low_base_km * 1000.0 : 1000.0;
    double speed = w->calm ? 0.0
                           : w->speed_m_s * pow(fmax(height_m, WIND_REFERENCE_M) / WIND_REFERENCE_M,
                                                WIND_POWER_EXPONENT);
    cJSON *wind = cJSON_AddObjectToObject(weather, "wind");
    if (!wind || !cJSON_AddNumberToObject(wind, "speed_m_s", fmin(speed, 100.0)))
        return false;
    if (!w->calm && w->direction_known)
        return cJSON_AddNumberToObject(wind, "direction_deg", fmod(w->direction_deg, 360.0)) !=
               NULL;
    return true;
}

bool proto_obs_metar_patch(const struct proto_metar_report *report, cJSON **patch, cJSON **unmapped,
                           char *why, size_t why_size)
{
    *patch = NULL;
    *unmapped = NULL;
    if (report->nil) {
        snprintf(why, why_size, "the report from %s is NIL: nothing was observed", report->station);
        return false;
    }
    cJSON *p = cJSON_CreateObject(), *u = cJSON_CreateArray();
    cJSON *weather = p ? cJSON_AddObjectToObject(p, "weather") : NULL;
    double low_base_km = -1;
    /* An observation replaces the weather: the autopilot would move it away at once. */
    bool ok = u && weather && cJSON_AddStringToObject(weather, "source", "metar") &&
              cJSON_AddStringToObject(weather, "autopilot", "off") &&
              map_clouds(report, p, u, &low_base_km) && map_precipitation(report, p, u) &&
              map_air(report, p) && map_wind(report, weather, low_base_km);
    if (!ok) {
        cJSON_Delete(p);
        cJSON_Delete(u);
        snprintf(why, why_size, "out of memory mapping the report");
        return false;
    }
    *patch = p;
    *unmapped = u;
    return true;
}
