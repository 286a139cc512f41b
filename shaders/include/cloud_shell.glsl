// The stretch of a ray inside a cloud layer's spherical shell, shared by the density's users
// (cloud_density.glsl) and the self-tests that replace the density with their own decks.
// Needs atmosphere.glsl (ray_sphere_nearest, ray_sphere_far, bottom_radius).
#ifndef CLOUD_SHELL_GLSL
#define CLOUD_SHELL_GLSL

// Range [t0, t1] of a ray inside the spherical shell [r_in, r_out], first crossing only;
// false when it misses it or the planet is in the way first.
bool shell_segment(vec3 o, vec3 d, float r_in, float r_out, out float t0, out float t1)
{
    t0 = t1 = 0.0;
    float r = length(o);
    if (r < r_in) {
        // Below: from the exit of the inner sphere to the exit of the outer one.
        t0 = ray_sphere_far(o, d, r_in);
        t1 = ray_sphere_far(o, d, r_out);
        return ray_sphere_nearest(o, d, bottom_radius()) < 0.0 && t1 > t0;
    }
    if (r <= r_out) {
        // Inside the shell: a descending ray that meets the inner sphere leaves there, at the
        // root nearest 0 (c / (-b + sqrt(disc)), free of cancellation, 0 on the sphere itself);
        // any other ray at the outer sphere. The nearest root of the general test would take
        // the far side of the inner sphere, through the planet, for a point on or a rounding
        // error inside it, and a level or rising ray on it would meet it at t = 0.
        t0 = 0.0;
        float b = dot(o, d), c = max((r - r_in) * (r + r_in), 0.0);
        float disc = b * b - c;
        t1 = b < 0.0 && disc >= 0.0 ? c / (sqrt(disc) - b) : ray_sphere_far(o, d, r_out);
        return t1 > 0.0;
    }
    float t_out = ray_sphere_nearest(o, d, r_out);
    if (t_out < 0.0)
        return false;
    t0 = t_out;
    float t_in_near = ray_sphere_nearest(o, d, r_in);
    t1 = t_in_near >= 0.0 ? t_in_near : ray_sphere_far(o, d, r_out);
    return t1 > t0;
}

#endif
