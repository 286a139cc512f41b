#version 450
#extension GL_GOOGLE_include_directive : require
// Once a shadow map's last slice is done (cloud_shadow.comp): each sun column's support, how
// much of the low layer's cloud around it is still cloud LATERAL_KM to its sides, in [0, 1]:
// the four neighbouring columns' optical depths (each at most the column's own) over the
// column's own, from the finished sun-space volume. 1 in a deck; less at the edge of a cloud of
// a few kilometres, whose diffuse light also leaves through its sides (cloud_light.glsl). Kept
// in the shadow map's b channel beside its transmittance (r) and optical depth (g), so that a
// march reads a column's whole state in one lookup instead of five of the volume per sample.
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_CLOUD_COLUMNS_CLOUD, CloudBlock, sky_cloud_uniforms, cloud);
layout(binding = SKY_CLOUD_COLUMNS_SUN_DEPTH) uniform sampler3D sun_depth_volume;
layout(binding = SKY_CLOUD_COLUMNS_SHADOW, rgba32f) uniform image2D shadow_map;
// params.xyz: the sun the map was built for.
layout(push_constant) uniform RowsPush { sky_cloud_rows_push push; };

const float LATERAL_KM = 0.4;

// The low layer's whole optical depth along the sun's ray through the column at uv.
float low_total(vec2 uv)
{
    const float top = 1.0 - 0.5 / float(SKY_CLOUD_SUN_DEPTH_LEVELS);
    return textureLod(sun_depth_volume, vec3(uv, top), 0.0).r;
}

void main()
{
    cloud = cloud_block;
    ivec2 size = imageSize(shadow_map);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, size)))
        return;
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
    vec3 sun = push.params.xyz;
    float own = low_total(uv);
    float support = 1.0;
    if (own > 0.0) {
        vec2 across = normalize(abs(sun.x) + abs(sun.y) > 1e-4 ? vec2(-sun.y, sun.x)
                                                                : vec2(1.0, 0.0));
        vec2 along = vec2(-across.y, across.x);
        vec2 step_a = across * LATERAL_KM * cloud.weather.z;
        vec2 step_b = along * LATERAL_KM * cloud.weather.z;
        float sum = min(low_total(uv + step_a), own) + min(low_total(uv - step_a), own) +
                    min(low_total(uv + step_b), own) + min(low_total(uv - step_b), own);
        support = sum / (4.0 * own);
    }
    vec4 column = imageLoad(shadow_map, px);
    imageStore(shadow_map, px, vec4(column.rg, support, column.a));
}
