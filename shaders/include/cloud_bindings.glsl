// Bindings 0-10 shared by the passes that march the cloud layers (trace, hemisphere): the
// atmosphere and frame blocks, the atmosphere LUTs, the cloud block, the noise volumes, the
// weather map and the sky-view LUT. Then the atmosphere, density and march code.
SKY_PARAMETER_BLOCK(0, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
SKY_PARAMETER_BLOCK(1, FrameBlock, sky_frame_uniforms, frame);
layout(binding = 2) uniform sampler2D transmittance_lut;
layout(binding = 3) uniform sampler2D multiscattering_lut;
layout(binding = 4) uniform sampler2D irradiance_lut;
SKY_PARAMETER_BLOCK(5, CloudBlock, sky_cloud_uniforms, cloud);
layout(binding = 6) uniform sampler3D base_noise;
layout(binding = 7) uniform sampler3D detail_noise;
layout(binding = 8) uniform sampler2D curl_noise;
layout(binding = 9) uniform sampler2D weather_map;
layout(binding = 10) uniform sampler2D skyview_lut; // the sky around the camera: sky ambient
// False in the pipelines for frames the moon does not light (cloud_renderer.c): they carry no
// moonlight march.
layout(constant_id = 0) const bool MOONLIT = true;

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT
#define SKY_HAS_SKYVIEW_LUT
#include "atmosphere.glsl"
#include "cloud_density.glsl"
#include "cloud_march.glsl"
