// The low layer's cloud types and height profiles (cloud_density.glsl), shared with the path
// tracer's majorant grid (cloud_majorant.comp), which bounds where each column can hold cloud.
// The including shader declares `cloud` (sky_cloud_uniforms).
#ifndef CLOUD_PROFILE_GLSL
#define CLOUD_PROFILE_GLSL

// Shape parameters of a cloud type in [0, 1] (stratus .. cumulonimbus), interpolated between
// the tabulated types (render/cloud_params.c): x the height fraction of the highest tops,
// y base rounding, z erosion, w anvil.
vec4 type_shape(float type)
{
    float x = clamp(type, 0.0, 1.0) * float(CLOUD_PROFILE_COUNT - 1);
    int i = min(int(x), CLOUD_PROFILE_COUNT - 2);
    return mix(cloud.profiles[i], cloud.profiles[i + 1], x - float(i));
}

float layer_fraction(float r, vec4 layer)
{
    return (r - layer.x) / (layer.y - layer.x);
}

// The base shape is stored uniformly distributed (cloud_noise.comp), so a coverage c keeps the
// c of it that lies above 1 - c. Coverage at a height is the column's coverage with its normal
// score lowered by the profile's rise: Phi(Phi^-1(c) - rise), with the logistic approximation
// of Phi (s = 1.702): c / (c + (1 - c) exp(s rise)).
const float LOGISTIC_PROBIT = 1.702;
float coverage_at(float c, float rise)
{
    c = min(c, 0.995);
    return c / (c + (1.0 - c) * exp(LOGISTIC_PROBIT * rise));
}

// How far (normal scores) the threshold rises at height fraction h (Schneider 2017's
// density-height gradient as a threshold): slowly up to RISE_AT_TOP at the type's tops
// shape.x, then fast, so that only the strongest columns reach them and no top is cut flat by
// the layer.
const float RISE_AT_TOP = 2.6;
float profile_rise(float h, vec4 shape)
{
    float x = h / shape.x;
    return RISE_AT_TOP * x * x + 30.0 * max(h - shape.x, 0.0) + 12.0 * smoothstep(0.9, 1.0, h);
}

// The largest of type_shape(t).x over the types t in [lo, hi]: type_shape is linear between
// the tabulated types, so the ends and the tabulated types between them.
float highest_top(float lo, float hi)
{
    float top = max(type_shape(lo).x, type_shape(hi).x);
    for (int i = 1; i < CLOUD_PROFILE_COUNT - 1; i++) {
        float t = float(i) / float(CLOUD_PROFILE_COUNT - 1);
        if (t > lo && t < hi)
            top = max(top, cloud.profiles[i].x);
    }
    return top;
}

// The height fraction above which a column of coverage at most c, of a type whose tops reach
// at most `top` (shape.x), holds no cloud: the density's coverage_at(c, profile_rise(h)) falls
// to CLOUD_MIN_COVERAGE m where the rise reaches ln(c (1 - m) / (m (1 - c))) / s (coverage_at
// inverted), and profile_rise grows with h (and falls with the top), so bisection finds it.
// Anvils (cloud_density.glsl's low_coverage) are not bounded by it: 1 for their types.
float cloud_top_fraction(float c, float top)
{
    c = min(c, 0.995);
    float m = CLOUD_MIN_COVERAGE;
    if (c <= m)
        return 0.0;
    float rise_max = log(c * (1.0 - m) / (m * (1.0 - c))) / LOGISTIC_PROBIT;
    vec4 shape = vec4(top, 0.0, 0.0, 0.0);
    if (profile_rise(1.0, shape) < rise_max)
        return 1.0;
    float lo = 0.0, hi = 1.0;
    for (int i = 0; i < 24; i++) {
        float h = 0.5 * (lo + hi);
        if (profile_rise(h, shape) < rise_max)
            lo = h;
        else
            hi = h;
    }
    return hi;
}

#endif
