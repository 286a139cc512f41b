// Transmittance toward the sun through the clouds above ground point p: the cloud shadow map
// is tileable and sun-projected onto a flat planet, so the ground point's horizontal position
// in the wind-advected pattern indexes it. Needs `cloud` (sky_cloud_uniforms) and a
// `cloud_shadow_map` sampler (r: transmittance) with repeat addressing.
#ifndef CLOUD_GROUND_SHADOW_GLSL
#define CLOUD_GROUND_SHADOW_GLSL

float cloud_ground_shadow(vec3 p)
{
    vec2 pattern = p.xy - cloud.weather.xy;
    return textureLod(cloud_shadow_map, pattern * cloud.weather.z + 0.5, 0.0).r;
}

#endif
