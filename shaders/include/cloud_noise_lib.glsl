// Tileable noise for the cloud volumes and the weather map: a hashed lattice, inverted
// Worley (cellular) noise and Perlin gradient noise, periodic over the unit cube (3D) or the
// unit square (2D, for the weather map). The
// including shader defines `noise_seed` (a uint) before including.
#ifndef CLOUD_NOISE_LIB_GLSL
#define CLOUD_NOISE_LIB_GLSL

uint hash(uvec4 v)
{
    // PCG-style mixing of the lattice cell and the seed.
    uint h = v.x * 747796405u + v.y * 2891336453u + v.z * 3545902487u + v.w * 2246822519u;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

vec3 hash3(ivec3 cell, uint salt)
{
    uvec4 k = uvec4(uvec3(cell), noise_seed * 7919u + salt);
    return vec3(hash(k), hash(k + uvec4(0u, 0u, 0u, 101u)), hash(k + uvec4(0u, 0u, 0u, 211u)))
           / 4294967295.0;
}

// Inverted cellular (Worley) noise, periodic with `period` cells over the unit cube.
float worley(vec3 x, int period, uint salt)
{
    vec3 p = x * float(period);
    ivec3 cell = ivec3(floor(p));
    float best = 1e9;
    for (int k = -1; k <= 1; k++)
        for (int j = -1; j <= 1; j++)
            for (int i = -1; i <= 1; i++) {
                ivec3 c = cell + ivec3(i, j, k);
                ivec3 wrapped = ((c % period) + period) % period;
                vec3 feature = vec3(c) + hash3(wrapped, salt);
                vec3 delta = feature - p;
                best = min(best, dot(delta, delta));
            }
    return 1.0 - clamp(sqrt(best), 0.0, 1.0);
}

// Periodic gradient (Perlin) noise in about [-1, 1].
float gradient_noise(vec3 x, int period, uint salt)
{
    vec3 p = x * float(period);
    ivec3 cell = ivec3(floor(p));
    vec3 f = p - vec3(cell);
    vec3 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    float corners[8];
    for (int n = 0; n < 8; n++) {
        ivec3 o = ivec3(n & 1, (n >> 1) & 1, (n >> 2) & 1);
        ivec3 c = (((cell + o) % period) + period) % period;
        vec3 g = normalize(hash3(c, salt) * 2.0 - 1.0 + 1e-4);
        corners[n] = dot(g, f - vec3(o));
    }
    float x00 = mix(corners[0], corners[1], u.x), x10 = mix(corners[2], corners[3], u.x);
    float x01 = mix(corners[4], corners[5], u.x), x11 = mix(corners[6], corners[7], u.x);
    return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z) * 1.7;
}

vec2 hash2(ivec2 cell, uint salt)
{
    uvec4 k = uvec4(uvec2(cell), noise_seed * 7919u + salt, 0u);
    return vec2(hash(k), hash(k + uvec4(0u, 0u, 0u, 101u))) / 4294967295.0;
}

// Periodic 2D gradient (Perlin) noise, mean 0, with `period` cells across the unit square
// (x and y may differ: a stretched pattern still tiles).
float gradient2(vec2 x, ivec2 period, uint salt)
{
    vec2 p = x * vec2(period);
    ivec2 cell = ivec2(floor(p));
    vec2 f = p - vec2(cell);
    vec2 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    float c[4];
    for (int n = 0; n < 4; n++) {
        ivec2 o = ivec2(n & 1, n >> 1);
        ivec2 wrapped = (((cell + o) % period) + period) % period;
        vec2 g = normalize(hash2(wrapped, salt) * 2.0 - 1.0 + 1e-4);
        c[n] = dot(g, f - vec2(o));
    }
    return mix(mix(c[0], c[1], u.x), mix(c[2], c[3], u.x), u.y);
}

// Inverted 2D cellular (Worley) noise: 1 at a cell's feature point, falling with distance.
float worley2(vec2 x, int period, uint salt)
{
    vec2 p = x * float(period);
    ivec2 cell = ivec2(floor(p));
    float best = 1e9;
    for (int j = -1; j <= 1; j++)
        for (int i = -1; i <= 1; i++) {
            ivec2 c = cell + ivec2(i, j);
            vec2 delta = vec2(c) + hash2(((c % period) + period) % period, salt) - p;
            best = min(best, dot(delta, delta));
        }
    return 1.0 - clamp(sqrt(best), 0.0, 1.0);
}

float perlin_fbm(vec3 x, int period, uint salt)
{
    float sum = 0.0, amp = 0.5;
    for (int o = 0; o < 3; o++) {
        sum += amp * gradient_noise(x, period << o, salt + uint(o));
        amp *= 0.5;
    }
    return clamp(sum / 0.875 * 0.5 + 0.5, 0.0, 1.0);
}

#endif
