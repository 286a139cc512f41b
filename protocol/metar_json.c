/* A decoded METAR as JSON (protocol/PROTOCOL.md, "METAR decoding") and as one line for
 * people. Unknown or absent values are JSON null. */
#include "metar.h"

#include <cjson/cJSON.h>

#include <stdarg.h>
#include <stdio.h>

const char *proto_metar_amount_name(enum proto_metar_cloud_amount amount)
{
    static const char *const names[] = { "FEW", "SCT", "BKN", "OVC", "///" };
    return (unsigned)amount < sizeof names / sizeof names[0] ? names[amount] : "?";
}

const char *proto_metar_intensity_name(enum proto_metar_intensity intensity)
{
    static const char *const names[] = { "none", "light", "moderate", "heavy" };
    return (unsigned)intensity < sizeof names / sizeof names[0] ? names[intensity] : "?";
}

const char *proto_metar_sky_name(enum proto_metar_sky sky)
{
    static const char *const names[] = { "not_reported", "layers", "CAVOK", "NSC",
                                         "NCD",          "SKC",    "CLR",   "obscured" };
    return (unsigned)sky < sizeof names / sizeof names[0] ? names[sky] : "?";
}

static const char *bound_name(enum proto_metar_bound bound)
{
    return bound == PROTO_METAR_AT_LEAST    ? "at_least"
           : bound == PROTO_METAR_LESS_THAN ? "less_than"
                                            : "exact";
}

/* Adds a number, or null when not known; false when memory is out. */
static bool add_number(cJSON *object, const char *name, bool known, double value)
{
    return known ? cJSON_AddNumberToObject(object, name, value) != NULL
                 : cJSON_AddNullToObject(object, name) != NULL;
}

static bool add_wind(cJSON *json, const struct proto_metar_wind *w)
{
    if (!w->reported)
        return cJSON_AddNullToObject(json, "wind") != NULL;
    cJSON *wind = cJSON_AddObjectToObject(json, "wind");
    if (!wind || !add_number(wind, "direction_deg", w->direction_known, w->direction_deg) ||
        !cJSON_AddBoolToObject(wind, "variable", w->variable))
        return false;
    if (w->sector) {
        double sector[2] = { w->sector_from_deg, w->sector_to_deg };
        cJSON *array = cJSON_CreateDoubleArray(sector, 2);
        if (!array || !cJSON_AddItemToObject(wind, "sector_deg", array)) {
            cJSON_Delete(array);
            return false;
        }
    } else if (!cJSON_AddNullToObject(wind, "sector_deg")) {
        return false;
    }
    return add_number(wind, "speed_m_s", w->speed_known, w->speed_m_s) &&
           cJSON_AddBoolToObject(wind, "speed_above", w->speed_above) &&
           add_number(wind, "gust_m_s", w->gust_reported, w->gust_m_s) &&
           cJSON_AddBoolToObject(wind, "gust_above", w->gust_above) &&
           cJSON_AddBoolToObject(wind, "calm", w->calm) &&
           cJSON_AddStringToObject(wind, "unit", w->unit);
}

static bool add_visibility(cJSON *json, const struct proto_metar_visibility *v)
{
    if (!v->reported)
        return cJSON_AddNullToObject(json, "visibility") != NULL;
    cJSON *visibility = cJSON_AddObjectToObject(json, "visibility");
    return visibility && cJSON_AddNumberToObject(visibility, "metres", v->metres) &&
           cJSON_AddStringToObject(visibility, "bound", bound_name(v->bound)) &&
           cJSON_AddBoolToObject(visibility, "ndv", v->ndv) &&
           cJSON_AddNumberToObject(visibility, "extinction_per_m", v->extinction_per_m) &&
           cJSON_AddNumberToObject(visibility, "extinction_per_km", v->extinction_per_km);
}

static bool add_layer(cJSON *clouds, const struct proto_metar_cloud_layer *l)
{
    cJSON *layer = cJSON_CreateObject();
    if (!layer || !cJSON_AddItemToArray(clouds, layer)) {
        cJSON_Delete(layer);
        return false;
    }
    bool amount_known = l->amount != PROTO_METAR_AMOUNT_UNKNOWN;
    if (!cJSON_AddStringToObject(layer, "amount", proto_metar_amount_name(l->amount)))
        return false;
    if (amount_known) {
        int oktas[2] = { l->oktas_min, l->oktas_max };
        cJSON *array = cJSON_CreateIntArray(oktas, 2);
        if (!array || !cJSON_AddItemToObject(layer, "oktas", array)) {
            cJSON_Delete(array);
            return false;
        }
    } else if (!cJSON_AddNullToObject(layer, "oktas")) {
        return false;
    }
    return add_number(layer, "coverage", amount_known, l->coverage) &&
           add_number(layer, "base_ft", l->base_known, l->base_ft) &&
           add_number(layer, "base_m", l->base_known, l->base_m) &&
           cJSON_AddBoolToObject(layer, "cumulonimbus", l->cumulonimbus) &&
           cJSON_AddBoolToObject(layer, "towering_cumulus", l->towering_cumulus) &&
           cJSON_AddBoolToObject(layer, "type_unknown", l->type_unknown);
}

static bool add_weather(cJSON *json, const struct proto_metar_weather *w)
{
    cJSON *weather = cJSON_AddObjectToObject(json, "weather");
    if (!weather)
        return false;
    const struct {
        const char *name;
        enum proto_metar_intensity value;
    } intensities[] = { { "rain", w->rain },
                        { "snow", w->snow },
                        { "drizzle", w->drizzle },
                        { "showers", w->showers },
                        { "precipitation", w->precipitation } };
    for (size_t i = 0; i < sizeof intensities / sizeof intensities[0]; i++)
        if (!cJSON_AddStringToObject(weather, intensities[i].name,
                                     proto_metar_intensity_name(intensities[i].value)))
            return false;
    const struct {
        const char *name;
        bool value;
    } flags[] = { { "fog", w->fog },
                  { "fog_partial", w->fog_partial },
                  { "mist", w->mist },
                  { "thunderstorm", w->thunderstorm },
                  { "freezing", w->freezing },
                  { "hail", w->hail },
                  { "showers_nearby", w->showers_nearby },
                  { "thunderstorm_nearby", w->thunderstorm_nearby },
                  { "fog_nearby", w->fog_nearby } };
    for (size_t i = 0; i < sizeof flags / sizeof flags[0]; i++)
        if (!cJSON_AddBoolToObject(weather, flags[i].name, flags[i].value))
            return false;
    cJSON *groups = cJSON_AddArrayToObject(weather, "groups");
    for (int i = 0; groups && i < w->group_count; i++) {
        cJSON *text = cJSON_CreateString(w->groups[i]);
        if (!text || !cJSON_AddItemToArray(groups, text)) {
            cJSON_Delete(text);
            return false;
        }
    }
    return groups != NULL;
}

static bool fill(cJSON *json, const struct proto_metar_report *r)
{
    bool ok = cJSON_AddStringToObject(json, "type",
                                      r->type == PROTO_METAR_TYPE_SPECI ? "SPECI" : "METAR") &&
              cJSON_AddStringToObject(json, "station", r->station);
    if (!ok)
        return false;
    if (r->day) {
        cJSON *observed = cJSON_AddObjectToObject(json, "observed");
        if (!observed || !cJSON_AddNumberToObject(observed, "day", r->day) ||
            !cJSON_AddNumberToObject(observed, "hour", r->hour) ||
            !cJSON_AddNumberToObject(observed, "minute", r->minute))
            return false;
    } else if (!cJSON_AddNullToObject(json, "observed")) {
        return false;
    }
    ok = cJSON_AddBoolToObject(json, "nil", r->nil) &&
         cJSON_AddBoolToObject(json, "auto", r->automatic) &&
         cJSON_AddBoolToObject(json, "correction", r->correction) && add_wind(json, &r->wind) &&
         add_visibility(json, &r->visibility) && cJSON_AddBoolToObject(json, "cavok", r->cavok) &&
         cJSON_AddStringToObject(json, "sky", proto_metar_sky_name(r->sky));
    cJSON *clouds = ok ? cJSON_AddArrayToObject(json, "clouds") : NULL;
    for (int i = 0; clouds && i < r->layer_count; i++)
        if (!add_layer(clouds, &r->layers[i]))
            return false;
    return clouds &&
           add_number(json, "vertical_visibility_m", r->vertical_visibility_known,
                      r->vertical_visibility_m) &&
           add_weather(json, &r->weather) &&
           add_number(json, "temperature_c", r->temperature_known, r->temperature_c) &&
           add_number(json, "dew_point_c", r->dew_point_known, r->dew_point_c) &&
           add_number(json, "relative_humidity", r->relative_humidity_known, r->relative_humidity);
}

cJSON *proto_metar_to_json(const struct proto_metar_report *report)
{
    cJSON *json = cJSON_CreateObject();
    if (json && !fill(json, report)) {
        cJSON_Delete(json);
        return NULL;
    }
    return json;
}

/* ---- the summary ------------------------------------------------------------------------ */

struct line {
    char *text;
    size_t capacity, used;
};

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void
put(struct line *line, const char *format, ...)
{
    if (line->used + 1 >= line->capacity)
        return;
    va_list args;
    va_start(args, format);
    int n = vsnprintf(line->text + line->used, line->capacity - line->used, format, args);
    va_end(args);
    if (n > 0)
        line->used += (size_t)n < line->capacity - line->used ? (size_t)n
                                                              : line->capacity - line->used - 1;
}

static void summarize_wind(struct line *line, const struct proto_metar_wind *w)
{
    if (!w->reported) {
        put(line, "wind not observed");
        return;
    }
    if (w->calm) {
        put(line, "calm");
        return;
    }
    if (w->direction_known)
        put(line, "wind %03.0f deg", w->direction_deg);
    else
        put(line, "wind variable");
    if (w->speed_known)
        put(line, " %s%.1f m/s", w->speed_above ? "above " : "", w->speed_m_s);
    if (w->gust_reported)
        put(line, " gusts %.1f m/s", w->gust_m_s);
    if (w->sector)
        put(line, " (varying %03.0f-%03.0f deg)", w->sector_from_deg, w->sector_to_deg);
}

static void summarize_weather(struct line *line, const struct proto_metar_weather *w)
{
    const struct {
        const char *name;
        enum proto_metar_intensity value;
    } kinds[] = { { "rain", w->rain },
                  { "snow", w->snow },
                  { "drizzle", w->drizzle },
                  { "showers", w->showers } };
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
        if (kinds[i].value)
            put(line, ", %s %s", proto_metar_intensity_name(kinds[i].value), kinds[i].name);
    if (w->thunderstorm)
        put(line, ", thunderstorm");
    if (w->fog)
        put(line, ", fog");
    if (w->fog_partial)
        put(line, ", shallow or patchy fog");
    if (w->mist)
        put(line, ", mist");
}

void proto_metar_summary(const struct proto_metar_report *r, char *text, size_t capacity)
{
    if (!text || capacity == 0)
        return;
    struct line line = { text, capacity, 0 };
    text[0] = '\0';
    put(&line, "%s %s", r->type == PROTO_METAR_TYPE_SPECI ? "SPECI" : "METAR", r->station);
    if (r->day)
        put(&line, " day %d %02d:%02dZ", r->day, r->hour, r->minute);
    if (r->nil) {
        put(&line, ": NIL (missing report)");
        return;
    }
    put(&line, ": ");
    summarize_wind(&line, &r->wind);
    if (r->visibility.reported)
        put(&line, ", visibility %s%.0f m (extinction %.3g /km)",
            r->visibility.bound == PROTO_METAR_AT_LEAST    ? ">= "
            : r->visibility.bound == PROTO_METAR_LESS_THAN ? "< "
                                                           : "",
            r->visibility.metres, r->visibility.extinction_per_km);
    summarize_weather(&line, &r->weather);
    if (r->sky != PROTO_METAR_SKY_LAYERS)
        put(&line, ", sky %s", proto_metar_sky_name(r->sky));
    if (r->sky == PROTO_METAR_SKY_OBSCURED && r->vertical_visibility_known)
        put(&line, " (vertical visibility %.0f m)", r->vertical_visibility_m);
    for (int i = 0; i < r->layer_count; i++) {
        const struct proto_metar_cloud_layer *l = &r->layers[i];
        put(&line, ", %s", proto_metar_amount_name(l->amount));
        if (l->base_known)
            put(&line, " %.0f m", l->base_m);
        put(&line, "%s", l->cumulonimbus ? " CB" : l->towering_cumulus ? " TCU" : "");
    }
    if (r->temperature_known)
        put(&line, ", %.0f C", r->temperature_c);
    if (r->dew_point_known)
        put(&line, ", dew point %.0f C", r->dew_point_c);
    if (r->relative_humidity_known)
        put(&line, ", RH %.0f %%", r->relative_humidity * 100.0);
}
