// Camera rays from the frame uniforms. uv in [0,1]^2, v = 0 at the top of the image.
#ifndef SKY_CAMERA_GLSL
#define SKY_CAMERA_GLSL

const float CAMERA_PI = 3.14159265358979;

// A camera's direction for uv: a pinhole with vertical tan(fov/2) and aspect, or an
// equirectangular panorama around `up` with the azimuth of `forward` at its centre.
// Both are computed and one is selected, with no branch on `projection`: lavapipe (Mesa 22.3)
// inlines a uniform that decides a branch and may compile the pipeline again at every
// dispatch, never freeing the old code, which this branch on frame.camera_up.w did to the
// metering and sun-disk passes every frame. It runs both sides of a branch anyway, so the
// select costs nothing.
vec3 camera_ray_of(vec2 uv, vec3 forward, vec3 right, vec3 up, float tan_half, float aspect,
                   int projection)
{
    float azimuth = (uv.x - 0.5) * 2.0 * CAMERA_PI;
    float elevation = (0.5 - uv.y) * CAMERA_PI;
    vec3 horizontal = forward * cos(azimuth) + right * sin(azimuth);
    vec3 panorama = normalize(horizontal * cos(elevation) + up * sin(elevation));
    vec2 ndc = vec2(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    vec3 d = forward + right * (ndc.x * tan_half * aspect) + up * (ndc.y * tan_half);
    vec3 pinhole = d * inversesqrt(dot(d, d));
    return mix(pinhole, panorama, bvec3(projection == SKY_PROJECTION_EQUIRECTANGULAR));
}

// Inverse of camera_ray_of: the uv a direction projects to (outside [0,1] when off screen).
vec2 camera_uv_of(vec3 dir, vec3 forward, vec3 right, vec3 up, float tan_half, float aspect,
                  int projection)
{
    if (projection == SKY_PROJECTION_EQUIRECTANGULAR) {
        float azimuth = atan(dot(dir, right), dot(dir, forward));
        float elevation = asin(clamp(dot(dir, up), -1.0, 1.0));
        return vec2(azimuth / (2.0 * CAMERA_PI) + 0.5, 0.5 - elevation / CAMERA_PI);
    }
    float z = dot(dir, forward);
    if (z <= 1e-6)
        return vec2(-1.0);
    vec2 ndc = vec2(dot(dir, right) / (z * tan_half * aspect), dot(dir, up) / (z * tan_half));
    return vec2(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
}

int camera_projection()
{
    return int(frame.camera_up.w + 0.5);
}

vec3 camera_ray(vec2 uv)
{
    return camera_ray_of(uv, frame.camera_forward.xyz, frame.camera_right.xyz,
                         frame.camera_up.xyz, frame.camera_forward.w, frame.camera_right.w,
                         camera_projection());
}

vec2 camera_uv(vec3 dir)
{
    return camera_uv_of(dir, frame.camera_forward.xyz, frame.camera_right.xyz,
                        frame.camera_up.xyz, frame.camera_forward.w, frame.camera_right.w,
                        camera_projection());
}

// Relative solid angle of the pixel at uv: 1 for a pinhole (near enough for metering), the
// cosine of the elevation for an equirectangular panorama, whose rows shrink to the poles.
float camera_pixel_weight(vec2 uv)
{
    return camera_projection() == SKY_PROJECTION_EQUIRECTANGULAR ? sin(uv.y * CAMERA_PI) : 1.0;
}

#endif
