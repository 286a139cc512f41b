// The sun's optical depth through the low layer from the sun-space volume that cloud_shadow.comp
// builds with the shadow map: for a point p, the sun's ray through it meets the ground at a
// point whose pattern position indexes the volume, and the volume holds that ray's optical
// depth from the layer's base up to each of its altitude levels. Smooth and free of the
// jitter of a march: the marches take the far part of the sun's optical depth from it.
// Needs `cloud`, the atmosphere functions and the `sun_depth_volume` and `sun_column_map`
// samplers (repeat addressing).
#ifndef CLOUD_SUN_DEPTH_GLSL
#define CLOUD_SUN_DEPTH_GLSL

// The sun may have moved this far (cosine) from the one the volume was built for: the map
// follows it within about 0.3 degree (render/clouds/cloud_renderer.c).
const float SUN_DEPTH_SUN_COS = 0.99996;

// The volume's coordinates for a point on the ground: the sun's ray through it meets the ground
// there. (sun_depth_coords from a point on the sphere leaves the intersection to round-off, which
// puts some of them on the planet's far side, a random texel of the volume.) False when the
// volume was not built for this sun or the sun is below the point's horizon.
bool sun_depth_ground_coords(vec3 ground, vec3 sun_dir, out vec2 uv)
{
    uv = vec2(0.0);
    if (cloud.shadow_sun.w < 0.5 || dot(sun_dir, cloud.shadow_sun.xyz) < SUN_DEPTH_SUN_COS ||
        dot(sun_dir, ground) <= 0.0)
        return false;
    uv = (ground.xy - cloud.weather.xy) * cloud.weather.z + 0.5;
    return true;
}

// The volume's coordinates for p: false when it was not built for this sun, or when the sun's
// ray through p does not come from the ground (a sun at the horizon).
bool sun_depth_coords(vec3 p, vec3 sun_dir, out vec2 uv)
{
    uv = vec2(0.0);
    float t = ray_sphere_nearest(p, -sun_dir, bottom_radius());
    return t >= 0.0 && sun_depth_ground_coords(p - sun_dir * t, sun_dir, uv);
}

// The low layer's optical depth along the sun's ray through p from the layer's base up to
// radius r.
float sun_column_below(vec2 uv, float r)
{
    const float levels = float(SKY_CLOUD_SUN_DEPTH_LEVELS);
    float h = clamp((r - cloud.low.x) / (cloud.low.y - cloud.low.x), 0.0, 1.0);
    return textureLod(sun_depth_volume, vec3(uv, (h * (levels - 1.0) + 0.5) / levels), 0.0).r;
}

// A sun column's state (cloud_shadow.comp, cloud_sun_columns.comp): the optical depth of both
// layers along the sun's ray, and its support: how much of the cloud around it is still cloud
// 400 m to its sides, in [0, 1] (1 in a deck, less at the edge of a cloud of a few kilometres,
// whose diffuse light also leaves through its sides).
struct SunColumn {
    float depth, support;
};

SunColumn sun_column(vec2 uv)
{
    vec4 c = textureLod(sun_column_map, uv, 0.0);
    return SunColumn(c.g, c.b);
}

#endif
