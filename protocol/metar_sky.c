/* METAR groups about the sky (WMO No. 306 FM 15 and code table 4678; ICAO Annex 3 appendix 3,
 * 4.4 and 4.5): present and recent weather, cloud and vertical visibility, and the
 * supplementary groups read after the pressure. */
#include "metar_groups.h"

#include <string.h>

#define FOOT_M 0.3048 /* the international foot */

/* ---- weather codes (code table 4678) ----------------------------------------------------- */

static const char descriptors[][3] = { "MI", "BC", "PR", "DR", "BL", "SH", "TS", "FZ" };
enum { MI, BC, PR, DR, BL, SH, TS, FZ, DESCRIPTOR_COUNT };

static const char phenomena[][3] = { "DZ", "RA", "SN", "SG", "IC", "PL", "GR",
                                     "GS", "UP", "BR", "FG", "FU", "VA", "DU",
                                     "SA", "HZ", "PO", "SQ", "FC", "SS", "DS" };
enum { DZ, RA, SN, SG, IC, PL, GR, GS, UP, BR, FG, FU, VA, DU, SA, HZ, PO, SQ, FC, SS, DS };
#define PHENOMENON_COUNT (int)(sizeof phenomena / sizeof phenomena[0])
#define MAX_PHENOMENA 3

static int find_code(const char (*table)[3], int count, const char *text)
{
    for (int i = 0; i < count; i++)
        if (text[0] == table[i][0] && text[1] == table[i][1])
            return i;
    return -1;
}

static bool is_precipitation(int phenomenon)
{
    return phenomenon <= UP;
}

/* Which phenomena each descriptor may qualify (FM 15, notes to 15.8); a bit per phenomenon. */
static unsigned allowed_with(int descriptor)
{
    const unsigned fog = 1u << FG;
    const unsigned lifted = 1u << DU | 1u << SA | 1u << SN;
    const unsigned showery = 1u << RA | 1u << SN | 1u << PL | 1u << GR | 1u << GS | 1u << UP;
    switch (descriptor) {
    case MI:
    case BC:
    case PR:
        return fog;
    case DR:
    case BL:
        return lifted;
    case SH:
    case TS:
        return showery;
    case FZ:
        return fog | 1u << DZ | 1u << RA | 1u << UP;
    default:
        return ~0u;
    }
}

struct weather_code {
    enum proto_metar_intensity intensity; /* of the group's precipitation */
    bool vicinity;
    int descriptor; /* -1: none */
    int phenomena[MAX_PHENOMENA];
    int count;
};

/* Reads an intensity or VC (when `prefix` allows them), a descriptor and phenomena from text.
 * NOT_THIS when text does not begin like a weather code. */
static enum metar_match read_weather(const struct metar_group *g, const char *text, bool prefix,
                                     struct weather_code *w, struct proto_metar_error *error)
{
    memset(w, 0, sizeof *w);
    w->intensity = PROTO_METAR_MODERATE;
    w->descriptor = -1;
    const char *p = text;
    bool signed_group = false;
    if (prefix && (*p == '-' || *p == '+')) {
        w->intensity = *p == '-' ? PROTO_METAR_LIGHT : PROTO_METAR_HEAVY;
        signed_group = true;
        p++;
    } else if (prefix && p[0] == 'V' && p[1] == 'C') {
        w->vicinity = true;
        p += 2;
    }
    size_t n = strlen(p);
    if (n < 2 || (find_code(descriptors, DESCRIPTOR_COUNT, p) < 0 &&
                  find_code(phenomena, PHENOMENON_COUNT, p) < 0)) {
        if (!signed_group && !w->vicinity)
            return METAR_NOT_THIS;
        return metar_fail(error, g, PROTO_METAR_ERR_WEATHER,
                          "unknown weather code after the intensity or VC");
    }
    w->descriptor = find_code(descriptors, DESCRIPTOR_COUNT, p);
    if (w->descriptor >= 0) {
        p += 2;
        n -= 2;
    }
    if (n % 2)
        return metar_fail(error, g, PROTO_METAR_ERR_WEATHER,
                          "weather codes are pairs of letters (code table 4678)");
    unsigned seen = 0;
    bool precipitation = false, other = false;
    for (; *p; p += 2) {
        int code = find_code(phenomena, PHENOMENON_COUNT, p);
        if (code < 0)
            return metar_fail(error, g, PROTO_METAR_ERR_WEATHER,
                              "\"%.2s\" is not a weather phenomenon (code table 4678)", p);
        if (w->count == MAX_PHENOMENA)
            return metar_fail(error, g, PROTO_METAR_ERR_WEATHER,
                              "more than %d phenomena in one group", MAX_PHENOMENA);
        if (seen & 1u << code)
            return metar_fail(error, g, PROTO_METAR_ERR_WEATHER, "\"%s\" is given twice",
                              phenomena[code]);
        if (w->descriptor >= 0 && !(allowed_with(w->descriptor) & 1u << code))
            return metar_fail(error, g, PROTO_METAR_ERR_WEATHER, "%s cannot qualify %s",
                              descriptors[w->descriptor], phenomena[code]);
        seen |= 1u << code;
        precipitation |= is_precipitation(code);
        other |= !is_precipitation(code);
        w->phenomena[w->count++] = code;
    }
    if (other && w->count > 1)
        return metar_fail(error, g, PROTO_METAR_ERR_WEATHER,
                          "only precipitation codes combine in one group");
    /* Alone, a descriptor must be TS (thunderstorm) or, in the vicinity, SH (showers). */
    if (w->count == 0 && w->descriptor != TS && !(w->vicinity && w->descriptor == SH))
        return metar_fail(error, g, PROTO_METAR_ERR_WEATHER, "%s needs a phenomenon after it",
                          descriptors[w->descriptor]);
    if (signed_group && !precipitation &&
        !(w->intensity == PROTO_METAR_HEAVY && w->count == 1 &&
          (w->phenomena[0] == SS || w->phenomena[0] == DS || w->phenomena[0] == FC)))
        return metar_fail(error, g, PROTO_METAR_ERR_WEATHER,
                          "an intensity needs precipitation (or +SS, +DS, +FC)");
    if (w->vicinity && precipitation)
        return metar_fail(error, g, PROTO_METAR_ERR_WEATHER,
                          "precipitation in the vicinity is reported as VCSH");
    return METAR_TAKEN;
}

static void raise_to(enum proto_metar_intensity *field, enum proto_metar_intensity intensity)
{
    if (intensity > *field)
        *field = intensity;
}

enum metar_match metar_parse_weather(const struct metar_group *g,
                                     struct proto_metar_weather *weather,
                                     struct proto_metar_error *error)
{
    struct weather_code w;
    enum metar_match m = read_weather(g, g->text, true, &w, error);
    if (m != METAR_TAKEN)
        return m;
    if (g->length >= sizeof weather->groups[0])
        return metar_fail(error, g, PROTO_METAR_ERR_WEATHER, "too long for a weather group");
    if (weather->group_count == PROTO_METAR_MAX_WEATHER)
        return metar_fail(error, g, PROTO_METAR_ERR_TOO_MANY, "more than %d present-weather groups",
                          PROTO_METAR_MAX_WEATHER);
    memcpy(weather->groups[weather->group_count++], g->text, g->length + 1);
    if (w.vicinity) {
        weather->showers_nearby |= w.descriptor == SH;
        weather->thunderstorm_nearby |= w.descriptor == TS;
        weather->fog_nearby |= w.count == 1 && w.phenomena[0] == FG;
        return METAR_TAKEN;
    }
    weather->thunderstorm |= w.descriptor == TS;
    weather->freezing |= w.descriptor == FZ;
    for (int i = 0; i < w.count; i++) {
        int code = w.phenomena[i];
        if (is_precipitation(code)) {
            raise_to(&weather->precipitation, w.intensity);
            if (w.descriptor == SH)
                raise_to(&weather->showers, w.intensity);
        }
        if (code == RA)
            raise_to(&weather->rain, w.intensity);
        else if (code == SN)
            raise_to(&weather->snow, w.intensity);
        else if (code == DZ)
            raise_to(&weather->drizzle, w.intensity);
        else if (code == GR || code == GS)
            weather->hail = true;
        else if (code == BR)
            weather->mist = true;
        else if (code == FG && (w.descriptor == MI || w.descriptor == BC || w.descriptor == PR))
            weather->fog_partial = true;
        else if (code == FG)
            weather->fog = true;
    }
    return METAR_TAKEN;
}

enum metar_match metar_parse_recent_weather(const struct metar_group *g,
                                            struct proto_metar_error *error)
{
    if (g->length < 4 || g->text[0] != 'R' || g->text[1] != 'E')
        return METAR_NOT_THIS;
    struct weather_code w;
    enum metar_match m = read_weather(g, g->text + 2, false, &w, error);
    if (m == METAR_NOT_THIS)
        return metar_fail(error, g, PROTO_METAR_ERR_WEATHER,
                          "recent weather must be RE and a weather code without intensity");
    return m;
}

/* ---- cloud and vertical visibility ------------------------------------------------------- */

static const char amounts[][4] = { "FEW", "SCT", "BKN", "OVC", "///" };
/* Okta bands of each amount (Annex 3, 4.5.4.3) and their middles as fractions of the sky. */
static const int okta_band[][2] = { { 1, 2 }, { 3, 4 }, { 5, 7 }, { 8, 8 }, { 0, 0 } };

static bool three_digits_or_slashes(const char *text, int *value, bool *known)
{
    *known = metar_digits(text, 3, value);
    return *known || (text[0] == '/' && text[1] == '/' && text[2] == '/');
}

static enum metar_match proto_word(const struct metar_group *g, struct proto_metar_report *r,
                                   struct proto_metar_error *error)
{
    static const struct {
        const char *word;
        enum proto_metar_sky sky;
    } words[] = { { "NSC", PROTO_METAR_SKY_NSC },
                  { "NCD", PROTO_METAR_SKY_NCD },
                  { "SKC", PROTO_METAR_SKY_SKC },
                  { "CLR", PROTO_METAR_SKY_CLR } };
    enum proto_metar_sky sky = PROTO_METAR_SKY_NOT_REPORTED;
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
        if (strcmp(g->text, words[i].word) == 0)
            sky = words[i].sky;
    bool vertical = g->text[0] == 'V' && g->text[1] == 'V';
    if (sky == PROTO_METAR_SKY_NOT_REPORTED && !vertical)
        return METAR_NOT_THIS;
    if (r->sky != PROTO_METAR_SKY_NOT_REPORTED || r->layer_count > 0)
        return metar_fail(error, g, PROTO_METAR_ERR_CLOUD, "%s cannot come with other cloud groups",
                          vertical ? "VV" : g->text);
    if (vertical) {
        int hundreds;
        bool known;
        if (g->length != 5 || !three_digits_or_slashes(g->text + 2, &hundreds, &known))
            return metar_fail(error, g, PROTO_METAR_ERR_CLOUD,
                              "vertical visibility must be VV and three digits (hundreds of "
                              "feet) or VV///");
        sky = PROTO_METAR_SKY_OBSCURED;
        r->vertical_visibility_known = known;
        r->vertical_visibility_m = known ? hundreds * 100 * FOOT_M : 0;
    }
    r->sky = sky;
    return METAR_TAKEN;
}

enum metar_match metar_parse_sky(const struct metar_group *g, struct proto_metar_report *r,
                                 struct proto_metar_error *error)
{
    enum metar_match word = proto_word(g, r, error);
    if (word != METAR_NOT_THIS)
        return word;
    int amount = 0;
    while (amount < 5 && strncmp(g->text, amounts[amount], 3) != 0)
        amount++;
    /* "///" starts a cloud group only with six characters or more ("////" is a visibility,
     * "/////" a temperature and dew point). */
    if (amount == 5 || (amount == PROTO_METAR_AMOUNT_UNKNOWN && g->length < 6))
        return METAR_NOT_THIS;
    struct proto_metar_cloud_layer layer;
    memset(&layer, 0, sizeof layer);
    layer.amount = (enum proto_metar_cloud_amount)amount;
    int hundreds = 0;
    if (g->length < 6 || !three_digits_or_slashes(g->text + 3, &hundreds, &layer.base_known))
        return metar_fail(error, g, PROTO_METAR_ERR_CLOUD,
                          "cloud height must be three digits (hundreds of feet) or ///");
    const char *type = g->text + 6;
    layer.cumulonimbus = strcmp(type, "CB") == 0;
    layer.towering_cumulus = strcmp(type, "TCU") == 0;
    layer.type_unknown = strcmp(type, "///") == 0;
    if (*type && !layer.cumulonimbus && !layer.towering_cumulus && !layer.type_unknown)
        return metar_fail(error, g, PROTO_METAR_ERR_CLOUD, "cloud type must be CB, TCU or ///");
    if (r->sky != PROTO_METAR_SKY_NOT_REPORTED && r->sky != PROTO_METAR_SKY_LAYERS)
        return metar_fail(error, g, PROTO_METAR_ERR_CLOUD, "a cloud layer cannot come with %s",
                          proto_metar_sky_name(r->sky));
    /* Nothing known at all (an automatic station's //////): nothing to keep. */
    if (layer.amount == PROTO_METAR_AMOUNT_UNKNOWN && !layer.base_known && !layer.cumulonimbus &&
        !layer.towering_cumulus)
        return METAR_TAKEN;
    if (r->layer_count == PROTO_METAR_MAX_LAYERS)
        return metar_fail(error, g, PROTO_METAR_ERR_TOO_MANY, "more than %d cloud layers",
                          PROTO_METAR_MAX_LAYERS);
    layer.oktas_min = okta_band[amount][0];
    layer.oktas_max = okta_band[amount][1];
    layer.coverage = (layer.oktas_min + layer.oktas_max) / 16.0;
    layer.base_ft = hundreds * 100;
    layer.base_m = layer.base_ft * FOOT_M;
    r->layers[r->layer_count++] = layer;
    r->sky = PROTO_METAR_SKY_LAYERS;
    return METAR_TAKEN;
}

/* ---- supplementary groups ---------------------------------------------------------------- */

enum metar_match metar_parse_sea_state(const struct metar_group *g, struct proto_metar_error *error)
{
    if (g->text[0] != 'W' ||
        !(g->text[1] == 'M' || g->text[1] == '/' || (g->text[1] >= '0' && g->text[1] <= '9')))
        return METAR_NOT_THIS;
    const char *p = g->text + 1 + (g->text[1] == 'M');
    int value;
    bool ok = (metar_digits(p, 2, &value) || (p[0] == '/' && p[1] == '/')) && p[2] == '/';
    p += 3;
    if (ok && p[0] == 'S') /* state of the sea, code table 3700 */
        ok = (metar_digits(p + 1, 1, &value) || p[1] == '/') && p[2] == '\0';
    else if (ok && p[0] == 'H') /* significant wave height, decimetres */
        ok = strlen(p + 1) >= 1 && strlen(p + 1) <= 3 &&
             metar_digits(p + 1, (int)strlen(p + 1), &value);
    else
        ok = false;
    if (!ok)
        return metar_fail(error, g, PROTO_METAR_ERR_SUPPLEMENTARY,
                          "sea state must be W, the sea temperature, then /S and a digit or /H "
                          "and the wave height (W15/S2, W12/H14)");
    return METAR_TAKEN;
}

enum metar_match metar_parse_wind_shear_runway(const struct metar_group *g,
                                               struct proto_metar_error *error)
{
    const char *p = g->text;
    int runway;
    if (strncmp(p, "RWY", 3) == 0)
        p += 3;
    else if (*p == 'R')
        p++;
    bool ok = p != g->text && metar_digits(p, 2, &runway);
    if (ok) {
        p += 2;
        if (*p == 'L' || *p == 'C' || *p == 'R')
            p++;
        ok = *p == '\0';
    }
    if (!ok)
        return metar_fail(error, g, PROTO_METAR_ERR_SUPPLEMENTARY,
                          "wind shear must name a runway (WS R27, WS R27L) or WS ALL RWY");
    return METAR_TAKEN;
}
