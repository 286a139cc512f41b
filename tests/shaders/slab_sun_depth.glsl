// In place of cloud_sun_depth.glsl for the self-tests' homogeneous deck (cloud.low: radii and
// extinction): the deck's optical depths along the sun's ray, exact where the renderer reads
// its sun-space volume. uv.x carries the sun's cosine to the local vertical.
#ifndef SLAB_SUN_DEPTH_GLSL
#define SLAB_SUN_DEPTH_GLSL

layout(binding = SKY_CLOUD_MARCH_SUN_DEPTH) uniform sampler3D sun_depth_volume;

bool sun_depth_coords(vec3 p, vec3 sun_dir, out vec2 uv)
{
    uv = vec2(max(dot(sun_dir, normalize(p)), 1e-3), 0.0);
    return true;
}

bool sun_depth_ground_coords(vec3 ground, vec3 sun_dir, out vec2 uv)
{
    return sun_depth_coords(ground, sun_dir, uv);
}

float sun_column_below(vec2 uv, float r)
{
    return cloud.low.z * (clamp(r, cloud.low.x, cloud.low.y) - cloud.low.x) / uv.x;
}

// The whole deck along the sun's ray; a deck has cloud on every side.
struct SunColumn {
    float depth, support;
};

SunColumn sun_column(vec2 uv)
{
    float depth = cloud.low.z * (cloud.low.y - cloud.low.x) / uv.x;
    return SunColumn(depth, 1.0);
}

#endif
