/* libFuzzer target: a METAR or SPECI report (protocol/metar_*.c). A decoded report must keep
 * the decoder's promises (layers sorted by base, coverages and humidity within [0, 1], the
 * extinction of the visibility, bounded counts) and print as JSON that reads back; a refused
 * one must leave the report zeroed and name why. */
#include "metar.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_decoded(const struct proto_metar_report *r)
{
    if (r->layer_count < 0 || r->layer_count > PROTO_METAR_MAX_LAYERS ||
        r->weather.group_count < 0 || r->weather.group_count > PROTO_METAR_MAX_WEATHER ||
        strlen(r->station) != 4)
        abort();
    double previous = -1.0;
    bool unknown_seen = false;
    for (int i = 0; i < r->layer_count; i++) {
        const struct proto_metar_cloud_layer *l = &r->layers[i];
        if (!(l->coverage >= 0.0 && l->coverage <= 1.0))
            abort();
        if (l->base_known) {
            if (unknown_seen || l->base_m < previous || l->base_m != l->base_ft * 0.3048)
                abort();
            previous = l->base_m;
        } else {
            unknown_seen = true;
        }
    }
    const struct proto_metar_visibility *v = &r->visibility;
    if (v->reported && (!(v->metres > 0.0) || fabs(v->extinction_per_m * v->metres - 3.912) > 1e-9))
        abort();
    if (r->relative_humidity_known && !(r->relative_humidity > 0.0 && r->relative_humidity <= 1.0))
        abort();
    const struct proto_metar_wind *w = &r->wind;
    if (!(w->speed_m_s >= 0.0 && w->gust_m_s >= 0.0 && w->direction_deg >= 0.0 &&
          w->direction_deg <= 360.0))
        abort();
    cJSON *json = proto_metar_to_json(r);
    char *text = json ? cJSON_PrintUnformatted(json) : NULL;
    cJSON *again = text ? cJSON_Parse(text) : NULL;
    if (!again || !cJSON_Compare(json, again, true))
        abort();
    cJSON_Delete(again);
    free(text);
    cJSON_Delete(json);
    char summary[160];
    proto_metar_summary(r, summary, sizeof summary);
    if (strlen(summary) >= sizeof summary)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct proto_metar_report report;
    struct proto_metar_error error;
    memset(&report, 0xa5, sizeof report);
    if (proto_metar_decode((const char *)data, size, &report, &error)) {
        check_decoded(&report);
        return 0;
    }
    static const struct proto_metar_report zero;
    if (memcmp(&report, &zero, sizeof report) != 0 || error.code == PROTO_METAR_OK ||
        !error.message[0] || error.group < 0 || error.offset > size ||
        strlen(error.message) >= sizeof error.message)
        abort();
    return 0;
}
