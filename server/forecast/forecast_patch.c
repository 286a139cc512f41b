/* A forecast sample as a world-state patch (forecast.h, forecast_patch). The model gives
 * covers per étage but no cloud bases: the low layer sits at a typical 1 km, the middle layer at
 * 3 km (the middle étage's lower half), the high at 8 km, each as deep as its kind. */
#include "forecast.h"
#include "weather_observation.h"

#include <cjson/cJSON.h>
#include <math.h>

#define LOW_BASE_KM 1.0
#define MIDDLE_BASE_KM 3.0
/* The 10 m wind at the clouds: u(z) = u10 (z / 10 m)^(1/7), at the low layer's base. */
#define WIND_AT_CLOUDS_FACTOR 1.9306977288832496 /* 100^(1/7) */

double forecast_precipitation_level(double rate_mm_h)
{
    static const double rates[] = { 0.0, 0.5, 4.0, 10.0, 20.0 };
    static const double levels[] = { 0.0, 0.3, 0.6, 0.9, 1.0 };
    if (!(rate_mm_h > 0.0))
        return 0.0;
    for (int i = 1; i < 5; i++)
        if (rate_mm_h < rates[i])
            return levels[i - 1] + (levels[i] - levels[i - 1]) * (rate_mm_h - rates[i - 1]) /
                                       (rates[i] - rates[i - 1]);
    return 1.0;
}

static bool put_layer(cJSON *clouds, const char *name, double coverage, double type,
                      double bottom_km, double thickness_km)
{
    cJSON *layer = cJSON_AddObjectToObject(clouds, name);
    return layer && cJSON_AddNumberToObject(layer, "coverage", coverage) &&
           cJSON_AddNumberToObject(layer, "type", type) &&
           cJSON_AddNumberToObject(layer, "bottom_km", bottom_km) &&
           cJSON_AddNumberToObject(layer, "thickness_km", thickness_km);
}

static bool put_low(cJSON *clouds, const struct forecast_sample *s)
{
    double low = fmin(fmax(s->low_cover, 0.0), 1.0);
    double type = proto_obs_low_type(low, LOW_BASE_KM * 1000.0);
    /* As for a METAR: cumulus 1.5 km, broken sheets 0.6 km, an overcast 0.8 km deep. */
    double thickness = type > 0.5 ? 1.5 : low >= 0.95 ? 0.8 : 0.6;
    return put_layer(clouds, "low", low, type, LOW_BASE_KM, thickness);
}

/* Altostratus sheets (from five oktas: type 0, 1.5 km) or altocumulus patches (type 1, 0.5 km),
 * as for a METAR's BKN/OVC and FEW/SCT. */
static bool put_mid(cJSON *clouds, const struct forecast_sample *s)
{
    double middle = fmin(fmax(s->medium_cover, 0.0), 1.0);
    bool sheet = middle >= 0.625;
    return put_layer(clouds, "mid", middle, sheet ? 0.0 : 1.0, MIDDLE_BASE_KM, sheet ? 1.5 : 0.5);
}

bool forecast_patch(const struct forecast *forecast, const struct forecast_sample *s, cJSON **patch,
                    cJSON **unmapped)
{
    cJSON *p = cJSON_CreateObject(), *u = cJSON_CreateArray();
    cJSON *clouds = p ? cJSON_AddObjectToObject(p, "clouds") : NULL;
    cJSON *weather = p ? cJSON_AddObjectToObject(p, "weather") : NULL;
    cJSON *wind = weather ? cJSON_AddObjectToObject(weather, "wind") : NULL;
    const struct forecast_info *info = forecast_info(forecast);
    double speed = s->wind_speed_m_s;
    if (info->wind_level == FORECAST_WIND_10M)
        speed *= WIND_AT_CLOUDS_FACTOR;
    bool ok = u && clouds && wind && put_low(clouds, s) && put_mid(clouds, s) &&
              put_layer(clouds, "high", fmin(fmax(s->high_cover, 0.0), 1.0), 0.0, 8.0, 0.6) &&
              cJSON_AddNumberToObject(clouds, "precipitation",
                                      forecast_precipitation_level(s->precipitation_mm_h)) &&
              cJSON_AddStringToObject(weather, "source", "forecast") &&
              cJSON_AddStringToObject(weather, "autopilot", "off") &&
              cJSON_AddNumberToObject(weather, "humidity",
                                      fmin(fmax(s->relative_humidity, 0.0), 1.0)) &&
              cJSON_AddNumberToObject(wind, "speed_m_s", fmin(speed, 100.0)) &&
              cJSON_AddNumberToObject(wind, "direction_deg", fmod(s->wind_direction_deg, 360.0));
    if (!ok) {
        cJSON_Delete(p);
        cJSON_Delete(u);
        return false;
    }
    *patch = p;
    *unmapped = u;
    return true;
}
