// Pinhole camera rays from the frame uniforms. uv in [0,1]^2, v = 0 at the top of the image.
#ifndef SKY_CAMERA_GLSL
#define SKY_CAMERA_GLSL

vec3 camera_ray(vec2 uv)
{
    float tan_half = frame.camera_forward.w;
    float aspect = frame.camera_right.w;
    vec2 ndc = vec2(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    vec3 d = frame.camera_forward.xyz + frame.camera_right.xyz * (ndc.x * tan_half * aspect)
             + frame.camera_up.xyz * (ndc.y * tan_half);
    return d * inversesqrt(dot(d, d));
}

// Inverse of camera_ray: the uv a direction projects to (outside [0,1] when off screen).
vec2 camera_uv(vec3 dir)
{
    float z = dot(dir, frame.camera_forward.xyz);
    if (z <= 1e-6)
        return vec2(-1.0);
    float tan_half = frame.camera_forward.w;
    float aspect = frame.camera_right.w;
    vec2 ndc = vec2(dot(dir, frame.camera_right.xyz) / (z * tan_half * aspect),
                    dot(dir, frame.camera_up.xyz) / (z * tan_half));
    return vec2(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
}

#endif
