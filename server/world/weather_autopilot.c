#include "weather_autopilot.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "ephemeris.h"

/* Independent noise channels. */
enum channel {
    CH_FRONT_SLOW,
    CH_FRONT_FAST,
    CH_INSTABILITY,
    CH_CIRRUS,
    CH_CIRRUS_BASE,
    CH_GUSTS,
    CH_WIND_BASE,
    CH_WIND_VEER,
    CH_MID,
    CH_MID_BASE,
};

/* Hours after which a front's wetness looks ahead to draw cirrus before it. */
static const double CIRRUS_LEAD_H = 6.0;
/* Altostratus follows the cirrus and comes before the rain (a warm front's sequence). */
static const double MID_LEAD_H = 3.0;

static double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

static double smoothstep(double edge0, double edge1, double x)
{
    double t = clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

/* splitmix64 finaliser: a well-mixed 64-bit hash. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* A uniform value in [0, 1) for (seed, channel, lattice index). */
static double lattice(int seed, enum channel ch, int64_t index)
{
    uint64_t h = mix64((uint64_t)(uint32_t)seed * 0x9e3779b97f4a7c15ULL ^
                       mix64((uint64_t)ch + 0x632be59bd9b4e019ULL) ^
                       mix64((uint64_t)index * 0xd6e8feb86659fd93ULL));
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/* 1D value noise with a quintic fade (C2 continuous): smooth in time, in [0, 1]. */
static double value_noise(int seed, enum channel ch, double u)
{
    double cell = floor(u);
    double f = u - cell;
    double fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    double a = lattice(seed, ch, (int64_t)cell), b = lattice(seed, ch, (int64_t)cell + 1);
    return a + (b - a) * fade;
}

static double hours(double unix_s)
{
    return unix_s / 3600.0;
}

double weather_autopilot_wetness(int seed, double unix_s)
{
    double h = hours(unix_s);
    /* Fronts every day or two, with shorter swings over them. */
    double raw = 0.65 * value_noise(seed, CH_FRONT_SLOW, h / 30.0) +
                 0.35 * value_noise(seed, CH_FRONT_FAST, h / 9.0);
    return smoothstep(0.2, 0.8, raw);
}

double weather_local_solar_hour(double unix_s, double longitude_deg)
{
    double h = fmod(
        hours(unix_s) + longitude_deg / 15.0 + world_equation_of_time_min(unix_s) / 60.0, 24.0);
    return h < 0.0 ? h + 24.0 : h;
}

/* Daytime heating: cumulus grows after late morning and decays through the evening. */
static double diurnal(double unix_s, double longitude_deg)
{
    double hour = weather_local_solar_hour(unix_s, longitude_deg);
    return smoothstep(10.5, 13.5, hour) * (1.0 - smoothstep(16.5, 19.5, hour));
}

double weather_autopilot_convection(int seed, double unix_s, double longitude_deg)
{
    double instability = value_noise(seed, CH_INSTABILITY, hours(unix_s) / 20.0);
    return diurnal(unix_s, longitude_deg) * (0.4 + 0.6 * instability);
}

void weather_autopilot_sample(int seed, double unix_s, double longitude_deg,
                              struct proto_weather_params *out)
{
    memset(out, 0, sizeof *out);
    double h = hours(unix_s);
    double wet = weather_autopilot_wetness(seed, unix_s);
    double ahead = weather_autopilot_wetness(seed, unix_s + CIRRUS_LEAD_H * 3600.0);
    double convection = weather_autopilot_convection(seed, unix_s, longitude_deg);
    double instability = value_noise(seed, CH_INSTABILITY, h / 20.0);
    /* No fair-weather cumulus under an overcast; storms need a wet front and instability. */
    double cumulus = convection * (1.0 - smoothstep(0.7, 0.95, wet));
    double storm = smoothstep(0.6, 0.9, wet) * smoothstep(0.5, 0.8, instability) *
                   (0.5 + 0.5 * diurnal(unix_s, longitude_deg));
    double stratiform = smoothstep(0.55, 0.85, wet) * (1.0 - storm);

    out->humidity = clamp(0.3 + 0.62 * wet - 0.12 * cumulus * (1.0 - wet), 0.05, 0.98);
    out->low.coverage = clamp(0.05 + 0.9 * smoothstep(0.35, 0.85, wet) + 0.45 * cumulus, 0.0, 1.0);
    out->low.type = clamp(0.67 - 0.6 * stratiform * (1.0 - cumulus) + 0.33 * storm, 0.0, 1.0);
    out->low.density = 0.7 + 0.5 * wet + 0.8 * storm;
    /* Cloud base at the lifting condensation level: about 125 m per kelvin of dew-point
     * depression (Espy), with T - Td ~ (100 - RH%) / 5 (Lawrence 2005, eq. 8). */
    out->low.bottom_km = clamp(0.125 * (100.0 - 100.0 * out->humidity) / 5.0, 0.2, 3.0);
    out->low.thickness_km = 0.6 + 1.6 * wet + 1.5 * cumulus + 7.0 * storm;
    /* Cirrus runs ahead of a wetter spell. */
    out->high.coverage =
        clamp(1.8 * fmax(0.0, ahead - wet) + 0.25 * value_noise(seed, CH_CIRRUS, h / 12.0) - 0.05,
              0.0, 1.0);
    /* Altostratus thickens ahead of the rain and stays in it (over the nimbostratus); when no
     * front is near, patches of altocumulus come and go. */
    double ahead_mid = weather_autopilot_wetness(seed, unix_s + MID_LEAD_H * 3600.0);
    double sheet = clamp(2.0 * fmax(0.0, ahead_mid - wet) + 0.6 * stratiform, 0.0, 1.0);
    out->mid.coverage = clamp(sheet + 0.35 * value_noise(seed, CH_MID, h / 10.0) - 0.15, 0.0, 1.0);
    out->mid.type = clamp(1.0 - 1.5 * sheet, 0.0, 1.0);
    out->mid.density = 0.3 + 0.4 * sheet;
    out->mid.bottom_km = 3.0 + 2.0 * value_noise(seed, CH_MID_BASE, h / 24.0);
    out->mid.thickness_km = 0.4 + 1.4 * sheet;
    out->high.type = 0.0;
    out->high.density = 0.2 + 0.2 * wet;
    out->high.bottom_km = 8.0 + 1.5 * value_noise(seed, CH_CIRRUS_BASE, h / 24.0);
    out->high.thickness_km = 0.6;
    out->precipitation = clamp(0.6 * smoothstep(0.72, 0.95, wet) + 0.4 * storm, 0.0, 1.0);
    out->wind_speed_m_s = 2.0 + 9.0 * wet + 10.0 * storm +
                          4.0 * value_noise(seed, CH_GUSTS, h / 6.0);
    /* A prevailing direction for the seed, veering as fronts pass. */
    double base = 360.0 * lattice(seed, CH_WIND_BASE, 0);
    double veer = 150.0 * (value_noise(seed, CH_WIND_VEER, h / 30.0) - 0.5) + 60.0 * (wet - 0.5);
    double direction = fmod(base + veer + 720.0, 360.0);
    out->wind_direction_deg = direction >= 360.0 ? 0.0 : direction;
}
