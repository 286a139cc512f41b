// Single scattering from the sun plus the multiple-scattering LUT along a ray (Hillaire 2020,
// sections 4-5), integrated per step with the energy-conserving formula of seed 001 eq. 17 /
// appendix C eq. 23. Needs atmosphere.glsl with both LUTs. Results are per unit sun
// illuminance.

#ifndef SKY_SCATTERING_MARCH_GLSL
#define SKY_SCATTERING_MARCH_GLSL

struct MarchResult {
    vec3 luminance;     // in-scattered luminance reaching the origin
    vec3 transmittance; // along the marched segment
    float t_end;        // where the march stopped
    bool hits_ground;
};

// Marches from origin along dir through the atmosphere, at most to t_limit, with `steps`
// samples (quadratic spacing from inside the atmosphere, uniform when entering from space).
// ms_weight scales the multiple-scattering LUT's part (the sky-view fades it out where the
// converged multiple scattering of ms_table.glsl takes over).
MarchResult march_scattering_weighted(vec3 origin, vec3 dir, vec3 sun_dir, float t_limit,
                                      float steps, float ms_weight)
{
    MarchResult res;
    res.luminance = vec3(0.0);
    res.transmittance = vec3(1.0);
    res.hits_ground = false;
    res.t_end = 0.0;
    float t_start, t_end;
    bool hits_ground;
    if (!atmosphere_segment(origin, dir, t_start, t_end, hits_ground))
        return res;
    res.hits_ground = hits_ground && t_end <= t_limit;
    t_end = min(t_end, t_limit);
    res.t_end = t_end;
    if (t_end <= t_start)
        return res;

    bool from_space = length(origin) > top_radius();
    float cos_theta = dot(dir, sun_dir);
    float phase_r = rayleigh_phase(cos_theta);
    vec3 phase_m = mie_phase(cos_theta, atmo.mie_g.xyz);
    float t_prev = t_start;
    for (float i = 0.0; i < steps; i += 1.0) {
        float t_next = from_space ? mix(t_start, t_end, (i + 1.0) / steps)
                                  : march_boundary(t_start, t_end, i + 1.0, steps);
        float dt = t_next - t_prev;
        float t = t_prev + 0.5 * dt;
        t_prev = t_next;
        vec3 p = origin + t * dir;
        float r = length(p);
        MediumSample m = sample_medium(r - bottom_radius());
        vec3 sun_t = sun_transmittance(p, sun_dir);
        vec3 ms = multiscattering(r, dot(p / r, sun_dir));
        vec3 source = sun_t * (m.rayleigh_scattering * phase_r + m.mie_scattering * phase_m)
                      + ms * m.scattering * ms_weight;
        vec3 step_t = exp(-m.extinction * dt);
        // Energy-conserving integral of the source over the step (seed 001 eq. 23).
        vec3 integral = mix(source * dt, (source - source * step_t) / max(m.extinction, vec3(1e-9)),
                            greaterThan(m.extinction, vec3(1e-9)));
        res.luminance += res.transmittance * integral;
        res.transmittance *= step_t;
    }
    return res;
}

MarchResult march_scattering(vec3 origin, vec3 dir, vec3 sun_dir, float t_limit, float steps)
{
    return march_scattering_weighted(origin, dir, sun_dir, t_limit, steps, 1.0);
}

#endif
