// Clouds in the final image: the reconstructed cloud layer over the sky (its opacity hides the
// sky and the sun disk behind it), cloud shadows on the ground (shadow map) and the clouds'
// effect on the aerial perspective and sky light below them (seed 001 eq. 22), and the light
// shafts their shadows cut into it. Needs sky_shading.glsl, the composite's bindings 8-14 and
// `cloud` (sky_cloud_uniforms).
#ifndef CLOUD_COMPOSITE_GLSL
#define CLOUD_COMPOSITE_GLSL

// Transmittance toward the sun through the clouds above ground point p (flat-planet
// projection along the sun onto the tileable shadow map).
float cloud_ground_shadow(vec3 p)
{
    vec2 pattern = p.xy - cloud.weather.xy;
    return textureLod(cloud_shadow_map, pattern * cloud.weather.z + 0.5, 0.0).r;
}

// The ground seen from inside the atmosphere, relit under the clouds: the sun's direct light
// through the shadow map, the sky's light through the clouds' mean transmittance plus the
// clouds' own light (eq. 22), and the aerial perspective in front of it likewise (eq. 22).
vec3 ground_under_clouds(vec3 cam, vec3 dir, float t, vec3 L)
{
    if (t < 0.0 || cloud.shadow_sun.w < 0.5)
        return L;
    vec3 p = cam + t * dir;
    vec3 n = normalize(p);
    vec3 sun_dir = frame.sun_direction.xyz;
    float mu_s = dot(n, sun_dir);
    vec3 e_top = frame.sun_illuminance.xyz;
    vec3 direct = sun_transmittance(p + n * 1e-3, sun_dir) * max(mu_s, 0.0);
    vec3 sky = ground_irradiance_per_lux(mu_s);
    vec3 albedo = atmo.ground_albedo.xyz / PI;
    // Transmittance camera <-> ground from the LUT: T(p, -dir) / T(cam, -dir).
    float r_cam = max(length(cam), bottom_radius() + 1e-3);
    vec3 t_cam = transmittance_to_top(r_cam, dot(cam / r_cam, -dir));
    vec3 t_path = transmittance_to_top(bottom_radius() + 1e-3, dot(n, -dir))
                  / max(t_cam, vec3(1e-6));
    t_path = clamp(t_path, 0.0, 1.0);
    vec3 ground = albedo * (direct + sky) * e_top;
    vec3 inscatter = max(L - t_path * ground, vec3(0.0));
    float tr = env_transmittance.x;
    vec3 l_cloud = env_luminance.rgb * e_top;
    vec3 lit = albedo * (direct * cloud_ground_shadow(p) + sky * tr) * e_top + albedo * PI * l_cloud;
    return inscatter * tr + l_cloud * (1.0 - t_path) + t_path * lit; // seed 001 eq. 22
}

// Light shafts: the sky-view LUT's in-scattering is unshadowed; take away what the clouds'
// shadows remove along the ray up to the ground, or to the end of the froxel volume (the sun
// light shadowed there, aerial_perspective.comp).
vec3 light_shafts(ivec2 px, float t)
{
    if (cloud.shadow_sun.w < 0.5)
        return vec3(0.0);
    float max_km = frame.image.z;
    float depth = t >= 0.0 ? min(t, max_km) : max_km;
    vec2 slice = aerial_perspective_slice(depth, max_km, float(textureSize(ap_shafts, 0).z));
    vec3 at = vec3((vec2(px) + 0.5) / frame.image.xy, slice.x);
    return textureLod(ap_shafts, at, 0.0).rgb * slice.y * frame.sun_illuminance.xyz;
}

vec3 apply_clouds(ivec2 px, vec3 dir, vec3 L)
{
    if (cloud.march.z < 0.5)
        return L;
    if (!FROM_SPACE) {
        vec3 cam = frame.camera_position.xyz;
        float t_ground = ray_sphere_nearest(cam, dir, bottom_radius());
        L = max(L - light_shafts(px, t_ground), vec3(0.0));
        L = ground_under_clouds(cam, dir, t_ground, L);
    }
    // The cloud image may be half the output's size: bilinear on premultiplied colour.
    vec4 c = textureLod(cloud_image, (vec2(px) + 0.5) / frame.image.xy, 0.0);
    return L * (1.0 - c.a) + c.rgb;
}

#endif
