/* skyd forecast FILE.grib2 --lat LAT --lon LON --time ISO8601|UNIX [--extent-km N] [--grid N]:
 * reads a GRIB2 forecast (server/forecast) for the square around a place and prints the
 * forecast at that time as JSON on stdout, with a one-line summary on stderr. A refused file,
 * place or time is a bad command-line value: the error says why, and the exit status is 2. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "cli_args.h"
#include "commands.h"
#include "error_text.h"
#include "forecast.h"
#include "messages.h"
#include "utc_time.h"

static void usage(FILE *out)
{
    fprintf(out,
            "usage: skyd forecast FILE.grib2 --lat DEG --lon DEG --time ISO8601|UNIX\n"
            "                     [--extent-km KM] [--grid N]\n"
            "Reads a GRIB2 forecast (ECMWF open data, GFS: a regular lat/lon grid) and prints\n"
            "the forecast at that time around the place as JSON on stdout: low, medium and\n"
            "high cloud cover (0..1, the mean over the grid points in the square), a coverage\n"
            "grid over the square, 2 m temperature, dew point and relative humidity, wind,\n"
            "precipitation rate, the steps it is interpolated between; a summary on stderr.\n"
            "  --extent-km KM  side of the square around the place (default %g, at most %g)\n"
            "  --grid N        coverage grid cells a side (default %d, at most %d)\n"
            "Exit status 2 when the file, place or time is refused; the message says why.\n",
            FORECAST_DEFAULT_EXTENT_KM, FORECAST_MAX_EXTENT_KM, FORECAST_DEFAULT_GRID,
            FORECAST_MAX_GRID);
}

/* Seconds since 1970 as a number, or ISO 8601 text. */
static bool parse_time(const char *text, double *unix_s)
{
    char *end = NULL;
    double value = strtod(text, &end);
    if (end != text && *end == '\0' && isfinite(value)) {
        *unix_s = value;
        return true;
    }
    error_text why;
    if (proto_time_parse_iso8601(text, unix_s, why, sizeof why))
        return true;
    fprintf(stderr, "skyd forecast: --time \"%s\" is neither ISO 8601 nor seconds since 1970: %s\n",
            text, why);
    return false;
}

static int print_forecast(const struct forecast *forecast, double unix_s)
{
    struct forecast_error error;
    struct forecast_moment *moment = malloc(sizeof *moment);
    if (!moment) {
        fprintf(stderr, "skyd forecast: out of memory\n");
        return SKYD_EXIT_FAILURE;
    }
    if (!forecast_at(forecast, unix_s, moment, &error)) {
        fprintf(stderr, "skyd forecast: %s\n", error.text);
        free(moment);
        return error.code == FORECAST_ERR_MEMORY ? SKYD_EXIT_FAILURE : SKYD_EXIT_USAGE;
    }
    cJSON *json = forecast_to_json(forecast, moment);
    char *printed = json && proto_json_exact_numbers(json) ? cJSON_Print(json) : NULL;
    cJSON_Delete(json);
    if (!printed) {
        fprintf(stderr, "skyd forecast: out of memory\n");
        free(moment);
        return SKYD_EXIT_FAILURE;
    }
    puts(printed);
    free(printed);
    char summary[512];
    forecast_summary(forecast, moment, summary, sizeof summary);
    fprintf(stderr, "%s\n", summary);
    free(moment);
    return SKYD_EXIT_OK;
}

int skyd_cmd_forecast(int argc, char **argv)
{
    if (argc == 1 && (strcmp(argv[0], "--help") == 0 || strcmp(argv[0], "-h") == 0)) {
        usage(stdout);
        return SKYD_EXIT_OK;
    }
    const char *path = NULL;
    struct forecast_request request = { .extent_km = FORECAST_DEFAULT_EXTENT_KM,
                                        .grid_size = FORECAST_DEFAULT_GRID };
    bool have_lat = false, have_lon = false, have_time = false;
    double unix_s = 0.0;
    for (int i = 0; i < argc; i++) {
        const char *option = argv[i];
        const char *value = NULL;
        bool ok = true;
        if (strcmp(option, "--lat") == 0) {
            ok = (value = cli_take_value(argc, argv, &i)) &&
                 cli_parse_double(option, value, -90.0, 90.0, &request.lat_deg);
            have_lat = true;
        } else if (strcmp(option, "--lon") == 0) {
            ok = (value = cli_take_value(argc, argv, &i)) &&
                 cli_parse_double(option, value, -180.0, 360.0, &request.lon_deg);
            have_lon = true;
        } else if (strcmp(option, "--time") == 0) {
            ok = (value = cli_take_value(argc, argv, &i)) && parse_time(value, &unix_s);
            have_time = true;
        } else if (strcmp(option, "--extent-km") == 0) {
            ok = (value = cli_take_value(argc, argv, &i)) &&
                 cli_parse_double(option, value, 0.001, FORECAST_MAX_EXTENT_KM, &request.extent_km);
        } else if (strcmp(option, "--grid") == 0) {
            unsigned size = 0;
            ok = (value = cli_take_value(argc, argv, &i)) &&
                 cli_parse_uint(option, value, 1, FORECAST_MAX_GRID, &size);
            request.grid_size = (int)size;
        } else if (option[0] == '-' && option[1] != '\0') {
            fprintf(stderr, "skyd forecast: unknown option \"%s\"\n", option);
            ok = false;
        } else if (path) {
            fprintf(stderr, "skyd forecast: one file only (\"%s\", then \"%s\")\n", path, option);
            ok = false;
        } else {
            path = option;
        }
        if (!ok)
            return SKYD_EXIT_USAGE;
    }
    if (!path || !have_lat || !have_lon || !have_time) {
        fprintf(stderr, "skyd forecast: %s is needed\n",
                !path       ? "a GRIB2 file"
                : !have_lat ? "--lat"
                : !have_lon ? "--lon"
                            : "--time");
        usage(stderr);
        return SKYD_EXIT_USAGE;
    }
    struct forecast_error error;
    struct forecast *forecast = forecast_read(path, &request, &error);
    if (!forecast) {
        fprintf(stderr, "skyd forecast: %s\n", error.text);
        return error.code == FORECAST_ERR_MEMORY ? SKYD_EXIT_FAILURE : SKYD_EXIT_USAGE;
    }
    int status = print_forecast(forecast, unix_s);
    forecast_free(forecast);
    return status;
}
