/* skyctl: command-line client of skyd (protocol/PROTOCOL.md). */
#include "skyctl.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage_text[] =
    "usage: skyctl [--url URL] [--token TOKEN | --token-file FILE] [--timeout S]\n"
    "              [--ca-file FILE] [--insecure] [--json] COMMAND [ARGS]\n"
    "\n"
    "Talks to a running skyd (`skyd serve`) over its WebSocket protocol.\n"
    "  --url URL      ws://HOST:PORT/, or wss://HOST:PORT/ through TLS to a skyd whose config\n"
    "                 sets listen.tls_certificate ($SKYD_URL, else ws://127.0.0.1:8080/)\n"
    "  --token TOKEN  the controller token, needed by set, preset, weather-map, metar and\n"
    "                 forecast\n"
    "                 ($SKYD_TOKEN when not given)\n"
    "  --token-file FILE\n"
    "                 a file whose first line is the token, read when neither --token\n"
    "                 nor $SKYD_TOKEN gives one: e.g. var/skyd-state.json.token, the\n"
    "                 token `skyd serve` made and keeps beside its state file\n"
    "  --timeout S    seconds to wait for the connection and each reply (default 30)\n"
    "  --ca-file FILE wss: trust the PEM certificates in FILE instead of the system's, e.g.\n"
    "                 the daemon's own self-signed listen.tls_certificate (the certificate\n"
    "                 must still name the URL's host)\n"
    "  --insecure     wss: accept any server certificate (self-signed, expired, another\n"
    "                 host's), with a warning on stderr\n"
    "  --json         print one JSON object per line on stdout instead of text:\n"
    "                 get: {\"path\", \"value\", \"revision\"} ({\"state\", \"revision\"}\n"
    "                 without PATH); set, preset, weather-map, probe, stats: the server's\n"
    "                 reply less its id ({\"type\": \"ack\", \"revision\"}, ...); snapshot\n"
    "                 and each frame of watch: {\"type\": \"frame\", \"frame_number\",\n"
    "                 \"revision\", \"simulation_time_s\", \"width\", \"height\", \"format\",\n"
    "                 \"bytes\", \"path\" (when saved)}; watch's subscribed and event\n"
    "                 messages as the server sent them. Errors stay text on stderr, with\n"
    "                 the same exit status\n"
    "\n"
    "commands:\n"
    "  get [PATH]                       the world state as JSON (itself a valid patch), one\n"
    "                                   field (dotted or /pointer), or `revision`\n"
    "  set PATH=VALUE...                change fields at once (all or nothing); prints the\n"
    "                                   new revision. VALUE is JSON, or else a string\n"
    "  preset [--kind K] [--transition-s S] NAME\n"
    "                                   apply a preset (kind atmosphere by default)\n"
    "  preset --list [--kind K]         the presets of a kind\n"
    "  weather-map FILE.png             send a weather map (r low coverage, g high coverage,\n"
    "                                   b cloud type, a rain) and select it; prints the\n"
    "                                   new revision (weather.map_source=procedural undoes)\n"
    "  metar \"REPORT\"                   apply a METAR or SPECI report to the weather\n"
    "                                   (weather.source becomes metar); prints the new\n"
    "                                   revision and each group left unmapped\n"
    "  forecast                         follow the daemon's forecast folder (weather.source\n"
    "                                   becomes forecast); prints the new revision\n"
    "  snapshot --out FILE.png [--width W] [--height H] [--set VIEW_PATH=VALUE]...\n"
    "                                   render one frame (default 640x360) into a PNG\n"
    "                                   (FILE.jpg: a JPEG; --set quality=N, 1..100)\n"
    "  watch [--count N] [--no-frames] [--out DIR] [--width W] [--height H] [--fps F]\n"
    "        [--set VIEW_PATH=VALUE]... print a line per frame and per state event until\n"
    "                                   interrupted or N frames (with --no-frames: N lines;\n"
    "                                   frames 320x180 by default); --out saves each frame\n"
    "                                   as DIR/frame_NNNNNN_rev_RRRRRR.png (.jpg with\n"
    "                                   --set format=jpeg; frame number,\n"
    "                                   state revision; DIR is created) and ends its line\n"
    "                                   with that path\n"
    "  probe QUANTITY [NAME=VALUE]...   transmittance altitude_km mu | luminance\n"
    "                                   altitude_km view_zenith_deg view_azimuth_deg\n"
    "                                   sun_zenith_deg | illuminance sun_zenith_deg\n"
    "  stats                            frames per second, clients, GPU ms per pass\n"
    "\n"
    "exit status:\n"
    "  0  done\n"
    "  1  the server refused the request; stderr names each offending field\n"
    "     (\"skyctl: set: /patch/location/latitude_deg: must be in [-90, 90] ... "
    "[out_of_range]\")\n"
    "  2  bad command line (or get of a field that does not exist), or a local file\n"
    "     that cannot be read or written (--out, --token-file, --ca-file, weather-map)\n"
    "  3  cannot connect (wss: the server's certificate was not accepted, and stderr\n"
    "     says so), connection lost, or no reply within --timeout\n"
    "\n"
    "examples:\n"
    "  skyctl get sun.elevation_deg\n"
    "  skyctl --token \"$T\" set clock.utc=2026-06-21T19:30:00Z clock.time_scale=0\n"
    "  skyctl --token \"$T\" set clock.sky_bodies=manual sun.elevation_deg=3\n"
    "  skyctl --token \"$T\" set atmosphere.ground_albedo=[0.1,0.2,0.3]\n"
    "  skyctl --token \"$T\" preset mars\n"
    "  skyctl --token \"$T\" preset --kind weather --transition-s 600 storm\n"
    "  skyctl --token \"$T\" weather-map front.png\n"
    "  skyctl --token \"$T\" metar \"METAR EGLL 281150Z 24010KT 9999 FEW040 12/09 Q1005\"\n"
    "  skyctl --token-file var/skyd-state.json.token set clouds.low.coverage=0.4\n"
    "  skyctl snapshot --out west.png --width 1280 --height 720 --set camera.yaw_deg=270\n"
    "  skyctl snapshot --out env.png --width 2048 --height 1024 --set projection=equirectangular\n"
    "         --set format=png16\n"
    "  skyctl watch --count 10\n"
    "  skyctl watch --count 100 --fps 1 --out frames\n"
    "  skyctl --json watch --no-frames\n"
    "  skyctl probe transmittance altitude_km=0 mu=0.5\n"
    "  skyctl stats\n"
    "  skyctl --url wss://sky.example:8443/ --ca-file skyd-cert.pem get clock.utc\n";

int skyctl_usage_error(const char *command, const char *format, ...)
{
    fprintf(stderr, "skyctl%s%s: ", command ? " " : "", command ? command : "");
    va_list args;
    va_start(args, format);
    vfprintf(stderr, format, args);
    va_end(args);
    fprintf(stderr, "\n(skyctl --help shows the usage)\n");
    return SKYCTL_USAGE;
}

/* The first line of path, blanks and line end trimmed, into token. */
static int read_token_file(const char *path, char *token, size_t tokenlen)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return skyctl_usage_error(NULL, "--token-file %s: %s", path, strerror(errno));
    char line[1024];
    bool read = fgets(line, sizeof line, f) != NULL;
    fclose(f);
    const char *start = line + strspn(line, " \t");
    size_t length = read ? strcspn(start, "\r\n") : 0;
    while (length > 0 && (start[length - 1] == ' ' || start[length - 1] == '\t'))
        length--;
    if (length == 0)
        return skyctl_usage_error(NULL, "--token-file %s: no token on its first line", path);
    if (length >= tokenlen)
        return skyctl_usage_error(NULL, "--token-file %s: the token is longer than %zu bytes", path,
                                  tokenlen - 1);
    memcpy(token, start, length);
    token[length] = '\0';
    return SKYCTL_OK;
}

/* Catches a wrong --ca-file here: libwebsockets only logs that it could not load one, and
 * the connection then fails as if the certificate were untrusted. */
static int check_ca_file(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return skyctl_usage_error(NULL, "--ca-file %s: %s", path, strerror(errno));
    static char text[1 << 20];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    if (!strstr(text, "-----BEGIN CERTIFICATE-----"))
        return skyctl_usage_error(NULL, "--ca-file %s: no PEM certificate in it", path);
    return SKYCTL_OK;
}

struct command {
    const char *name;
    int (*run)(const struct skyctl_options *, int, char **);
};

static const struct command commands[] = {
    { "get", skyctl_get },       { "set", skyctl_set },
    { "preset", skyctl_preset }, { "snapshot", skyctl_snapshot },
    { "watch", skyctl_watch },   { "probe", skyctl_probe },
    { "stats", skyctl_stats },   { "weather-map", skyctl_weather_map },
    { "metar", skyctl_metar },   { "forecast", skyctl_forecast },
};

int main(int argc, char **argv)
{
    struct skyctl_options options = {
        .url = getenv("SKYD_URL") ? getenv("SKYD_URL") : "ws://127.0.0.1:8080/",
        .token = getenv("SKYD_TOKEN"),
        .timeout_ms = 30000,
    };
    if (options.token && !options.token[0])
        options.token = NULL;
    const char *token_file = NULL;
    int i = 1;
    for (; i < argc && argv[i][0] == '-'; i++) {
        const char *arg = argv[i];
        if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
            fputs(usage_text, stdout);
            return SKYCTL_OK;
        }
        if (strcmp(arg, "--insecure") == 0) {
            options.insecure = true;
            continue;
        }
        if (strcmp(arg, "--json") == 0) {
            options.json = true;
            continue;
        }
        if (i + 1 >= argc)
            return skyctl_usage_error(NULL, "%s needs a value", arg);
        const char *value = argv[++i];
        if (strcmp(arg, "--url") == 0) {
            options.url = value;
        } else if (strcmp(arg, "--token") == 0) {
            options.token = value;
        } else if (strcmp(arg, "--token-file") == 0) {
            token_file = value;
        } else if (strcmp(arg, "--ca-file") == 0) {
            int rc = check_ca_file(value);
            if (rc != SKYCTL_OK)
                return rc;
            options.ca_file = value;
        } else if (strcmp(arg, "--timeout") == 0) {
            double seconds;
            if (!skyctl_parse_number(value, 0.001, 86400, &seconds))
                return skyctl_usage_error(NULL, "--timeout needs seconds in (0, 86400]");
            options.timeout_ms = (int)(seconds * 1000);
        } else {
            return skyctl_usage_error(NULL, "unknown option %s", arg);
        }
    }
    if (i >= argc)
        return skyctl_usage_error(NULL, "no command");
    static char file_token[300]; /* the protocol takes tokens of up to 256 bytes */
    if (token_file && !options.token) {
        int rc = read_token_file(token_file, file_token, sizeof file_token);
        if (rc != SKYCTL_OK)
            return rc;
        options.token = file_token;
    }
    for (size_t c = 0; c < sizeof commands / sizeof commands[0]; c++) {
        if (strcmp(argv[i], commands[c].name) == 0)
            return commands[c].run(&options, argc - i, argv + i);
    }
    return skyctl_usage_error(NULL, "unknown command %s", argv[i]);
}
