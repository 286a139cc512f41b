#include "cloud_params.h"

#include <math.h>
#include <string.h>

#define V4(x_, y_, z_, w_) ((sky_vec4){ (float)(x_), (float)(y_), (float)(z_), (float)(w_) })

/* Cloud-type shapes over the layer's height fraction (after Schneider 2015/2017's density
 * gradients per type, cloud_density.glsl's profile_rise): the height of the highest tops, the
 * base's rounding, the detail erosion of the edges, the anvil. Stratus are thin sheets;
 * stratocumulus reach half the layer; cumulus domes most of it (humilis to congestus, by the
 * strength of their columns); cumulonimbus towers fill it and spread into an anvil under its
 * top. */
static const float type_shapes[CLOUD_PROFILE_COUNT][4] = {
    { 0.35f, 0.10f, 0.15f, 0.0f }, /* stratus */
    { 0.55f, 0.06f, 0.25f, 0.0f }, /* stratocumulus */
    { 0.90f, 0.03f, 0.25f, 0.0f }, /* cumulus */
    { 0.95f, 0.02f, 0.30f, 1.0f }, /* cumulonimbus */
};

/* Cell size of each type's weather pattern, km (cloud_weather.comp). */
static const double cell_km[4] = {
    1.6,  /* cumulus clumps */
    12.0, /* cumulonimbus cells */
    1.6,  /* stratocumulus cells */
    15.0, /* stratus sheet variations */
};

/* Longest distance marched through one layer (grazing rays would otherwise take the whole
 * shell around the planet): far enough for a storm's tower on the horizon (a cumulonimbus
 * 100 km away, whose 12 km layer a ray 5 degrees up crosses from 12 km on, vanished at 80).
 * Steps grow with the distance and empty space is skipped, so the longer reach costs no
 * measurable frame time. */
#define LONGEST_MARCH_KM 160.0

static bool layer_on(const struct sky_render_cloud_layer *layer)
{
    return layer->coverage > 0.0 && layer->density > 0.0;
}

bool cloud_params_any_layer(const struct sky_render_clouds *c)
{
    return c->use_client_map || layer_on(&c->low) || layer_on(&c->mid) || layer_on(&c->high);
}

void cloud_params_weather_periods(const struct sky_render_clouds *c, float periods[4])
{
    double extent = c->map_extent_km > 0.0 ? c->map_extent_km : 60.0;
    for (int i = 0; i < 4; i++)
        /* At most 64 cells across the map (its base octave): 16 texels a cell at least. */
        periods[i] = (float)fmin(64.0, fmax(1.0, round(extent / cell_km[i])));
}

int cloud_params_block(enum sky_render_cloud_resolution resolution)
{
    switch (resolution) {
    case SKY_RENDER_CLOUDS_FULL:
        return 1;
    case SKY_RENDER_CLOUDS_QUARTER:
        return 2;
    default:
        return 4;
    }
}

int cloud_params_downscale(enum sky_render_cloud_resolution resolution)
{
    return resolution == SKY_RENDER_CLOUDS_SIXTYFOURTH ? 2 : 1;
}

/* The tile closest to `wanted` km that repeats a whole number of times over `extent`. */
static double tile_km(double extent, double wanted)
{
    double count = fmax(1.0, round(extent / wanted));
    return extent / count;
}

/* The same, an even number of times: twice it tiles too (cloud_density.glsl's towers). */
static double even_tile_km(double extent, double wanted)
{
    return 0.5 * tile_km(extent, 2.0 * wanted);
}

void cloud_params_fill(const struct sky_render_clouds *c, double R, struct sky_cloud_uniforms *u)
{
    memset(u, 0, sizeof *u);
    const struct sky_render_cloud_layer *lo = &c->low, *hi = &c->high;
    bool high_on = c->use_client_map || layer_on(hi);
    u->low = V4(R + lo->bottom_km, R + lo->bottom_km + lo->thickness_km,
                c->extinction_per_km * lo->density, 1);
    u->high = V4(R + hi->bottom_km, R + hi->bottom_km + hi->thickness_km,
                 c->extinction_per_km * hi->density, high_on ? 1 : 0);
    /* The middle layer is the same everywhere in the weather map (client maps included): its
     * coverage and type come from these uniforms (cloud_density.glsl's mid_density_or_empty). */
    const struct sky_render_cloud_layer *mi = &c->mid;
    u->mid = V4(R + mi->bottom_km, R + mi->bottom_km + mi->thickness_km,
                c->extinction_per_km * mi->density, layer_on(mi) ? 1 : 0);
    u->mid_shape = V4(fmin(fmax(mi->coverage, 0.0), 1.0), fmin(fmax(mi->type, 0.0), 1.0), 0, 0);
    u->media = V4(c->albedo, c->precipitation, c->ambient_scale, hi->type);
    u->phase = V4(c->phase_g0, c->phase_g1, c->phase_w, c->multiscatter_octaves);
    /* a <= b keeps the octaves energy conserving (seed 001 5.8). */
    u->octaves = V4(fmin(c->multiscatter_a, c->multiscatter_b), c->multiscatter_b,
                    c->multiscatter_c, c->light_steps);
    double extent = c->map_extent_km > 0.0 ? c->map_extent_km : 60.0;
    /* The wind's displacement only matters modulo the tiled pattern: keep floats small. */
    double east = fmod(c->wind_offset_east_km, extent),
           north = fmod(c->wind_offset_north_km, extent);
    u->weather = V4(east, north, 1.0 / extent, extent);
    u->march = V4(c->primary_steps, LONGEST_MARCH_KM, cloud_params_any_layer(c) ? 1 : 0, 0);
    for (int i = 0; i < CLOUD_PROFILE_COUNT; i++)
        u->profiles[i] = V4(type_shapes[i][0], type_shapes[i][1], type_shapes[i][2],
                            type_shapes[i][3]);
    /* Base noise turrets of 150-600 m (Wielicki & Welch 1986: cumulus turrets 250 m - 1 km;
     * cells of a quarter to a sixteenth of the tile), detail of tens of metres, curl distortion
     * over a few kilometres. */
    u->tiles = V4(even_tile_km(extent, 2.5), tile_km(extent, 0.8), tile_km(extent, 12.0), 0);
    u->build_up = V4(c->multiscatter_powder, 0, 0, 0);
}
