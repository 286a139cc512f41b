// Tonemapping operators and sRGB encoding; both run last, on exposed luminance.
#ifndef SKY_TONEMAP_GLSL
#define SKY_TONEMAP_GLSL

// Narkowicz 2015 fit of the ACES filmic curve.
vec3 tonemap_aces(vec3 x)
{
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// Selects rather than branches on the uniform operator: lavapipe compiles a shader variant
// for each value of a uniform that a branch tests, and kept recompiling one pipeline.
vec3 tonemap(vec3 x, int op)
{
    x = max(x, vec3(0.0));
    vec3 mapped = tonemap_aces(x);
    mapped = mix(mapped, x / (1.0 + x), float(op == SKY_TONEMAP_OP_REINHARD));
    return mix(mapped, clamp(x, 0.0, 1.0), float(op == SKY_TONEMAP_OP_CLAMP));
}

// IEC 61966-2-1 sRGB transfer function. Above the linear segment, a sum of square roots
// stands in for the 1/2.4 power (max error 0.25 of an 8-bit step): pow costs an exp2 and a
// log2 per channel, which dominates a cheap pixel on CPU Vulkan.
vec3 linear_to_srgb(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    vec3 s1 = sqrt(c), s2 = sqrt(s1), s3 = sqrt(s2);
    vec3 hi = 0.662002687 * s1 + 0.684122060 * s2 - 0.323583601 * s3 - 0.0225411470 * c;
    return mix(hi, c * 12.92, lessThanEqual(c, vec3(0.0031308)));
}

#endif
