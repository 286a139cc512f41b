// The converged multiple-scattering tables (render/sky/ms_refine.h): 4D functions of
// (r, mu, mu_s, nu) stored in a 3D image of SKY_MS_NU * SKY_MS_MU_S x SKY_MS_MU x SKY_MS_R
// texels, parameterized as Bruneton's scattering texture (Bruneton & Neyret 2008 section 4,
// as in the 2017 reference implementation): r by rho = sqrt(r^2 - R^2), mu by the distance to
// the atmosphere's boundary with ground rays in the first half and sky rays in the second (sky
// rays by the square root of that distance's fraction: with it linear, a point on the ground
// had the 60 deg around its zenith within two rows, and the sky's light on the ground came out
// 3-4% low in twilight), mu_s by the distance to the top from the ground (dense at the horizon,
// down to SKY_MS_MU_S_MIN), nu linear; the nu axis is interpolated by hand between two 3D
// fetches.
// Needs atmosphere.glsl.
#ifndef SKY_MS_TABLE_GLSL
#define SKY_MS_TABLE_GLSL

// 4-point Gauss-Legendre nodes and weights on [0, 1] (Abramowitz & Stegun table 25.4, mapped).
const float GL4_X[4] = float[4](0.0694318442, 0.3300094782, 0.6699905218, 0.9305681558);
const float GL4_W[4] = float[4](0.1739274226, 0.3260725774, 0.3260725774, 0.1739274226);

const float MS_NU = float(SKY_MS_NU);
const float MS_MU_S = float(SKY_MS_MU_S);
const float MS_MU = float(SKY_MS_MU);
const float MS_R = float(SKY_MS_R);

float ms_distance_to_top(float r, float mu)
{
    float top = top_radius();
    return max(0.0, -r * mu + sqrt(max(0.0, r * r * (mu * mu - 1.0) + top * top)));
}

// The mu_s coordinate of Bruneton's texture (2017, GetScatteringTextureUvwzFromRMuMuSNu).
float ms_mu_s_to_unit(float mu_s)
{
    float bottom = bottom_radius(), top = top_radius();
    float H = sqrt(max(0.0, top * top - bottom * bottom));
    float d_min = top - bottom, d_max = H;
    float d = ms_distance_to_top(bottom, mu_s);
    float a = (d - d_min) / (d_max - d_min);
    float A = (ms_distance_to_top(bottom, SKY_MS_MU_S_MIN) - d_min) / (d_max - d_min);
    return max(1.0 - a / A, 0.0) / (1.0 + a);
}

float ms_unit_to_mu_s(float x)
{
    float bottom = bottom_radius(), top = top_radius();
    float H = sqrt(max(0.0, top * top - bottom * bottom));
    float d_min = top - bottom, d_max = H;
    float A = (ms_distance_to_top(bottom, SKY_MS_MU_S_MIN) - d_min) / (d_max - d_min);
    float a = (A - x * A) / (1.0 + x * A);
    float d = d_min + min(a, A) * (d_max - d_min);
    return d == 0.0 ? 1.0 : clamp((H * H - d * d) / (2.0 * bottom * d), -1.0, 1.0);
}

// The w coordinate (altitude) of a radius.
float ms_r_coord(float r)
{
    float bottom = bottom_radius(), top = top_radius();
    float H = sqrt(max(0.0, top * top - bottom * bottom));
    r = clamp(r, bottom, top);
    float rho = sqrt(max(0.0, r * r - bottom * bottom));
    return unit_to_sub_uv(rho / H, MS_R);
}

// The same, but between two altitude slices the weights go by altitude rather than by rho:
// the light changes about exponentially with altitude near the ground, and rho = sqrt(2 R h)
// there put a camera 1.5 km up 85% of the way to the slice at 2 km, where it is 75%.
float ms_r_coord_by_altitude(float r)
{
    float bottom = bottom_radius(), top = top_radius();
    float H = sqrt(max(0.0, top * top - bottom * bottom));
    r = clamp(r, bottom, top);
    float s = sqrt(max(0.0, r * r - bottom * bottom)) / H * (MS_R - 1.0);
    float k = min(floor(s), MS_R - 2.0);
    float rho0 = H * k / (MS_R - 1.0), rho1 = H * (k + 1.0) / (MS_R - 1.0);
    float r0 = sqrt(rho0 * rho0 + bottom * bottom), r1 = sqrt(rho1 * rho1 + bottom * bottom);
    return (k + clamp((r - r0) / (r1 - r0), 0.0, 1.0) + 0.5) / MS_R;
}

// The u coordinate of a sun zenith within one nu slice.
float ms_mu_s_coord(float mu_s)
{
    return unit_to_sub_uv(clamp(ms_mu_s_to_unit(mu_s), 0.0, 1.0), MS_MU_S);
}

// The v coordinate (view zenith) at radius r.
float ms_mu_coord(float r, float mu)
{
    float bottom = bottom_radius(), top = top_radius();
    float H = sqrt(max(0.0, top * top - bottom * bottom));
    r = clamp(r, bottom, top);
    float rho = sqrt(max(0.0, r * r - bottom * bottom));
    float r_mu = r * mu;
    float disc = r_mu * r_mu - r * r + bottom * bottom;
    float half_mu = MS_MU * 0.5;
    if (mu < 0.0 && disc >= 0.0) {
        float d = -r_mu - sqrt(disc);
        float d_min = r - bottom, d_max = rho;
        float x = d_max == d_min ? 0.0 : clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
        return 0.5 - 0.5 * unit_to_sub_uv(x, half_mu);
    }
    float d = -r_mu + sqrt(max(0.0, disc + H * H));
    float d_min = top - r, d_max = rho + H;
    float x = clamp((d - d_min) / max(d_max - d_min, 1e-6), 0.0, 1.0);
    return 0.5 + 0.5 * unit_to_sub_uv(sqrt(x), half_mu);
}

// Texture coordinates (u of one nu slice, v, w) and the nu coordinate in [0, 1].
vec4 ms_coords(float r, float mu, float mu_s, float nu)
{
    return vec4(ms_mu_s_coord(mu_s), ms_mu_coord(r, mu), ms_r_coord(r),
                clamp((nu + 1.0) * 0.5, 0.0, 1.0));
}

// The (r, mu, mu_s, nu) of a texel's centre (the inverse of ms_coords).
void ms_texel_params(ivec3 texel, out float r, out float mu, out float mu_s, out float nu)
{
    float bottom = bottom_radius(), top = top_radius();
    float H = sqrt(max(0.0, top * top - bottom * bottom));
    float rho = H * float(texel.z) / (MS_R - 1.0);
    r = sqrt(rho * rho + bottom * bottom);
    int half_mu = SKY_MS_MU / 2;
    if (texel.y < half_mu) {
        float x = float(half_mu - 1 - texel.y) / float(half_mu - 1);
        float d_min = r - bottom, d_max = rho;
        float d = d_min + x * (d_max - d_min);
        mu = d == 0.0 ? -1.0 : clamp(-(rho * rho + d * d) / (2.0 * r * d), -1.0, 1.0);
    } else {
        float x = float(texel.y - half_mu) / float(half_mu - 1);
        x = x * x;
        float d_min = top - r, d_max = rho + H;
        float d = d_min + x * (d_max - d_min);
        mu = d == 0.0 ? 1.0 : clamp((H * H - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
    }
    int i_nu = texel.x / SKY_MS_MU_S, i_mu_s = texel.x % SKY_MS_MU_S;
    mu_s = ms_unit_to_mu_s(float(i_mu_s) / (MS_MU_S - 1.0));
    nu = float(i_nu) / (MS_NU - 1.0) * 2.0 - 1.0;
    // nu is bounded by the two zenith angles.
    float spread = sqrt(max(0.0, (1.0 - mu * mu) * (1.0 - mu_s * mu_s)));
    nu = clamp(nu, mu * mu_s - spread, mu * mu_s + spread);
}

// The view direction and the sun of a texel's (mu, mu_s, nu) in a frame with the point on +z.
void ms_directions(float mu, float mu_s, float nu, out vec3 view, out vec3 sun)
{
    float sin_mu = sqrt(max(0.0, 1.0 - mu * mu));
    view = vec3(sin_mu, 0.0, mu);
    float sx = sin_mu > 1e-4 ? clamp((nu - mu * mu_s) / sin_mu, -1.0, 1.0)
                             : sqrt(max(0.0, 1.0 - mu_s * mu_s));
    sun = vec3(sx, sqrt(max(0.0, 1.0 - sx * sx - mu_s * mu_s)), mu_s);
}

// A value of the table at coordinates c (ms_coords), interpolated in all four: the
// altitude and sun zenith of a texel are the same for all the directions around it, so
// callers that integrate over directions compute those coordinates once.
vec3 ms_lookup_coords(sampler3D table, vec4 c)
{
    float t = c.w * (MS_NU - 1.0);
    float i = min(floor(t), MS_NU - 2.0);
    float f = t - i;
    vec3 a = textureLod(table, vec3((i + c.x) / MS_NU, c.y, c.z), 0.0).rgb;
    vec3 b = textureLod(table, vec3((i + 1.0 + c.x) / MS_NU, c.y, c.z), 0.0).rgb;
    return mix(a, b, f);
}

// A table that holds logarithms (the scattering density) at (r, mu, mu_s, nu): the filtered
// fetches interpolate the logarithm, i.e. geometrically, in r, mu and mu_s, then nu linearly.
vec3 ms_lookup_of_log(sampler3D log_table, float r, float mu, float mu_s, float nu)
{
    vec4 c = ms_coords(r, mu, mu_s, nu);
    float t = c.w * (MS_NU - 1.0);
    float i = min(floor(t), MS_NU - 2.0);
    float f = t - i;
    vec3 a = exp(textureLod(log_table, vec3((i + c.x) / MS_NU, c.y, c.z), 0.0).rgb);
    vec3 b = exp(textureLod(log_table, vec3((i + 1.0 + c.x) / MS_NU, c.y, c.z), 0.0).rgb);
    return mix(a, b, f);
}

// Catmull-Rom weights of four evenly spaced nodes for a point at t in [0, 1] between the middle
// two.
vec4 ms_catmull_rom(float t)
{
    float t2 = t * t, t3 = t2 * t;
    return 0.5 * vec4(-t3 + 2.0 * t2 - t, 3.0 * t3 - 5.0 * t2 + 2.0, -3.0 * t3 + 4.0 * t2 + t,
                      t3 - t2);
}

// A value of the table at (r, mu, mu_s, nu): linear in r, mu and nu, and cubic in the logarithm
// along mu_s (Catmull-Rom through four sun zeniths). Where the sun sets the light falls about
// exponentially with its elevation, so a straight line between two texels overestimates it,
// and in deep twilight ever faster, so a straight line in the logarithm between texels 1-1.5
// deg apart falls a few per cent short. Eight fetches: for the reads made once per texel or
// pixel (the ground irradiance, the sky view), not inside marches (ms_lookup_of_log).
vec3 ms_lookup_log_cubic(sampler3D table, float r, float mu, float mu_s, float nu)
{
    vec4 c = ms_coords(r, mu, mu_s, nu);
    c.z = ms_r_coord_by_altitude(r);
    float t = c.w * (MS_NU - 1.0);
    float i = min(floor(t), MS_NU - 2.0);
    float f = t - i;
    float s = clamp(c.x * MS_MU_S - 0.5, 0.0, MS_MU_S - 1.0);
    float j = min(floor(s), MS_MU_S - 2.0);
    vec4 w = ms_catmull_rom(s - j);
    const vec3 tiny = vec3(1e-30);
    vec3 acc[2];
    for (int n = 0; n < 2; n++) {
        vec3 l = vec3(0.0);
        for (int q = 0; q < 4; q++) {
            float jq = clamp(j - 1.0 + float(q), 0.0, MS_MU_S - 1.0);
            float x = (i + float(n) + (jq + 0.5) / MS_MU_S) / MS_NU;
            l += w[q] * log(max(textureLod(table, vec3(x, c.y, c.z), 0.0).rgb, tiny));
        }
        acc[n] = exp(l);
    }
    return mix(acc[0], acc[1], f);
}

// Ground irradiance table: SKY_MS_GROUND texels over mu_s at the 4D table's sun zeniths, so
// that ms_ground.comp reads that table without interpolating in mu_s.
float ms_ground_mu_s(int texel)
{
    return ms_unit_to_mu_s(float(texel) / float(SKY_MS_GROUND - 1));
}

// The ground irradiance at a sun zenith cosine: cubic in its logarithm, as ms_lookup_log_cubic.
vec3 ms_ground_lookup(sampler2D ground_table, float mu_s)
{
    const float N = float(SKY_MS_GROUND);
    float s = clamp(ms_mu_s_to_unit(mu_s), 0.0, 1.0) * (N - 1.0);
    float j = min(floor(s), N - 2.0);
    vec4 w = ms_catmull_rom(s - j);
    vec3 l = vec3(0.0);
    for (int q = 0; q < 4; q++) {
        float jq = clamp(j - 1.0 + float(q), 0.0, N - 1.0);
        l += w[q] * log(max(textureLod(ground_table, vec2((jq + 0.5) / N, 0.5), 0.0).rgb,
                            vec3(1e-30)));
    }
    return exp(l);
}

#endif
