// The planet surface: a Lambertian sphere lit by the sun (through the atmosphere, with the
// planet's own shadow) and by the sky (ground irradiance LUT). Per unit sun illuminance.
// Needs atmosphere.glsl with SKY_HAS_TRANSMITTANCE_LUT and an `irradiance_lut` sampler.
#ifndef SKY_GROUND_GLSL
#define SKY_GROUND_GLSL

vec3 ground_irradiance_per_lux(float mu_s)
{
    float size = float(textureSize(irradiance_lut, 0).x);
    float u = unit_to_sub_uv(clamp(mu_s * 0.5 + 0.5, 0.0, 1.0), size);
    return textureLod(irradiance_lut, vec2(u, 0.5), 0.0).rgb;
}

// Radiance leaving the ground at p: albedo / pi * (E_sun cos + E_sky) (Lambert).
vec3 ground_radiance_per_lux(vec3 p, vec3 sun_dir)
{
    vec3 n = normalize(p);
    float mu_s = dot(n, sun_dir);
    vec3 direct = sun_transmittance(p + n * 1e-3, sun_dir) * max(mu_s, 0.0);
    return atmo.ground_albedo.xyz / PI * (direct + ground_irradiance_per_lux(mu_s));
}

#endif
