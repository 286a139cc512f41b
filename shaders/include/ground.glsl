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

// Radiance leaving the ground at p: albedo / pi * (E_sun cos + sky_weight E_sky) (Lambert);
// sky_weight < 1 where the converged multiple scattering brings the sky's part instead.
vec3 ground_radiance_weighted(vec3 p, vec3 sun_dir, float sky_weight)
{
    vec3 n = normalize(p);
    float mu_s = dot(n, sun_dir);
    vec3 direct = sun_transmittance(p + n * 1e-3, sun_dir) * max(mu_s, 0.0);
    return atmo.ground_albedo.xyz / PI * (direct + sky_weight * ground_irradiance_per_lux(mu_s));
}

vec3 ground_radiance_per_lux(vec3 p, vec3 sun_dir)
{
    return ground_radiance_weighted(p, sun_dir, 1.0);
}

#endif
