#include "cli_observation.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error_text.h"
#include "field_errors.h"
#include "forecast.h"
#include "metar.h"
#include "weather_observation.h"
#include "world_sim.h"

/* Applies a patch all or nothing, as a client change (the wind re-anchored, a transition's
 * parameters held, the driven fields settled); prints the field errors when the world refuses
 * it. */
static bool apply_patch(struct proto_world_state *state, const cJSON *patch, const char *option)
{
    struct proto_field_errors errors;
    struct proto_world_state before = *state;
    if (proto_world_state_apply_json(state, patch, &errors)) {
        world_sim_client_changed(&before, state);
        return true;
    }
    char text[2048];
    proto_field_errors_format(&errors, text, sizeof text);
    fprintf(stderr, "skyd render: %s: the world refuses the patch:\n%s\n", option, text);
    return false;
}

static void print_unmapped(const char *option, const cJSON *unmapped)
{
    const cJSON *item;
    cJSON_ArrayForEach(item, unmapped)
    {
        char *text = cJSON_PrintUnformatted(item);
        if (text)
            fprintf(stderr, "skyd render: %s: unmapped %s\n", option, text);
        cJSON_free(text);
    }
}

bool cli_apply_metar(struct proto_world_state *state, const char *text)
{
    struct proto_metar_report *report = malloc(sizeof *report);
    struct proto_metar_error error;
    if (!report) {
        fprintf(stderr, "skyd render: --metar: out of memory\n");
        return false;
    }
    if (!proto_metar_decode(text, strlen(text), report, &error)) {
        fprintf(stderr, "skyd render: --metar: %s\n", error.message);
        free(report);
        return false;
    }
    cJSON *patch = NULL, *unmapped = NULL;
    error_text why;
    bool ok = proto_obs_metar_patch(report, &patch, &unmapped, why, sizeof why);
    if (!ok)
        fprintf(stderr, "skyd render: --metar: %s\n", why);
    else if ((ok = apply_patch(state, patch, "--metar"))) {
        char summary[512];
        proto_metar_summary(report, summary, sizeof summary);
        fprintf(stderr, "skyd render: --metar: %s\n", summary);
        print_unmapped("--metar", unmapped);
    }
    cJSON_Delete(patch);
    cJSON_Delete(unmapped);
    free(report);
    return ok;
}

struct forecast *cli_open_forecast(const struct proto_world_state *state, const char *path)
{
    struct forecast_request request = {
        .lat_deg = state->location.latitude_deg,
        .lon_deg = state->location.longitude_deg,
        .extent_km = state->weather.map_extent_km,
        .grid_size = FORECAST_DEFAULT_GRID,
    };
    struct forecast_error error;
    struct forecast *forecast = forecast_read(path, &request, &error);
    if (!forecast)
        fprintf(stderr, "skyd render: --forecast %s: %s\n", path, error.text);
    return forecast;
}

bool cli_apply_forecast(struct proto_world_state *state, const struct forecast *forecast, bool hold,
                        bool quiet, struct proto_weather_map *map)
{
    const struct forecast_info *info = forecast_info(forecast);
    double t = state->clock.utc_unix_s;
    if (hold) {
        double first = forecast_step_unix(forecast, 0);
        double last = forecast_step_unix(forecast, info->step_count - 1);
        t = fmin(fmax(t, first), last);
    }
    struct forecast_moment *moment = malloc(sizeof *moment);
    struct forecast_error error;
    if (!moment) {
        fprintf(stderr, "skyd render: --forecast: out of memory\n");
        return false;
    }
    if (!forecast_at(forecast, t, moment, &error)) {
        fprintf(stderr, "skyd render: --forecast: %s\n", error.text);
        free(moment);
        return false;
    }
    cJSON *patch = NULL, *unmapped = NULL;
    struct proto_weather_map grid;
    bool ok = forecast_patch(forecast, &moment->sample, &patch, &unmapped) &&
              forecast_weather_map(&moment->sample, state->weather.map_extent_km,
                                   state->weather.offset_east_km, state->weather.offset_north_km,
                                   &grid);
    if (ok) {
        proto_weather_map_free(map);
        *map = grid;
    }
    if (!ok)
        fprintf(stderr, "skyd render: --forecast: out of memory\n");
    else if ((ok = apply_patch(state, patch, "--forecast")) && !quiet) {
        char summary[512];
        forecast_summary(forecast, moment, summary, sizeof summary);
        fprintf(stderr, "skyd render: --forecast: %s\n", summary);
        print_unmapped("--forecast", unmapped);
    }
    cJSON_Delete(patch);
    cJSON_Delete(unmapped);
    free(moment);
    return ok;
}
