// Tonemapping operators and sRGB encoding; both run last, on exposed luminance.
#ifndef SKY_TONEMAP_GLSL
#define SKY_TONEMAP_GLSL

// Narkowicz 2015 fit of the ACES filmic curve.
vec3 tonemap_aces(vec3 x)
{
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 tonemap(vec3 x, int op)
{
    x = max(x, vec3(0.0));
    if (op == SKY_TONEMAP_OP_REINHARD)
        return x / (1.0 + x);
    if (op == SKY_TONEMAP_OP_CLAMP)
        return clamp(x, 0.0, 1.0);
    return tonemap_aces(x);
}

// IEC 61966-2-1 sRGB transfer function.
vec3 linear_to_srgb(vec3 c)
{
    vec3 lo = c * 12.92;
    vec3 hi = 1.055 * pow(max(c, vec3(0.0)), vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(c, vec3(0.0031308)));
}

#endif
