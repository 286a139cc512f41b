#include "sky_layouts.h"

// Bindings 0-7, common to every pass that shades view directions (composite, probe, meter),
// and the specialization that picks the camera's situation.
SKY_PARAMETER_BLOCK(SKY_SHADING_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
SKY_PARAMETER_BLOCK(SKY_SHADING_FRAME, FrameBlock, sky_frame_uniforms, frame);
layout(binding = SKY_SHADING_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_SHADING_MULTISCATTERING) uniform sampler2D multiscattering_lut;
layout(binding = SKY_SHADING_SKYVIEW) uniform sampler2D skyview_lut;
layout(binding = SKY_SHADING_IRRADIANCE) uniform sampler2D irradiance_lut;
// Night sky (night_sky.glsl): the star field of night_shared.h and the moonlit sky-view LUT.
layout(std430, binding = SKY_SHADING_STARS) readonly buffer StarBlock { uvec4 star_words[]; };
layout(binding = SKY_SHADING_MOON_SKYVIEW) uniform sampler2D moon_skyview_lut;

// True when the camera is above the atmosphere: every pixel is then ray-marched. A
// specialization constant rather than a branch, so that each pipeline contains only its own
// path (lavapipe would otherwise execute both under a mask).
layout(constant_id = SKY_CONST_FROM_SPACE) const bool FROM_SPACE = false;
// False in the pipelines for frames where the night sky adds nothing visible (render/night_sky.c
// night_sky_visible): they carry none of its cost.
layout(constant_id = SKY_CONST_NIGHT_SKY) const bool NIGHT_SKY = true;

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT
#define SKY_HAS_SKYVIEW_LUT
