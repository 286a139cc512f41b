// Bindings 0-12 shared by the passes that march the cloud layers (trace, hemisphere): the
// atmosphere and frame blocks, the atmosphere LUTs, the cloud block, the noise volumes, the
// weather map and the sky-view LUT. Then the atmosphere, density and march code.
#include "cloud_layouts.h"

SKY_PARAMETER_BLOCK(SKY_CLOUD_MARCH_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
SKY_PARAMETER_BLOCK(SKY_CLOUD_MARCH_FRAME, FrameBlock, sky_frame_uniforms, frame);
layout(binding = SKY_CLOUD_MARCH_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_CLOUD_MARCH_MULTISCATTERING) uniform sampler2D multiscattering_lut;
layout(binding = SKY_CLOUD_MARCH_IRRADIANCE) uniform sampler2D irradiance_lut;
SKY_PARAMETER_BLOCK(SKY_CLOUD_MARCH_CLOUD, CloudBlock, sky_cloud_uniforms, cloud);
layout(binding = SKY_CLOUD_MARCH_BASE_NOISE) uniform sampler3D base_noise;
layout(binding = SKY_CLOUD_MARCH_DETAIL_NOISE) uniform sampler3D detail_noise;
layout(binding = SKY_CLOUD_MARCH_CURL_NOISE) uniform sampler2D curl_noise;
layout(binding = SKY_CLOUD_MARCH_WEATHER) uniform sampler2D weather_map;
// The sky around the camera: sky ambient.
layout(binding = SKY_CLOUD_MARCH_SKYVIEW) uniform sampler2D skyview_lut;
// The sun's optical depth through the low layer in sun space (cloud_shadow.comp).
layout(binding = SKY_CLOUD_MARCH_SUN_DEPTH) uniform sampler3D sun_depth_volume;
// Each sun column's transmittance, optical depth and support (cloud_sun_columns.comp).
layout(binding = SKY_CLOUD_MARCH_SUN_COLUMNS) uniform sampler2D sun_column_map;
// False in the pipelines for frames the moon does not light (cloud_renderer.c): they carry no
// moonlight march.
layout(constant_id = SKY_CLOUD_CONST_MOONLIT) const bool MOONLIT = true;

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT
#define SKY_HAS_SKYVIEW_LUT
#include "atmosphere.glsl"
#include "cloud_density.glsl"
#include "cloud_sun_depth.glsl"
#include "cloud_march.glsl"
